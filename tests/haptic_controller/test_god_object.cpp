// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/god_object.h"
#include "haptic_controller/proxy_projection.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <Eigen/LU>

#include <cmath>
#include <initializer_list>
#include <limits>
#include <random>

using namespace impetus;
using impetus::test::make_plane;
using impetus::test::make_set;
using Eigen::Vector3d;

namespace {

constexpr double kTol = 1e-12;

double slack(const ContactPlane& p, const Vector3d& x) { return p.normal.dot(x - p.point_m); }

// KKT of the projection: feasible, x − C = Σ λ n over the active planes, λ ≥ 0, active planes tight.
void require_kkt(const PlaneSet& planes, const Vector3d& finger, const ProxySolution& s) {
  REQUIRE(s.proxy_m.allFinite());
  for (std::uint32_t k = 0; k < planes.count; ++k) REQUIRE(slack(planes.planes[k], s.proxy_m) >= -1e-10);
  Vector3d sum = Vector3d::Zero();
  for (int j = 0; j < s.active_count; ++j) {
    REQUIRE(s.active[j].multiplier_m >= -1e-12);
    REQUIRE(std::abs(slack(planes.planes[s.active[j].plane], s.proxy_m)) < 1e-10);
    sum += s.active[j].multiplier_m * planes.planes[s.active[j].plane].normal;
  }
  REQUIRE((s.proxy_m - finger - sum).norm() < 1e-10);
}

// Reference: the nearest point to C among the projections onto every face, edge and corner (every subset of ≤ 3
// planes, treated as equalities) that lies outside all planes.
Vector3d brute_force_projection(const PlaneSet& planes, const Vector3d& c) {
  Vector3d best = c;
  double best_distance = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(planes.count);
  auto consider = [&](const Vector3d& x) {
    for (int k = 0; k < n; ++k) {
      if (slack(planes.planes[k], x) < -1e-10) return;
    }
    if ((x - c).norm() < best_distance) {
      best_distance = (x - c).norm();
      best = x;
    }
  };
  consider(c);
  auto face = [&](std::initializer_list<int> subset) {
    const int m = static_cast<int>(subset.size());
    Eigen::MatrixXd normals(3, m);
    Eigen::VectorXd rhs(m);
    int j = 0;
    for (const int k : subset) {
      normals.col(j) = planes.planes[k].normal;
      rhs[j++] = -slack(planes.planes[k], c);
    }
    const Eigen::MatrixXd gram = normals.transpose() * normals;
    if (std::abs(gram.determinant()) < 1e-10) return;
    consider(c + normals * (gram.inverse() * rhs));
  };
  for (int a = 0; a < n; ++a) {
    face({a});
    for (int b = a + 1; b < n; ++b) {
      face({a, b});
      for (int d = b + 1; d < n; ++d) face({a, b, d});
    }
  }
  return best;
}

}  // namespace

TEST_CASE("one plane: the proxy is the finger's projection onto it") {
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1})});
  const Vector3d finger(0.1, 0.2, -0.01);
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(s.active_count == 1);
  REQUIRE((s.proxy_m - Vector3d(0.1, 0.2, 0.0)).norm() < kTol);
  REQUIRE(s.active[0].multiplier_m == Approx(0.01));
  require_kkt(planes, finger, s);
}

TEST_CASE("finger outside every plane: the proxy is the finger, nothing active") {
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}), make_plane({0, 0, 0}, {1, 0, 0})});
  const ProxySolution s = project_outside_planes(planes, Vector3d(0.01, 0.0, 0.02));
  REQUIRE(s.active_count == 0);
  REQUIRE((s.proxy_m - Vector3d(0.01, 0.0, 0.02)).norm() == 0.0);
}

TEST_CASE("two planes: the proxy slides into the edge line") {
  // Floor and the side of a cube meeting at the y axis: free space is x ≥ 0, z ≥ 0.
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}), make_plane({0, 0, 0}, {1, 0, 0})});
  const Vector3d finger(-0.01, 0.05, -0.02);
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(s.active_count == 2);
  REQUIRE((s.proxy_m - Vector3d(0.0, 0.05, 0.0)).norm() < kTol);
  require_kkt(planes, finger, s);
}

