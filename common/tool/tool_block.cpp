// SPDX-License-Identifier: Apache-2.0
#include "common/tool/tool_block.h"

#include "common/mesh/mesh_object.h"
#include "common/runtime/message_text.h"
#include "common/shape/shape.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <span>
#include <string_view>

namespace impetus {
namespace {

// The keys a tool may have; its shape's own come from the shape module.
constexpr std::string_view kToolKeys[] = {
    "shape", "position_m", "orientation_wxyz", "mass_kg", "density_kgpm3", "stiffness_Npm", "damping_Nspm",
    "rotational_stiffness_Nmprad", "rotational_damping_Nmsprad", "max_force_N", "max_torque_Nm"};

}  // namespace

ToolBlock parse_tool_block(const JsonNode& node, const Vec3& gravity_mps2, const std::string& scene_dir) {
  node.expect_object();
  const ShapeKind kind = parse_shape_kind(node.required("shape"));
  node.expect_keys({std::span<const std::string_view>(kToolKeys), shape_keys(kind)});
  ToolBlock tool;
  // A mesh tool is a closed body (its mass and inertia come from its volume) whose corners and sharp edges stand for
  // it: it touches by them (docs/tool.md), so it must be convex and have few enough of them.
  tool.shape.shape = kind == ShapeKind::mesh ? load_mesh_shape(node, scene_dir, true) : parse_shape(node, kind);
  ContactSamples samples;
  if (kind == ShapeKind::mesh && contact_samples(tool.shape.shape, samples) == 0) {
    node.child("file").fail("a tool's mesh must bound a convex body with at most " +
                            std::to_string(kMaxContactSamples) + " corners and " + std::to_string(kMaxContactEdges) +
                            " sharp edges: a tool touches by its corners and edges (docs/tool.md); make a convex "
                            "hull of few faces, or use box, sphere, capsule or cylinder");
  }
  if (node.has("position_m")) {
    const Vec3 at = node.child("position_m").vector_up_to(ToolLimits::kMaxToolReach_m, " m");
    tool.shape.placement.position_m = Eigen::Vector3d(at[0], at[1], at[2]);
  }
  if (node.has("orientation_wxyz")) {
    const std::array<double, 4> q = node.child("orientation_wxyz").unit_quaternion();
    tool.shape.placement.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
  }
  ToolCoupling& coupling = tool.coupling;
  if (node.has("stiffness_Npm")) {
    coupling.stiffness_Npm = node.child("stiffness_Npm").positive_up_to(limits::kMaxStiffness_Npm, " N/m");
  }
  if (node.has("damping_Nspm")) {
    coupling.damping_Nspm = node.child("damping_Nspm").in_range(0.0, limits::kMaxDamping_Nspm, " N·s/m");
  }
  if (node.has("rotational_stiffness_Nmprad")) {
    coupling.rotational_stiffness_Nmprad = node.child("rotational_stiffness_Nmprad")
                                               .positive_up_to(ToolLimits::kMaxRotationalStiffness_Nmprad, " N·m/rad");
  }
  if (node.has("rotational_damping_Nmsprad")) {
    coupling.rotational_damping_Nmsprad = node.child("rotational_damping_Nmsprad")
                                              .in_range(0.0, ToolLimits::kMaxRotationalDamping_Nmsprad, " N·m·s/rad");
  }
  if (node.has("max_force_N")) {
    coupling.max_force_N = node.child("max_force_N").positive_up_to(ToolLimits::kMaxToolForce_N, " N");
  }
  if (node.has("max_torque_Nm")) {
    coupling.max_torque_Nm = node.child("max_torque_Nm").positive_up_to(ToolLimits::kMaxToolTorque_Nm, " N·m");
  }
  // Its mass (none given: weightless), and its weight under the scene's gravity. A device that cannot hold the weight
  // up, or its moment about the grip, could not render the tool: refused rather than clamped on every tick.
  if (node.has("mass_kg") && node.has("density_kgpm3")) {
    node.child("density_kgpm3").fail("give either mass_kg or density_kgpm3, not both");
  }
  if (node.has("mass_kg")) {
    tool.shape.mass_kg = node.child("mass_kg").in_range(0.0, ToolLimits::kMaxToolMass_kg, " kg");
  } else if (node.has("density_kgpm3")) {
    tool.shape.mass_kg = node.child("density_kgpm3").positive() * volume_m3(tool.shape.shape);
    if (!(tool.shape.mass_kg <= ToolLimits::kMaxToolMass_kg)) {
      node.child("density_kgpm3").fail("density × volume = " + readable(tool.shape.mass_kg) + " kg; a tool's mass " +
                                       "must be at most " + readable(ToolLimits::kMaxToolMass_kg) + " kg");
    }
  }
  tool.shape.weight_N = tool.shape.mass_kg * Eigen::Vector3d(gravity_mps2[0], gravity_mps2[1], gravity_mps2[2]);
  const char* const mass_key = node.has("mass_kg") ? "mass_kg" : "density_kgpm3";
  const double weight_N = tool.shape.weight_N.norm();
  if (weight_N > coupling.max_force_N) {
    node.child(mass_key).fail("the tool weighs " + readable(weight_N) + " N, more than max_force_N (" +
                              readable(coupling.max_force_N) + " N): the device could not hold it up");
  }
  const double weight_torque_Nm = tool.shape.placement.position_m.norm() * weight_N;  // at most, turned any way
  if (weight_torque_Nm > coupling.max_torque_Nm) {
    node.child(mass_key).fail("the tool's weight turns the grip by up to " + readable(weight_torque_Nm) + " N·m " +
                              "about its centre, more than max_torque_Nm (" + readable(coupling.max_torque_Nm) +
                              " N·m): the device could not hold it level");
  }
  // The farthest the tool reaches from the grip's centre: its placement plus its bounding box's farthest corner.
  const Eigen::AlignedBox3d bounds = world_bounds(tool.shape.shape, BodyPose{});
  tool.reach_m = tool.shape.placement.position_m.norm() +
                 std::max(bounds.min().norm(), bounds.max().norm());
  return tool;
}

std::optional<ToolBlock> load_scene_tool(const std::string& path) {
  const nlohmann::json document = read_scene_document(path);
  const JsonNode root(document, "", path);
  root.expect_object();
  if (!root.has("tool")) return std::nullopt;
  Vec3 gravity_mps2{0.0, 0.0, -limits::kStandardGravity_mps2};  // the scene's default (world_manager/scene.h)
  if (root.has("gravity_mps2")) {
    gravity_mps2 = root.child("gravity_mps2").vector_up_to(limits::kMaxGravity_mps2, " m/s²");
  }
  return parse_tool_block(root.child("tool"), gravity_mps2, scene_folder(path));
}

}  // namespace impetus
