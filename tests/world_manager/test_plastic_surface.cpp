// SPDX-License-Identifier: Apache-2.0
// The plastic slab (world_manager/deform/): its law, where a push lands, its limits, and its scene keys.

#include "world_manager/deform/deformable_surface.h"
#include "world_manager/deform/press_path.h"
#include "world_manager/scene.h"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <string>

namespace impetus {
namespace {

using Eigen::Vector3d;

// A 10 × 10 × 2 cm slab centred at the origin, top face at z = 0.01, with the scene's default clay.
DeformableSurface slab(DeformableMaterial material = {}) {
  return DeformableSurface(material, Vector3d(0.05, 0.05, 0.01), Vector3d::Zero(), Eigen::Quaterniond::Identity());
}

PressStroke at(const Vector3d& point_m, double push_Ns) { return {push_Ns, point_m, point_m}; }

TEST_CASE("a plastic slab dents by the push beyond yield it is given: volume = push / flow resistance") {
  const DeformableMaterial clay;
  DeformableSurface surface = slab(clay);
  const double push_Ns = 0.01;
  surface.press(at(Vector3d(0.003, -0.002, 0.01), push_Ns));
  CHECK(surface.max_dent_m() == 0.0);  // nothing yields before the period ends
  surface.yield_period();
  CHECK(surface.yielding_Ns() == Approx(push_Ns).epsilon(1e-12));
  CHECK(surface.dent_volume_m3() * clay.flow_resistance_Paspm == Approx(push_Ns).epsilon(1e-12));
  // The pad's centre goes in by about 2·e/(π·a²·η) (deformable_material.h), what the haptic side yields it by between
  // frames: the grid's paraboloid sampled at 1 mm cells under a 6 mm pad differs from the continuous one by a few
  // percent of the dent (the step a finger meets at the next frame).
  const double centre_m = clay.yield_depth_mpNs() * push_Ns;
  CHECK(surface.max_dent_m() == Approx(centre_m).epsilon(0.03));
  CHECK(surface.height_m(0.003, -0.002) == Approx(0.01 - surface.max_dent_m()).epsilon(0.02));
  // Outside the pad nothing moved.
  CHECK(surface.height_m(0.003 + 0.008, -0.002) == 0.01);
  // A second period with nothing received changes nothing.
  const double volume_m3 = surface.dent_volume_m3();
  surface.yield_period();
  CHECK(surface.dent_volume_m3() == volume_m3);
}

TEST_CASE("a plastic slab's patch of heights lies on its cells' centres, and spreads out to reach a fast finger") {
  DeformableSurface surface = slab();
  surface.press(at(Vector3d(0.0013, 0.0004, 0.01), 0.01));
  surface.yield_period();
  DentPatch patch;
  const Vector3d about_m(0.0011, 0.0007, 0.01);
  surface.patch_about(about_m, 4, 0.0, patch);
  CHECK(patch.object_id == 4);
  CHECK(patch.spacing_m == Approx(0.001));
  // Every sample is a cell centre ((i + 0.5) mm from the face's edge at −5 cm) and carries that cell's height.
  const double u0 = (patch.origin_m[0] + 0.05) / 0.001 - 0.5;
  const double v0 = (patch.origin_m[1] + 0.05) / 0.001 - 0.5;
  CHECK(u0 == Approx(std::round(u0)).margin(1e-9));
  CHECK(v0 == Approx(std::round(v0)).margin(1e-9));
  const auto column = static_cast<std::size_t>(std::round(u0)) + 16;
  const auto row = static_cast<std::size_t>(std::round(v0)) + 15;
  REQUIRE(surface.depth_m(column, row) > 0.0);
  CHECK(patch.height_m[15 * kDentPatchSide + 16] == Approx(0.01 - surface.depth_m(column, row)).epsilon(1e-12));
  // It holds the point it was taken about, near its middle.
  CHECK(std::abs(about_m.x() - (patch.origin_m[0] + 15.5 * patch.spacing_m)) <= 0.5 * patch.spacing_m + 1e-12);
  // A finger that may travel 5 cm before the next frame: samples further apart, so the patch reaches it.
  surface.patch_about(about_m, 4, 0.05, patch);
  CHECK(patch.spacing_m * 0.5 * (kDentPatchSide - 1) == Approx(0.05));
  // A nonsense reach is no reach.
  surface.patch_about(about_m, 4, std::numeric_limits<double>::quiet_NaN(), patch);
  CHECK(patch.spacing_m == Approx(0.001));
}

TEST_CASE("a plastic slab's threshold is the material's yield force over the contact pad") {
  DeformableMaterial clay;
  clay.yield_stress_Pa = 5000.0;
  clay.contact_radius_m = 0.006;
  clay.flow_resistance_Paspm = 1e6;
  CHECK(clay.yield_force_N() == Approx(5000.0 * M_PI * 0.006 * 0.006));
  CHECK(clay.yield_depth_mpNs() == Approx(2.0 / (M_PI * 0.006 * 0.006 * 1e6)));
  clay.rule = DeformableMaterial::Rule::penetration;  // the previous method: the push does not dent it
  CHECK(clay.yield_force_N() == 0.0);
  CHECK(clay.yield_depth_mpNs() == 0.0);
}

namespace {

// Adds a push p at x to the moments, as the haptic side does tick by tick (ImpulseAccumulator).
void add_push(PressMoments& moments, double p_Ns, const Vector3d& x_m) {
  moments.push_Ns += p_Ns;
  moments.point_Nsm += p_Ns * x_m;
  moments.point2_Nsm2 += p_Ns * x_m * x_m.transpose();
}

// Whether a stroke runs between a and b, either way (its direction is not a moment's), to `tolerance_m`.
bool runs_between(const PressStroke& stroke, const Vector3d& a, const Vector3d& b, double tolerance_m) {
  return ((stroke.from_m - a).norm() < tolerance_m && (stroke.to_m - b).norm() < tolerance_m) ||
         ((stroke.from_m - b).norm() < tolerance_m && (stroke.to_m - a).norm() < tolerance_m);
}

}  // namespace

TEST_CASE("a stroke's push is laid along the path it was given on, from the moments of a world period") {
  // A finger moving at 5 cm/s along x for 50 ticks of 1 ms, pushing 2 mN·s per tick.
  PressMoments moments;
  const Vector3d start_m(-0.01, 0.002, 0.01);
  const Vector3d velocity_mps(0.05, 0.0, 0.0);
  for (int k = 0; k < 50; ++k) add_push(moments, 0.002, start_m + velocity_mps * (0.001 * k));
  const PressStroke stroke = stroke_of(moments);
  CHECK(stroke.push_Ns == Approx(0.1));
  // Fifty samples uniform over [0, 49] ms: the uniform stroke with their spread runs half a tick beyond the first
  // and last (variance (n² − 1)/12 ticks², the continuous uniform's n²/12): within 0.5 ms·5 cm/s = 25 µm each end.
  CHECK(runs_between(stroke, start_m, start_m + velocity_mps * 0.049, 26e-6));
  CHECK(std::abs(stroke.from_m.y() - 0.002) < 1e-12);

  // A finger that did not move presses at one point.
  PressMoments still;
  for (int k = 0; k < 50; ++k) add_push(still, 0.001, start_m);
  const PressStroke press = stroke_of(still);
  CHECK((press.from_m - start_m).norm() < 1e-6);
  CHECK((press.to_m - start_m).norm() < 1e-6);

  // Nothing, or nothing usable, presses nowhere.
  CHECK(stroke_of(PressMoments{}).push_Ns == 0.0);
  PressMoments broken = moments;
  broken.point2_Nsm2(1, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK(stroke_of(broken).push_Ns == 0.0);
}

TEST_CASE("a stroke is laid as precisely after an hour of pressing as at the start") {
  // The haptic side's running totals after an hour of a finger pressing 0.5 N beyond yield while circling over the
  // slab (3.6 million ticks), then the stroke above: the world takes the period's difference of the totals.
  PressMoments before;
  for (int k = 0; k < 3'600'000; ++k) {
    const double angle = 2.0 * M_PI * k / 4000.0;  // one 2 cm circle every 4 s
    add_push(before, 5e-4, Vector3d(0.02 * std::cos(angle), 0.02 * std::sin(angle), 0.01));
  }
  PressMoments after = before;
  const Vector3d start_m(-0.01, 0.002, 0.01);
  const Vector3d velocity_mps(0.05, 0.0, 0.0);
  for (int k = 0; k < 50; ++k) add_push(after, 0.002, start_m + velocity_mps * (0.001 * k));
  const PressStroke stroke = stroke_of(after - before);
  CHECK(stroke.push_Ns == Approx(0.1).epsilon(1e-9));
  CHECK(runs_between(stroke, start_m, start_m + velocity_mps * 0.049, 26e-6));
}

TEST_CASE("a plastic slab conserves a stroke's push and keeps what lands off its face as lost") {
  const DeformableMaterial clay;
  DeformableSurface surface = slab(clay);
  surface.press({0.02, Vector3d(-0.02, 0.0, 0.01), Vector3d(0.02, 0.0, 0.01)});
  surface.press(at(Vector3d(0.3, 0.0, 0.01), 0.005));  // 30 cm off the slab
  surface.yield_period();
  CHECK(surface.yielding_Ns() == Approx(0.02).epsilon(1e-12));
  CHECK(surface.lost_Ns() == Approx(0.005).epsilon(1e-12));
  CHECK(surface.dent_volume_m3() * clay.flow_resistance_Paspm == Approx(0.02).epsilon(1e-12));
  // A groove: as deep in its middle at x = −5 mm as at x = +5 mm (the push was even along it).
  CHECK(surface.height_m(-0.005, 0.0) == Approx(surface.height_m(0.005, 0.0)).epsilon(1e-3));
  CHECK(surface.height_m(0.0, 0.0) < 0.01);
}

TEST_CASE("no push goes through a plastic slab: its last tenth does not yield") {
  const DeformableMaterial clay;
  DeformableSurface surface = slab(clay);
  for (int period = 0; period < 100; ++period) {
    surface.press(at(Vector3d::Zero(), 10.0));  // 200 N for 50 ms, a hundred times over
    surface.yield_period();
  }
  CHECK(std::isfinite(surface.dent_volume_m3()));
  CHECK(surface.max_dent_m() == Approx(0.9 * 0.02));
  CHECK(surface.clamped_m3() > 0.0);
  CHECK(surface.height_m(0.0, 0.0) == Approx(0.01 - 0.018));
  // Its surface there is still a surface: a tangent plane with a unit normal.
  Vector3d point_m, normal;
  surface.tangent_plane(Vector3d(0.0, 0.0, 0.0), point_m, normal);
  CHECK(point_m.allFinite());
  CHECK(normal.norm() == Approx(1.0));
}

TEST_CASE("the penetration rule moves the surface by plasticity times the sampled penetration") {
  DeformableMaterial clay;
  clay.rule = DeformableMaterial::Rule::penetration;
  clay.plasticity = 0.5;
  DeformableSurface surface = slab(clay);
  surface.press_by_penetration(Vector3d(0.0005, 0.0005, 0.01 + 0.002));  // above: nothing
  CHECK(surface.max_dent_m() == 0.0);
  surface.press_by_penetration(Vector3d(0.0005, 0.0005, 0.01 - 0.002));  // 2 mm in, over a cell centre
  CHECK(surface.max_dent_m() == Approx(0.001).epsilon(1e-12));
  CHECK(surface.height_m(0.0005, 0.0005) == Approx(0.009).epsilon(1e-12));
  surface.press_by_penetration(Vector3d(0.0005, 0.0005, 0.009 - 0.002));  // 2 mm below the new surface
  CHECK(surface.max_dent_m() == Approx(0.002).epsilon(1e-12));
}

TEST_CASE("a tilted plastic slab takes pushes and gives planes in its own frame") {
  const DeformableMaterial clay;
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(0.3, Vector3d::UnitX()));
  const Vector3d centre_m(0.1, 0.0, 0.05);
  DeformableSurface surface(clay, Vector3d(0.05, 0.05, 0.01), centre_m, tilt);
  const Vector3d on_top_m = centre_m + tilt * Vector3d(0.0, 0.0, 0.01);
  Vector3d point_m, normal;
  surface.tangent_plane(surface.to_body(on_top_m + tilt * Vector3d(0, 0, 0.003)), point_m, normal);
  CHECK((point_m - on_top_m).norm() < 1e-12);
  CHECK((normal - tilt * Vector3d::UnitZ()).norm() < 1e-12);
  surface.press(at(on_top_m, 0.01));
  surface.yield_period();
  surface.tangent_plane(surface.to_body(on_top_m), point_m, normal);
  CHECK((point_m - on_top_m).dot(tilt * Vector3d::UnitZ()) == Approx(-surface.max_dent_m()).epsilon(0.02));
}

nlohmann::json clay_scene() {
  return nlohmann::json::parse(R"({
    "objects": [{"name": "clay", "shape": "box", "size_m": [0.2, 0.2, 0.03], "dynamic": false,
                 "position_m": [0, 0, 0.015], "deformable": {}}]})");
}

std::string error_of(const nlohmann::json& scene) {
  try {
    parse_scene(scene, "clay.json");
  } catch (const SceneError& error) {
    return error.what();
  }
  return "";
}

TEST_CASE("a scene's deformable block: defaults, and errors that name the file, the key and the value") {
  nlohmann::json scene = clay_scene();
  const Scene parsed = parse_scene(scene, "clay.json");
  REQUIRE(parsed.objects[0].deformable.has_value());
  CHECK(parsed.objects[0].deformable->rule == DeformableMaterial::Rule::impulse);
  CHECK(parsed.objects[0].deformable->yield_stress_Pa == DeformableMaterial{}.yield_stress_Pa);

  scene["objects"][0]["deformable"] = {{"rule", "melt"}};
  CHECK_THAT(error_of(scene), Catch::Contains("clay.json: /objects/0/deformable/rule") &&
                                  Catch::Contains("impulse or penetration"));
  scene["objects"][0]["deformable"] = {{"cell_m", 0.004}};
  CHECK_THAT(error_of(scene), Catch::Contains("/objects/0/deformable/cell_m") && Catch::Contains("half"));
  scene["objects"][0]["deformable"] = {{"cell_m", 1e-5}};
  CHECK_THAT(error_of(scene), Catch::Contains("cells"));
  scene["objects"][0]["deformable"] = {{"yield_stress_Pa", -1}};
  CHECK_THAT(error_of(scene), Catch::Contains("/objects/0/deformable/yield_stress_Pa"));
  scene["objects"][0]["deformable"] = {{"softness", 1}};
  CHECK_THAT(error_of(scene), Catch::Contains("softness"));
  scene = clay_scene();
  scene["objects"][0]["dynamic"] = true;
  scene["objects"][0]["mass_kg"] = 1.0;
  CHECK_THAT(error_of(scene), Catch::Contains("only a static object"));
  scene = clay_scene();
  scene["objects"][0]["shape"] = "sphere";
  scene["objects"][0].erase("size_m");
  scene["objects"][0]["radius_m"] = 0.05;
  CHECK_THAT(error_of(scene), Catch::Contains("only a box"));
}

}  // namespace
}  // namespace impetus
