// SPDX-License-Identifier: Apache-2.0
// Users' meshes (common/mesh): reading OBJ and STL, the checks a mesh must pass, mass properties against closed
// forms, and the nearest-point tree against brute force.

#include "common/mesh/mass_properties.h"
#include "common/mesh/mesh_body.h"
#include "common/mesh/mesh_bvh.h"
#include "common/mesh/mesh_check.h"
#include "common/mesh/mesh_file.h"
#include "common/runtime/input_error.h"

#include "tests/support/allocation_counter.h"
#include "tests/support/mesh_shapes.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <random>

using namespace impetus;
using impetus::test::box_mesh;
using impetus::test::icosphere;

namespace {

std::filesystem::path scratch() {
  const std::filesystem::path dir = std::filesystem::path(IMPETUS_BINARY_DIR) / "test-output" / "mesh";
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace

TEST_CASE("mesh: a box's mass, centre and inertia are the closed forms, wherever it sits") {
  const Eigen::Vector3d size(0.1, 0.2, 0.3), centre(1.0, -2.0, 3.0);
  const MassProperties p = mass_properties(box_mesh(size, centre), 500.0);
  const double mass = 500.0 * size.prod();
  CHECK(p.volume_m3 == Approx(size.prod()).epsilon(1e-12));
  CHECK(p.mass_kg == Approx(mass).epsilon(1e-12));
  CHECK((p.centre_of_mass_m - centre).norm() < 1e-12);
  // I = m/12·(b² + c²), … about the centre; no products.
  CHECK(p.inertia_about_com_kgm2(0, 0) == Approx(mass / 12 * (0.04 + 0.09)).epsilon(1e-10));
  CHECK(p.inertia_about_com_kgm2(1, 1) == Approx(mass / 12 * (0.01 + 0.09)).epsilon(1e-10));
  CHECK(p.inertia_about_com_kgm2(2, 2) == Approx(mass / 12 * (0.01 + 0.04)).epsilon(1e-10));
  CHECK(std::abs(p.inertia_about_com_kgm2(0, 1)) < 1e-12);
  CHECK(std::abs(p.inertia_about_com_kgm2(1, 2)) < 1e-12);
}

TEST_CASE("mesh: a turned box's inertia is R·I·Rᵀ, and a sphere's tends to 2/5·m·r²") {
  TriangleMesh box = box_mesh({0.1, 0.2, 0.3});
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (Eigen::Vector3d& v : box.vertices_m) v = r * v;
  const MassProperties turned = mass_properties(box, 1000.0);
  const MassProperties straight = mass_properties(box_mesh({0.1, 0.2, 0.3}), 1000.0);
  CHECK((turned.inertia_about_com_kgm2 - r * straight.inertia_about_com_kgm2 * r.transpose()).norm() <
        1e-12 * straight.inertia_about_com_kgm2.norm());

  const double radius = 0.05;
  const MassProperties ball = mass_properties(icosphere(radius, 5), 1000.0);  // 20 480 triangles
  const double volume = 4.0 / 3.0 * M_PI * radius * radius * radius;
  // An inscribed polyhedron: a little less than the sphere, by the square of the edge over the radius.
  CHECK(ball.volume_m3 < volume);
  CHECK(ball.volume_m3 == Approx(volume).epsilon(2e-3));
  CHECK(ball.centre_of_mass_m.norm() < 1e-15);
  const double expected = 0.4 * ball.mass_kg * radius * radius;
  for (int a = 0; a < 3; ++a) CHECK(ball.inertia_about_com_kgm2(a, a) == Approx(expected).epsilon(3e-3));
}

TEST_CASE("mesh: the checks find open, shared and wound-against edges, and degenerate triangles, by triangle") {
  CHECK(check_mesh(box_mesh({1, 1, 1})).closed());
  CHECK(check_mesh(icosphere(1.0, 2)).closed());
  CHECK(check_mesh(icosphere(1.0, 2)).signed_volume_m3 > 0.0);

  TriangleMesh open = box_mesh({1, 1, 1});
  open.triangles.erase(open.triangles.begin() + 4);
  MeshReport report = check_mesh(open);
  CHECK(report.open_edges == 3);
  CHECK(report.first_open >= 0);
  CHECK_FALSE(report.closed());

  TriangleMesh wound = box_mesh({1, 1, 1});
  std::swap(wound.triangles[7][1], wound.triangles[7][2]);
  report = check_mesh(wound);
  CHECK(report.misoriented_edges == 3);
  CHECK(report.first_misoriented >= 0);

  TriangleMesh doubled = box_mesh({1, 1, 1});
  doubled.triangles.push_back(doubled.triangles[2]);
  CHECK(check_mesh(doubled).nonmanifold_edges == 3);

  TriangleMesh flat = box_mesh({1, 1, 1});
  flat.vertices_m.push_back(Eigen::Vector3d(5, 5, 5));
  flat.triangles.push_back({8, 8, 1});
  report = check_mesh(flat);
  CHECK(report.degenerate_triangles == 1);
  CHECK(report.first_degenerate == 12);
}

TEST_CASE("mesh: a moving body needs a closed mesh with a volume, one wound inside out is turned around") {
  bool flipped = false;
  TriangleMesh inside_out = box_mesh({0.1, 0.1, 0.1});
  flip_winding(inside_out);
  const MeshReport report = require_usable(inside_out, true, "cube.obj", flipped);
  CHECK(flipped);
  CHECK(report.signed_volume_m3 == Approx(1e-3));
  CHECK(mass_properties(inside_out, 1000.0).mass_kg == Approx(1.0));

  TriangleMesh open = box_mesh({0.1, 0.1, 0.1});
  open.triangles.pop_back();
  CHECK_THROWS_WITH(require_usable(open, true, "cup.obj", flipped),
                    Catch::Contains("cup.obj: triangle") && Catch::Contains("open edge"));
  CHECK_NOTHROW(require_usable(open, false, "terrain.obj", flipped));  // a static mesh may be open

  TriangleMesh flat;
  flat.vertices_m = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  flat.triangles = {{0, 1, 2}, {0, 2, 1}};
  CHECK_THROWS_WITH(require_usable(flat, true, "sheet.stl", flipped),
                    Catch::Contains("sheet.stl") && Catch::Contains("no volume"));
}

TEST_CASE("mesh: OBJ, ASCII STL and binary STL read to the same welded mesh, scaled") {
  const TriangleMesh sphere = icosphere(0.04, 2);
  const std::filesystem::path dir = scratch();
  test::write_obj(sphere, (dir / "sphere.obj").string());
  test::write_stl_ascii(sphere, (dir / "sphere_ascii.stl").string());
  test::write_stl_binary(sphere, (dir / "sphere_binary.stl").string());
  for (const char* name : {"sphere.obj", "sphere_ascii.stl", "sphere_binary.stl"}) {
    INFO(name);
    const TriangleMesh read = load_mesh((dir / name).string());
    CHECK(read.triangles.size() == sphere.triangles.size());
    CHECK(read.vertices_m.size() == sphere.vertices_m.size());  // STL's 3 vertices a triangle welded back
    const MeshReport report = check_mesh(read);
    CHECK(report.closed());
    CHECK(report.signed_volume_m3 == Approx(check_mesh(sphere).signed_volume_m3).epsilon(1e-5));
  }
  // Millimetres to metres.
  const TriangleMesh scaled = load_mesh((dir / "sphere.obj").string(), Eigen::Vector3d::Constant(0.001));
  CHECK(check_mesh(scaled).signed_volume_m3 == Approx(check_mesh(sphere).signed_volume_m3 * 1e-9).epsilon(1e-5));
  // A mirror (one negative scale) keeps the winding outward.
  const TriangleMesh mirrored = load_mesh((dir / "sphere.obj").string(), Eigen::Vector3d(-1, 1, 1));
  CHECK(check_mesh(mirrored).signed_volume_m3 > 0.0);
}

TEST_CASE("mesh: a missing, foreign, empty or out-of-range file is an error naming it") {
  const std::filesystem::path dir = scratch();
  CHECK_THROWS_WITH(load_mesh((dir / "nothing.obj").string()),
                    Catch::Contains("nothing.obj") && Catch::Contains("cannot open"));
  std::ofstream(dir / "words.stl") << "this is not a mesh at all\n";
  CHECK_THROWS_WITH(load_mesh((dir / "words.stl").string()), Catch::Contains("words.stl"));
  std::ofstream(dir / "points.obj") << "v 0 0 0\nv 1 0 0\n";
  CHECK_THROWS_WITH(load_mesh((dir / "points.obj").string()), Catch::Contains("points.obj"));
  std::ofstream(dir / "far.obj") << "v 0 0 0\nv 1 0 0\nv 0 5000 0\nf 1 2 3\n";
  CHECK_THROWS_WITH(load_mesh((dir / "far.obj").string()),
                    Catch::Contains("far.obj: vertex 3") && Catch::Contains("scale"));
}

TEST_CASE("mesh: the tree's nearest point, distance and side agree with brute force, at faces, edges and corners") {
  const TriangleMesh sphere = icosphere(0.05, 3);  // 1 280 triangles
  const MeshBvh tree(sphere);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-0.08, 0.08);
  int inside = 0;
  for (int q = 0; q < 2000; ++q) {
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    const double best = impetus::test::brute_force_distance(sphere, p);
    MeshPoint found;
    REQUIRE(tree.nearest(p, found));
    CHECK(std::abs(found.signed_distance_m) == Approx(best).margin(1e-15));
    // Convex: inside exactly when behind every face's plane.
    bool behind_all = true;
    for (const auto& t : sphere.triangles) {
      const Eigen::Vector3d& a = sphere.vertices_m[t[0]];
      const Eigen::Vector3d n = (sphere.vertices_m[t[1]] - a).cross(sphere.vertices_m[t[2]] - a);
      behind_all = behind_all && (p - a).dot(n) <= 0.0;
    }
    inside += behind_all;
    CHECK((found.signed_distance_m < 0.0) == behind_all);
    CHECK(found.normal.norm() == Approx(1.0));
  }
  CHECK(inside > 100);  // the queries covered the inside too
  // Just outside and inside a vertex and an edge: the side from the pseudo-normal, not a face's.
  const Eigen::Vector3d vertex = sphere.vertices_m[0];
  const Eigen::Vector3d edge_middle = 0.5 * (sphere.vertices_m[sphere.triangles[0][0]] +
                                             sphere.vertices_m[sphere.triangles[0][1]]);
  for (const Eigen::Vector3d& point : {vertex, edge_middle}) {
    MeshPoint out, in;
    REQUIRE(tree.nearest(point * 1.001, out));
    REQUIRE(tree.nearest(point * 0.999, in));
    CHECK(out.signed_distance_m > 0.0);
    CHECK(in.signed_distance_m < 0.0);
  }
  // Started from the last answer along a sliding path, the same distance and side as from scratch.
  MeshPoint last;
  REQUIRE(tree.nearest(Eigen::Vector3d(0.05, 0, 0), last));
  for (int q = 1; q < 3000; ++q) {
    const double s = q * 2e-3;
    const Eigen::Vector3d p = (0.047 + 0.006 * std::sin(7 * s)) *
                              Eigen::Vector3d(std::cos(s) * std::cos(0.3 * s), std::sin(s) * std::cos(0.3 * s),
                                              std::sin(0.3 * s));
    MeshPoint scratch_answer, hinted;
    REQUIRE(tree.nearest(p, scratch_answer));
    REQUIRE(tree.nearest_from(p, last, hinted));
    CHECK(hinted.signed_distance_m == Approx(scratch_answer.signed_distance_m).margin(1e-15));
    last = hinted;
  }
  MeshPoint none;
  CHECK_FALSE(tree.nearest_within(Eigen::Vector3d(0.2, 0, 0), 0.1, none));
  CHECK(tree.nearest_within(Eigen::Vector3d(0.1, 0, 0), 0.06, none));
}

#if IMPETUS_COUNT_ALLOCATIONS
TEST_CASE("mesh: a nearest-point query allocates nothing") {
  const MeshBvh tree(icosphere(0.05, 4));
  MeshPoint out;
  double sum = 0.0;
  impetus::test::start_counting_allocations();
  for (int q = 0; q < 10000; ++q) {
    tree.nearest(Eigen::Vector3d(0.06 * std::sin(q * 0.01), 0.06 * std::cos(q * 0.013), 0.01), out);
    sum += out.signed_distance_m;
  }
  CHECK(impetus::test::stop_counting_allocations() == 0);
  CHECK(std::isfinite(sum));
}
#endif

TEST_CASE("mesh: the hash is the same for the same mesh and differs when a vertex moves") {
  const TriangleMesh a = icosphere(0.05, 2);
  TriangleMesh b = a;
  CHECK(mesh_hash(a) == mesh_hash(b));
  b.vertices_m[5].x() += 1e-12;
  CHECK(mesh_hash(a) != mesh_hash(b));
}

TEST_CASE("mesh: a segment crosses the surface where it does, and enters a body or a thin wall only by going in") {
  const MeshBvh tree(box_mesh(Eigen::Vector3d(0.02, 0.02, 0.02)));
  // Through the box along x: two crossings; from the centre out: one; beside it: none.
  CHECK(tree.segment_crosses(Eigen::Vector3d(-0.05, 0.0, 0.0), Eigen::Vector3d(0.05, 0.0, 0.0), 0.0));
  CHECK(tree.segment_crosses(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.05, 0.0, 0.0), 0.0));
  CHECK_FALSE(tree.segment_crosses(Eigen::Vector3d(-0.05, 0.02, 0.0), Eigen::Vector3d(0.05, 0.02, 0.0), 0.0));
  // A crossing at the very start does not count past t_min: a way that starts on the face and leaves.
  CHECK_FALSE(tree.segment_crosses(Eigen::Vector3d(0.01, 0.0, 0.0), Eigen::Vector3d(0.05, 0.0, 0.0), 1e-9));