TEST_CASE("two planes at an obtuse edge: only the plane that holds the finger stays active") {
  // z ≥ 0 and a slope rising with x; the finger is below the floor far on the slope's open side.
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}), make_plane({0, 0, 0}, {-1, 0, 2})});
  const Vector3d finger(-0.2, 0.0, -0.01);
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(s.active_count == 1);
  REQUIRE(s.active[0].plane == 0);
  require_kkt(planes, finger, s);
}

TEST_CASE("three planes: the proxy is held in the corner") {
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {1, 0, 0}), make_plane({0, 0, 0}, {0, 1, 0}),
                                    make_plane({0, 0, 0}, {0, 0, 1})});
  const Vector3d finger(-0.01, -0.02, -0.03);
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(s.active_count == 3);
  REQUIRE(s.proxy_m.norm() < kTol);
  require_kkt(planes, finger, s);
}

TEST_CASE("duplicate planes act as one and share the load") {
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}, 1), make_plane({0, 0, 0}, {0, 0, 1}, 2)});
  const Vector3d finger(0.0, 0.0, -0.01);
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(s.active_count == 1);
  REQUIRE(std::abs(s.proxy_m.z()) < kTol);
  require_kkt(planes, finger, s);
}

TEST_CASE("parallel planes facing the same way: the outer one holds the proxy") {
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}), make_plane({0, 0, 0.01}, {0, 0, 1})});
  const ProxySolution s = project_outside_planes(planes, Vector3d(0.0, 0.0, -0.02));
  REQUIRE(s.active_count == 1);
  REQUIRE(s.active[0].plane == 1);
  REQUIRE(s.proxy_m.z() == Approx(0.01).margin(kTol));
  require_kkt(planes, Vector3d(0.0, 0.0, -0.02), s);
}

TEST_CASE("planes 1e-9 rad apart are treated as one: no ill-conditioned edge, no NaN") {
  const double angle = 1e-9;
  const Vector3d tilted(0.0, std::sin(angle), std::cos(angle));
  for (const double offset : {0.0, 1e-6, -1e-6}) {
    const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}), make_plane({0, 0, offset}, tilted)});
    for (const Vector3d& finger : {Vector3d(0.0, 0.0, -0.01), Vector3d(0.0, 0.3, -0.01), Vector3d(0.1, -0.3, -0.02)}) {
      const ProxySolution s = project_outside_planes(planes, finger);
      REQUIRE(s.proxy_m.allFinite());
      REQUIRE(!s.infeasible);
      REQUIRE(s.active_count == 1);
      for (std::uint32_t k = 0; k < planes.count; ++k) REQUIRE(slack(planes.planes[k], s.proxy_m) >= -1e-12);
      REQUIRE((s.proxy_m - finger).norm() == Approx(-finger.z() + std::max(0.0, offset)).margin(1e-9));
    }
  }
}

TEST_CASE("pinched between two objects whose planes overlap: midpoint, flagged, finite, both loaded") {
  // Object below with its top at z = 0.01, object above with its bottom at z = 0: no point is outside both.
  const PlaneSet planes = make_set({make_plane({0, 0, 0.01}, {0, 0, 1}, 1), make_plane({0, 0, 0}, {0, 0, -1}, 2)});
  const Vector3d finger(0.02, 0.0, 0.004);
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(s.infeasible);
  REQUIRE(s.proxy_m.allFinite());
  REQUIRE(s.proxy_m.z() == Approx(0.005).margin(kTol));
  REQUIRE(s.proxy_m.x() == Approx(0.02).margin(kTol));
  REQUIRE(s.active_count == 2);
  REQUIRE(s.active[0].multiplier_m > 0.0);
  REQUIRE(s.active[1].multiplier_m > 0.0);
}

