// SPDX-License-Identifier: Apache-2.0
// The smooth surface behind a mesh (common/mesh/smooth_surface.h), against a sphere known exactly.

#include "common/mesh/smooth_surface.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/mesh_shapes.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace impetus;
using Eigen::Vector3d;

namespace {

// Directions swept over a great circle tilted off the mesh's axes, `steps` of them.
Vector3d swept(int step, int steps) {
  const double angle = 2.0 * 3.14159265358979323846 * step / steps;
  return Vector3d(std::cos(angle), std::sin(angle), 0.3 * std::sin(angle + 0.4)).normalized();
}

}  // namespace

TEST_CASE("smooth surface: a tessellated ball's farthest point is nearly the sphere's, and moves as it turns") {
  const double radius_m = 0.02;
  const int subdivisions = GENERATE(3, 5);  // 1 280 and 20 480 triangles
  const TriangleMesh ball = test::icosphere(radius_m, subdivisions);
  const SmoothSurface surface(ball);
  constexpr int kSteps = 20000;  // 0.31 mrad a step: many steps a facet
  double worst_radius_m = 0.0, worst_facets_m = 0.0, worst_normal = 0.0, worst_step_m = 0.0, worst_vertex_step_m = 0.0;
  std::uint32_t start = 0;
  Vector3d last_point = Vector3d::Zero(), last_vertex = Vector3d::Zero();
  for (int step = 0; step <= kSteps; ++step) {
    const Vector3d direction = swept(step, kSteps);
    const SmoothPoint point = surface.farthest(direction, start);
    start = point.vertex;
    worst_radius_m = std::max(worst_radius_m, std::abs(point.point_m.dot(direction) - radius_m));
    // The facets' own farthest point is their farthest vertex: the sphere's less up to the sagitta.
    worst_facets_m = std::max(worst_facets_m, radius_m - ball.vertices_m[point.vertex].dot(direction));
    worst_normal = std::max(worst_normal, (point.normal - direction).norm());
    if (step > 0) {
      worst_step_m = std::max(worst_step_m, (point.point_m - last_point).norm());
      worst_vertex_step_m = std::max(worst_vertex_step_m, (ball.vertices_m[point.vertex] - last_vertex).norm());
    }
    last_point = point.point_m;
    last_vertex = ball.vertices_m[point.vertex];
  }
  const double step_m = radius_m * 2.0 * 3.14159265358979323846 / kSteps;  // the sphere's arc a step
  INFO(ball.triangles.size() << " triangles: support height off the radius by " << worst_radius_m
                             << " m (the facets' by " << worst_facets_m << " m), normal by " << worst_normal
                             << ", largest step " << worst_step_m << " m (the sphere's " << step_m
                             << ", the vertices' " << worst_vertex_step_m << ")");
  // Nearer the sphere than the facets are. Not exact: angle-weighted normals at the icosphere's uneven vertices are
  // not quite radial, and the surface follows them.
  CHECK(worst_radius_m < worst_facets_m);
  // The interpolated normal there is about the direction (a patch's own normal differs from it slightly).
  CHECK(worst_normal < 0.01);
  // Across a patch the point moves with the sphere's arc; where two patches meet at a slight kink it steps over
  // (a few per cent of a facet), where the facets' farthest vertex jumps a whole facet.
  CHECK(worst_step_m < 0.1 * worst_vertex_step_m);
}

TEST_CASE("smooth surface: creases are measured, a box's 90 degrees, a tessellated ball's a few") {
  const SmoothSurface box(test::box_mesh(Vector3d(0.04, 0.02, 0.01)));
  CHECK(box.largest_crease_rad() == Approx(3.14159265358979323846 / 2).epsilon(1e-12));
  CHECK(box.largest_crease_rad() > SmoothSurface::kMaxCrease_rad);
  const SmoothSurface ball(test::icosphere(0.02, 3));
  CHECK(ball.largest_crease_rad() < SmoothSurface::kMaxCrease_rad);
  CHECK(ball.largest_crease_rad() > 0.01);
}

TEST_CASE("smooth surface: a climb from anywhere ends on a convex body's farthest point") {
  const TriangleMesh ball = test::icosphere(0.02, 4);
  const SmoothSurface round(ball);
  const Vector3d direction = Vector3d(0.3, -0.5, -0.8).normalized();
  const SmoothPoint from0 = round.farthest(direction, 0);
  const SmoothPoint from_far = round.farthest(direction, 100);
  CHECK((from0.point_m - from_far.point_m).norm() < 1e-15);
  CHECK(from0.point_m.dot(direction) == Approx(0.02).margin(1e-6));
}

#if IMPETUS_COUNT_ALLOCATIONS
TEST_CASE("smooth surface: a query allocates nothing") {
  const SmoothSurface surface(test::icosphere(0.02, 3));
  std::uint32_t start = 0;
  impetus::test::start_counting_allocations();
  for (int step = 0; step < 1000; ++step) start = surface.farthest(swept(step, 1000), start).vertex;
  CHECK(impetus::test::stop_counting_allocations() == 0);
}
#endif