  // A 1 mm shell: the outer face at z = 0.0105, the inner one at z = 0.0095 (two boxes, one inside the other, wound
  // against each other), as MeshBody tests it through the shape module.
  TriangleMesh shell = box_mesh(Eigen::Vector3d(0.021, 0.021, 0.021));
  TriangleMesh inner = box_mesh(Eigen::Vector3d(0.019, 0.019, 0.019));
  flip_winding(inner);
  const auto offset = static_cast<std::uint32_t>(shell.vertices_m.size());
  for (const Eigen::Vector3d& v : inner.vertices_m) shell.vertices_m.push_back(v);
  for (const auto& t : inner.triangles) shell.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "impetus-mesh-shell.obj";
  impetus::test::write_obj(shell, file.string());
  const impetus::MeshBody& body = impetus::MeshBody::load(file.string(), Eigen::Vector3d::Ones(), false);
  const Eigen::Vector3d above(0.0, 0.0, 0.02), on_top(0.0, 0.0, 0.0105), cavity(0.0, 0.0, 0.0);
  CHECK(body.segment_enters(above, on_top - above, 1e-9) == false);   // up to the wall, not into it
  CHECK(body.segment_enters(on_top, above - on_top, 1e-9) == false);  // off the wall, outward
  CHECK(body.segment_enters(on_top, cavity - on_top, 1e-9));          // through the 1 mm wall
  CHECK(body.segment_enters(above, cavity - above, 1e-9));            // from outside through it
  CHECK(body.segment_enters(above, Eigen::Vector3d(0.0, 0.0, 0.01) - above, 1e-9));  // into the wall's middle
}