TEST_CASE("nearly opposed planes that overlap meet far away: beyond the planes' reach it is a pinch") {
  // Hard case 5 in numbers: a static face at x = -5 mm facing +x, a slider's face 0.14 mm past it facing −x, turned
  // by 3e-5 rad about z. The half-spaces do meet, δ/sin θ ≈ 4.7 m away along y.
  const double angle = 3e-5;
  PlaneSet planes = make_set({make_plane({-0.005, 0, 0}, {1, 0, 0}, 1),
                              make_plane({-0.00514, 0, 0}, {-std::cos(angle), std::sin(angle), 0}, 2)});
  const Vector3d finger(-0.0045, 0.0, 0.0);

  const ProxySolution unbounded = project_outside_planes(planes, finger);
  REQUIRE(!unbounded.infeasible);
  require_kkt(planes, finger, unbounded);
  REQUIRE((unbounded.proxy_m - finger).norm() > 1.0);

  planes.valid_within_m = 0.05;
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(s.infeasible);
  REQUIRE(s.proxy_m.x() == Approx(-0.00507).margin(1e-7));  // the midpoint of the overlap
  REQUIRE(std::abs(s.proxy_m.y()) < 1e-7);
  // Both faces are listed; the finger is behind the slider's only, by 0.64 mm, so the slider takes the reaction.
  REQUIRE(s.active_count == 2);
  for (int j = 0; j < 2; ++j) {
    const ActiveConstraint& c = s.active[j];
    REQUIRE(c.multiplier_m == Approx(planes.planes[c.plane].object_id == 2 ? 0.00064 : 0.0).margin(1e-9));
  }
}

TEST_CASE("a wedge whose crossing is within the planes' reach is solved exactly, bound or not") {
  // A 90° groove: the finger pressed 10 mm into it ends at the groove's edge line, 10 mm away.
  PlaneSet planes = make_set({make_plane({0, 0, 0}, Vector3d(1, 0, 1).normalized(), 1),
                              make_plane({0, 0, 0}, Vector3d(-1, 0, 1).normalized(), 2)});
  const Vector3d finger(0.001, 0.0, -0.01);
  planes.valid_within_m = 0.05;
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(!s.infeasible);
  REQUIRE(s.active_count == 2);
  REQUIRE(s.proxy_m.norm() < 1e-12);
  require_kkt(planes, finger, s);
}

TEST_CASE("random plane sets under a reach bound: the exact projection, or a pinch whose projection is out of reach") {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> uniform(-0.02, 0.02);
  int pinched = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    PlaneSet planes;
    const int n = 2 + trial % 4;
    for (int k = 0; k < n; ++k) {
      planes.planes[planes.count++] = make_plane(Vector3d(uniform(rng), uniform(rng), uniform(rng)),
                                                 Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized(), k);
    }
    const Vector3d finger(uniform(rng), uniform(rng), uniform(rng));
    const ProxySolution unbounded = project_outside_planes(planes, finger);
    planes.valid_within_m = 0.03;
    const ProxySolution bounded = project_outside_planes(planes, finger);
    REQUIRE(bounded.proxy_m.allFinite());
    if (bounded.infeasible && !unbounded.infeasible) {
      ++pinched;
      REQUIRE((unbounded.proxy_m - finger).norm() > planes.valid_within_m);
    } else if (!unbounded.infeasible) {
      REQUIRE((bounded.proxy_m - unbounded.proxy_m).norm() < 1e-12);
    }
  }
  REQUIRE(pinched > 0);  // the sample reaches the case it is about
}

TEST_CASE("a plane reaches only its extent: a finger beside a small ball is not held by its tangent plane") {
  ContactPlane ball = make_plane({0, 0, 0.01}, {0, 0, 1}, 3, true);
  ball.extent_m = 0.01;  // a 1 cm ball's tangent plane at its top
  PlaneSet planes = make_set({ball});
  // Under the plane but 2.5 cm to the side: beside the ball, not in it.
  ProxySolution s = project_outside_planes(planes, Vector3d(0.025, 0.0, 0.005));
  REQUIRE(s.active_count == 0);
  REQUIRE(s.proxy_m == Vector3d(0.025, 0.0, 0.005));
  // Over the ball (5 mm off its top point): held, however deep.
  s = project_outside_planes(planes, Vector3d(0.005, 0.0, -0.003));
  REQUIRE(s.active_count == 1);
  REQUIRE(s.proxy_m.z() == Approx(0.01));
  // No extent (the floor): unbounded.
  planes.planes[0].extent_m = 0.0;
  s = project_outside_planes(planes, Vector3d(0.025, 0.0, 0.005));
  REQUIRE(s.active_count == 1);
}

