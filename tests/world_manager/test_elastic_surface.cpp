// SPDX-License-Identifier: Apache-2.0
// The elastic slab (world_manager/deform/elastic_membrane.h, deformable_surface.h): its statics, its energy books,
// where a push lands, its floor, the patch it sends, and its scene keys.

#include "world_manager/deform/deformable_surface.h"
#include "world_manager/deform/elastic_membrane.h"
#include "world_manager/scene.h"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace impetus {
namespace {

using Eigen::Vector3d;

DeformableMaterial gel() {
  DeformableMaterial material;
  material.law = DeformableMaterial::Law::elastic;
  return material;
}

// A 10 × 10 × 2 cm slab centred at the origin, top face at z = 0.01.
DeformableSurface slab(const DeformableMaterial& material) {
  return DeformableSurface(material, Vector3d(0.05, 0.05, 0.01), Vector3d::Zero(), Eigen::Quaterniond::Identity());
}

PressStroke at(const Vector3d& point_m, double push_Ns) { return {push_Ns, point_m, point_m}; }

// The books of elastic_membrane.h: what the forces did and the integrator added equals what damping and the floor
// took plus what the surface holds.
double unbalanced_J(const ElasticMembrane& membrane, const std::vector<double>& depth_m) {
  return membrane.work_J() + membrane.scheme_J() - membrane.damped_J() - membrane.stopped_J() -
         membrane.stored_J(depth_m);
}

TEST_CASE("an elastic slab under a steady even push sinks by p/k, springs back to nothing, and its books balance") {
  const DeformableMaterial material = gel();
  const std::size_t side = 20;
  const double cell_m = 1e-3;
  ElasticMembrane membrane(material, side, side, cell_m, cell_m, 0.018);
  std::vector<double> depth_m(side * side, 0.0);
  const double pressure_Pa = 1000.0;  // a light hand's weight over a palm
  std::vector<double> force_N(side * side, pressure_Pa * cell_m * cell_m);
  const double period_s = 0.05;
  for (int k = 0; k < 40; ++k) membrane.step(period_s, force_N, depth_m);
  // An even push stretches no skin: the foundation alone holds it, d = p/k (0.4 mm).
  for (const double d : depth_m) CHECK(d == Approx(pressure_Pa / material.stiffness_Papm).epsilon(1e-9));
  CHECK(std::abs(unbalanced_J(membrane, depth_m)) < 1e-12 * membrane.work_J());
  std::fill(force_N.begin(), force_N.end(), 0.0);
  for (int k = 0; k < 40 && !membrane.at_rest(); ++k) membrane.step(period_s, force_N, depth_m);
  REQUIRE(membrane.at_rest());
  for (const double d : depth_m) CHECK(d == 0.0);
  // At rest the work went to damping, to the integrator's last rounding of the picometres it set to zero; the
  // integrator added nothing, and an even push gives the skin nothing to lag by.
  CHECK(membrane.stored_J(depth_m) == 0.0);
  CHECK(membrane.scheme_J() <= 0.0);
  CHECK(membrane.given_back_J() == 0.0);
  CHECK(membrane.damped_J() == Approx(membrane.work_J() + membrane.scheme_J()).epsilon(1e-9));
  // And a slab at rest costs nothing: a period with no push moves nothing.
  CHECK_FALSE(membrane.step(period_s, force_N, depth_m));
}

TEST_CASE("an undamped elastic slab struck once keeps its energy: no gain, the books exact at every period") {
  DeformableMaterial material = gel();
  material.damping_Paspm = 0.0;
  DeformableSurface surface = slab(material);
  const double period_s = 0.05;
  surface.press(at(Vector3d(0.004, -0.003, 0.01), 0.02));
  surface.yield_period(period_s);
  const double work_J = surface.work_J();
  REQUIRE(work_J > 0.0);
  double highest_J = 0.0;
  double lowest_J = work_J;
  for (int k = 0; k < 200; ++k) {  // 10 s
    surface.yield_period(period_s);
    highest_J = std::max(highest_J, surface.stored_J());
    lowest_J = std::min(lowest_J, surface.stored_J());
    CHECK(surface.work_J() == work_J);  // nothing pushes after the first period
  }
  // It never holds more than the push put in (the integrator's share is given back as it arises,
  // elastic_membrane.h), and loses nothing either: the trapezoid's foundation and the observer's give-back keep it.
  CHECK(highest_J <= work_J * (1.0 + 1e-9));
  CHECK(lowest_J > 0.98 * work_J);
  CHECK(surface.dissipated_J() == 0.0);
  CHECK(surface.scheme_J() <= 0.0);
}

TEST_CASE("a pad's steady press sinks its centre by the compliance, and the patch sent is the surface without it") {
  const DeformableMaterial material = gel();
  DeformableSurface surface = slab(material);
  const double period_s = 0.05;
  const double force_N = 1.0;
  const Vector3d point_m(0.0005, 0.0005, 0.01);  // a cell's centre
  for (int k = 0; k < 40; ++k) {
    surface.press(at(point_m, force_N * period_s), 0);
    surface.yield_period(period_s);
  }
  const double compliance_mpN = surface.compliance_mpN();
  // The default gel: a 1 N press sinks the pad's centre about 5 mm (deformable_material.h).
  CHECK(compliance_mpN > 3e-3);
  CHECK(compliance_mpN < 7e-3);
  // The grid's free edges are 5 cm away, 25 decay lengths: the slab's own depth is the window's response.
  CHECK(surface.dent_m() == Approx(compliance_mpN * force_N).epsilon(1e-3));
  CHECK(surface.height_m(point_m.x(), point_m.y()) == Approx(0.01 - compliance_mpN * force_N).epsilon(1e-3));
  // The patch for the endpoint that pressed carries the face without its own press: flat to 0.2 % of the dent.
  DentPatch patch;
  surface.patch_about(point_m, 0, 0.0, patch, 0);
  for (const double height_m : patch.height_m) CHECK(std::abs(height_m - 0.01) < 2e-3 * surface.dent_m());
  // Another endpoint's patch shows the dent whole.
  surface.patch_about(point_m, 0, 0.0, patch, 1);
  const double lowest_m = *std::min_element(patch.height_m.begin(), patch.height_m.end());
  CHECK(lowest_m == Approx(0.01 - surface.dent_m()).epsilon(1e-6));
}

TEST_CASE("two fingers on a gel: each one's patch leaves out its own press and shows the other's") {
  DeformableSurface surface = slab(gel());
  const double period_s = 0.05;
  const Vector3d first_m(-0.0195, 0.0005, 0.01);
  const Vector3d second_m(0.0205, 0.0005, 0.01);  // 4 cm away: 20 decay lengths, the dents do not meet
  for (int k = 0; k < 40; ++k) {
    surface.press(at(first_m, 1.0 * period_s), 0);
    if (k >= 10) surface.press(at(second_m, 0.5 * period_s), 1);  // joins later, with half the force
    surface.yield_period(period_s);
  }
  const double compliance_mpN = surface.compliance_mpN();
  CHECK(surface.height_m(first_m.x(), first_m.y()) == Approx(0.01 - compliance_mpN).epsilon(1e-6));
  CHECK(surface.height_m(second_m.x(), second_m.y()) == Approx(0.01 - 0.5 * compliance_mpN).epsilon(1e-6));
  DentPatch patch;
  // The patch's sample nearest a point, and where that sample lies.
  const auto nearest = [&patch](const Vector3d& at_m, Vector3d& sample_m) {
    const long u = std::lround((at_m.x() - patch.origin_m[0]) / patch.spacing_m);
    const long v = std::lround((at_m.y() - patch.origin_m[1]) / patch.spacing_m);
    sample_m = Vector3d(patch.origin_m[0] + u * patch.spacing_m, patch.origin_m[1] + v * patch.spacing_m, 0.0);
    return patch.height_m[static_cast<std::size_t>(v) * kDentPatchSide + static_cast<std::size_t>(u)];
  };
  // The linear law splits the surface into the fingers' shares, to the observer's give-back: a micrometre's
  // millionth here.
  const double margin_m = 1e-6 * compliance_mpN;
  Vector3d sample_m = Vector3d::Zero();
  // The first finger's patch, wide enough (a fast finger's) to reach both: flat under its own press, the second's
  // dent whole; and the other way round.
  surface.patch_about(Vector3d(0.0005, 0.0005, 0.01), 0, 0.03, patch, 0);
  CHECK(nearest(first_m, sample_m) == Approx(0.01).margin(margin_m));
  const double second_in_first_m = nearest(second_m, sample_m);
  CHECK(second_in_first_m == Approx(surface.height_m(sample_m.x(), sample_m.y())).margin(margin_m));
  CHECK(second_in_first_m < 0.01 - 0.4 * compliance_mpN);
  surface.patch_about(Vector3d(0.0005, 0.0005, 0.01), 0, 0.03, patch, 1);
  const double first_in_second_m = nearest(first_m, sample_m);
  CHECK(first_in_second_m == Approx(surface.height_m(sample_m.x(), sample_m.y())).margin(margin_m));
  CHECK(first_in_second_m < 0.01 - 0.8 * compliance_mpN);
  CHECK(nearest(second_m, sample_m) == Approx(0.01).margin(margin_m));
}

TEST_CASE("the floor stops an elastic slab: no cell below it, nothing NaN, the speed it stopped counted") {
  DeformableSurface surface = slab(gel());
  const double period_s = 0.05;
  for (int k = 0; k < 10; ++k) {
    surface.press(at(Vector3d::Zero(), 100.0 * period_s));  // 100 N: far beyond any hand
    surface.yield_period(period_s);
  }
  CHECK(std::isfinite(surface.dent_m()));
  CHECK(surface.dent_m() <= 0.9 * 0.02 + 1e-12);
  CHECK(surface.dent_m() == Approx(0.9 * 0.02));
  CHECK(surface.room_m(0.0, 0.0) == Approx(0.0).margin(1e-12));
  CHECK(surface.dissipated_J() > 0.0);
  CHECK(std::isfinite(surface.stored_J()));
}

TEST_CASE("the penetration rule holds an elastic slab where the sampled contact is, for one period, and counts it") {
  DeformableMaterial material = gel();
  material.rule = DeformableMaterial::Rule::penetration;
  DeformableSurface surface = slab(material);
  const double period_s = 0.05;
  surface.press_by_penetration(Vector3d(0.0005, 0.0005, 0.011), 0);  // above the face: nothing
  surface.yield_period(period_s);
  CHECK(surface.dent_m() == 0.0);
  surface.press_by_penetration(Vector3d(0.0005, 0.0005, 0.008), 0);  // 2 mm in, over a cell's centre
  surface.yield_period(period_s);
  // The pad's centre is held at the contact's depth, the gel around it pulled in after it.
  CHECK(surface.dent_m() == Approx(0.002).epsilon(1e-12));
  CHECK(surface.height_m(0.0005, 0.0005) == Approx(0.008).epsilon(1e-12));
  CHECK(surface.height_m(0.0085, 0.0005) < 0.01);  // beyond the pad's rim, moved by the skin
  // The pins' work is the energy they gave the gel; the books balance.
  CHECK(surface.work_J() > 0.0);
  CHECK(surface.work_J() + surface.scheme_J() ==
        Approx(surface.dissipated_J() + surface.stored_J()).epsilon(1e-9));
  // Released (no sample in the next period), it springs back.
  for (int k = 0; k < 20; ++k) surface.yield_period(period_s);
  CHECK(std::abs(surface.dent_m()) < 1e-9);
  // Neither rule's elastic slab takes a yield force or a plastic depth per push: the haptic side counts all of it.
  CHECK(material.yield_force_N() == 0.0);
  CHECK(material.yield_depth_mpNs() == 0.0);
}

TEST_CASE("under the penetration rule a second finger's first pin is its own share, not the first finger's") {
  DeformableMaterial material = gel();
  material.rule = DeformableMaterial::Rule::penetration;
  DeformableSurface surface = slab(material);
  const double period_s = 0.05;
  const Vector3d first_m(-0.0195, 0.0005, 0.008);  // 2 mm in
  const Vector3d second_m(0.0205, 0.0005, 0.008);  // 4 cm away
  surface.press_by_penetration(first_m, 0);
  surface.yield_period(period_s);
  surface.press_by_penetration(first_m, 0);
  surface.press_by_penetration(second_m, 1);  // its first: the shares split here
  surface.yield_period(period_s);
  DentPatch patch;
  // The first finger's wide patch about the middle: the second's pinned dent shows whole in it.
  surface.patch_about(Vector3d(0.0005, 0.0005, 0.01), 0, 0.03, patch, 0);
  const long u = std::lround((second_m.x() - patch.origin_m[0]) / patch.spacing_m);
  const long v = std::lround((second_m.y() - patch.origin_m[1]) / patch.spacing_m);
  const double sample_x_m = patch.origin_m[0] + static_cast<double>(u) * patch.spacing_m;
  const double sample_y_m = patch.origin_m[1] + static_cast<double>(v) * patch.spacing_m;
  const double height_m = patch.height_m[static_cast<std::size_t>(v) * kDentPatchSide + static_cast<std::size_t>(u)];
  CHECK(height_m < 0.01 - 1e-4);
  CHECK(height_m == Approx(surface.height_m(sample_x_m, sample_y_m)).margin(1e-9));
}

TEST_CASE("an elastic slab's scene keys: defaults, and errors that name the file, the key and the value") {
  nlohmann::json scene = nlohmann::json::parse(R"({
    "objects": [{"name": "gel", "shape": "box", "size_m": [0.1, 0.1, 0.03], "dynamic": false,
                 "position_m": [0, 0, 0.015], "deformable": {"law": "elastic"}}]})");
  const Scene parsed = parse_scene(scene, "gel.json");
  REQUIRE(parsed.objects[0].deformable.has_value());
  CHECK(parsed.objects[0].deformable->law == DeformableMaterial::Law::elastic);
  CHECK(parsed.objects[0].deformable->stiffness_Papm == gel().stiffness_Papm);
  const auto error_of = [&scene](const nlohmann::json& deformable) {
    scene["objects"][0]["deformable"] = deformable;
    try {
      parse_scene(scene, "gel.json");
    } catch (const SceneError& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  CHECK_THAT(error_of({{"law", "rubbery"}}),
             Catch::Contains("gel.json: /objects/0/deformable/law") && Catch::Contains("plastic or elastic"));
  CHECK_THAT(error_of({{"law", "elastic"}, {"yield_stress_Pa", 5000}}),
             Catch::Contains("/objects/0/deformable/yield_stress_Pa") && Catch::Contains("elastic"));
  CHECK_THAT(error_of({{"tension_Npm", 10}}),
             Catch::Contains("/objects/0/deformable/tension_Npm") && Catch::Contains("plastic"));
  CHECK_THAT(error_of({{"law", "elastic"}, {"areal_density_kgpm2", 0}}), Catch::Contains("areal_density_kgpm2"));
  // A stiff skin on a light layer over fine cells would need more updates a second than real time allows.
  CHECK_THAT(error_of({{"law", "elastic"}, {"tension_Npm", 10000}, {"areal_density_kgpm2", 0.01}, {"cell_m", 0.0002},
                       {"contact_radius_m", 0.002}}),
             Catch::Contains("real time"));
}

}  // namespace
}  // namespace impetus