TEST_CASE("mesh: a box and a tessellated ball are convex, a dented ball, a box with a face open and a valley are not") {
  CHECK(MeshBvh(test::box_mesh(Eigen::Vector3d(0.04, 0.02, 0.01))).locally_convex());
  CHECK(MeshBvh(test::icosphere(0.02, 4)).locally_convex());
  TriangleMesh dented = test::icosphere(0.02, 3);
  dented.vertices_m[0] *= 0.9;  // one vertex pushed in: the edges around it bend inward
  CHECK_FALSE(MeshBvh(dented).locally_convex());
  TriangleMesh open = test::box_mesh(Eigen::Vector3d(0.02, 0.02, 0.02));
  open.triangles.pop_back();
  CHECK_FALSE(MeshBvh(open).locally_convex());
  TriangleMesh valley;
  valley.vertices_m = {{-0.05, -0.05, 0.025}, {-0.05, 0.05, 0.025}, {0.0, -0.05, 0.0},
                       {0.0, 0.05, 0.0},      {0.05, -0.05, 0.025}, {0.05, 0.05, 0.025}};
  valley.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};
  CHECK_FALSE(MeshBvh(valley).locally_convex());
}

namespace {

// The first entry by trying every triangle, as MeshBvh::first_entry defines it: `a` in front of the triangle's plane
// or within the tolerance behind it, `b` behind it by more, and the crossing on the triangle to the tolerance; the
// least t, and every triangle that gives it; triangle `skip` is not tried (−1: none).
double brute_force_entry(const MeshBvh& tree, const TriangleMesh& mesh, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b, double tolerance_m, int skip,
                         std::vector<std::uint32_t>& at_least_t) {
  const std::vector<Eigen::Vector3d> normals = face_normals(mesh);
  double best = std::numeric_limits<double>::infinity();
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    if (static_cast<int>(t) == skip) continue;
    const Eigen::Vector3d& p = mesh.vertices_m[mesh.triangles[t][0]];
    const double height_a = normals[t].dot(a - p), height_b = normals[t].dot(b - p);
    if (height_a < -tolerance_m || height_b >= -tolerance_m) continue;
    const double s = height_a > 0.0 ? height_a / (height_a - height_b) : 0.0;
    MeshEntry on;
    if (s > best || !tree.on_triangle(t, a + s * (b - a), tolerance_m, on)) continue;
    if (s < best) at_least_t.clear();
    best = s;
    at_least_t.push_back(t);
  }
  return best;
}

}  // namespace