TEST_CASE("a pocket of tangent planes whose corner lies beside the balls is a pinch, not a far corner") {
  // The finger between two 1 cm balls that have closed on it: their tangent planes face each other, 2° above the
  // horizontal, and overlap by 1 mm at the finger. They do cross, 14 mm above it: beyond a radius from either
  // tangent point, where neither plane is on its ball any more.
  const double tilt = 2.0 * M_PI / 180.0;
  ContactPlane left = make_plane({0.0005, 0, 0}, {std::cos(tilt), 0, std::sin(tilt)}, 1, true);
  ContactPlane right = make_plane({-0.0005, 0, 0}, {-std::cos(tilt), 0, std::sin(tilt)}, 2, true);
  PlaneSet planes = make_set({left, right});
  const Vector3d finger(0, 0, 0);
  const ProxySolution unbounded = project_outside_planes(planes, finger);
  REQUIRE(!unbounded.infeasible);
  REQUIRE(unbounded.proxy_m.z() == Approx(0.0005 / std::tan(tilt)).epsilon(1e-9));
  planes.planes[0].extent_m = planes.planes[1].extent_m = 0.01;
  const ProxySolution s = project_outside_planes(planes, finger);
  REQUIRE(s.infeasible);
  REQUIRE((s.proxy_m - finger).norm() < 0.001);
}

TEST_CASE("four inward-facing planes enclose nothing: defined, finite proxy") {
  // Faces of a tetrahedron with normals pointing inward: the intersection of the half-spaces is empty.
  const Vector3d corners[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  PlaneSet planes;
  for (int i = 0; i < 4; ++i) planes.planes[planes.count++] = make_plane(0.01 * corners[i], corners[i], i);
  const ProxySolution s = project_outside_planes(planes, Vector3d(0.001, 0.002, 0.003));
  REQUIRE(s.infeasible);
  REQUIRE(s.proxy_m.allFinite());
  REQUIRE(s.active_count <= kMaxActiveConstraints + 1);
}

TEST_CASE("random feasible plane sets: the proxy is the exact nearest point outside all planes") {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> uniform(-0.05, 0.05);
  for (int trial = 0; trial < 2000; ++trial) {
    PlaneSet planes;
    const int n = 1 + trial % 6;
    for (int k = 0; k < n; ++k) {
      const Vector3d normal = Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
      const double distance = 0.001 + 0.02 * std::abs(uniform(rng));  // the origin is outside every plane
      planes.planes[planes.count++] = make_plane(-distance * normal, normal, k);
    }
    const Vector3d finger(uniform(rng), uniform(rng), uniform(rng));
    const ProxySolution s = project_outside_planes(planes, finger);
    REQUIRE(!s.infeasible);
    require_kkt(planes, finger, s);
    REQUIRE((s.proxy_m - brute_force_projection(planes, finger)).norm() < 1e-9);
  }
}

TEST_CASE("a plane moving toward the proxy pushes it out") {
  GodObject god;
  const Vector3d finger(0.0, 0.0, -0.005);
  god.solve(make_set({make_plane({0, 0, 0}, {0, 0, 1})}), finger, 1e-3);
  REQUIRE(god.result().contact.proxy_m.z() == Approx(0.0).margin(kTol));
  god.solve(make_set({make_plane({0, 0, 0.01}, {0, 0, 1})}), finger, 1e-3);
  REQUIRE(god.result().contact.proxy_m.z() == Approx(0.01).margin(kTol));

  // A proxy in free space is swept out too when the plane passes over it.
  GodObject free;
  const Vector3d above(0.0, 0.0, 0.005);
  free.solve(make_set({make_plane({0, 0, 0}, {0, 0, 1})}), above, 1e-3);
  REQUIRE(free.result().contact.active_count == 0);
  free.solve(make_set({make_plane({0, 0, 0.01}, {0, 0, 1})}), above, 1e-3);
  REQUIRE(free.result().contact.proxy_m.z() == Approx(0.01).margin(kTol));
}