TEST_CASE("mesh: the first entry of a way agrees with trying every triangle, on spheres, a box and one triangle") {
  TriangleMesh one;
  one.vertices_m = {{-0.01, -0.01, 0.0}, {0.02, -0.01, 0.0}, {-0.01, 0.02, 0.0}};
  one.triangles = {{0, 1, 2}};
  std::vector<TriangleMesh> meshes = {icosphere(0.05, 1), icosphere(0.05, 4), box_mesh(Eigen::Vector3d(0.08, 0.05,
                                                                                                       0.03)), one};
  for (const TriangleMesh& mesh : meshes) {
    CAPTURE(mesh.triangles.size());
    const MeshBvh tree(mesh);
    std::mt19937 random(5);
    std::uniform_real_distribution<double> coordinate(-0.07, 0.07), step(-0.004, 0.004);
    int entered = 0;
    for (int q = 0; q < 4000; ++q) {
      const Eigen::Vector3d a(coordinate(random), coordinate(random), coordinate(random));
      Eigen::Vector3d b = q % 2 == 0 ? Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random))
                                     : Eigen::Vector3d(a + Eigen::Vector3d(step(random), step(random), step(random)));
      if (q % 5 == 0) b.z() = a.z();  // along a slab: a way that does not move along an axis
      const std::uint32_t skip = static_cast<std::uint32_t>(q) % static_cast<std::uint32_t>(mesh.triangles.size());
      const int skip_count = q % 3 == 0 ? 1 : 0;
      std::vector<std::uint32_t> tied;
      MeshEntry found;
      const bool entry = tree.first_entry(a, b, 1e-9, &skip, skip_count, found);
      const double brute =
          brute_force_entry(tree, mesh, a, b, 1e-9, skip_count == 1 ? static_cast<int>(skip) : -1, tied);
      REQUIRE(entry == (brute <= 1.0));
      if (!entry) continue;
      ++entered;
      CHECK(found.t == brute);
      CHECK(std::find(tied.begin(), tied.end(), found.triangle) != tied.end());
    }
    CHECK(entered > 10);  // ways that enter: 17 through the one triangle, thousands through the spheres
  }
}
