// SPDX-License-Identifier: Apache-2.0
// The viewer's parts without a browser: what the world publishes for it, the frame encoding, which files it serves,
// its listen address, and reading a trial back.

#include "common/link/dds/dds_world_view.h"
#include "common/link/shm/shm_world_view.h"
#include "common/mesh/mesh_body.h"
#include "common/shape/mesh_geometry.h"
#include "viewer/replay.h"
#include "viewer/request_check.h"
#include "viewer/view_feed.h"
#include "viewer/view_encoding.h"
#include "viewer/view_protocol.h"
#include "viewer/viewer_node.h"
#include "viewer/web_root.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/world.h"
#include "world_manager/world_view.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>
#include <filesystem>
#include <fstream>
#include <memory>

namespace impetus {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(IMPETUS_BINARY_DIR) / "test-output" / "viewer-unit" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<double> values_of(const std::string& message) {
  std::vector<double> values(message.size() / sizeof(double));
  std::memcpy(values.data(), message.data(), values.size() * sizeof(double));
  return values;
}

}  // namespace

namespace {

// The first frame a live feed over DDS shows of `snapshot`: snapshots are best effort, so it is published again, as
// a world does every step, until one is shown (nullptr after 2 s).
std::shared_ptr<const std::string> first_frame(view::LiveFeed& feed, DdsWorldViewPublisher& publisher,
                                               const WorldSnapshot& snapshot) {
  view::Playback playback;
  std::shared_ptr<const std::string> frame;
  for (int attempt = 0; attempt < 400 && frame == nullptr; ++attempt) {
    publisher.publish_snapshot(snapshot);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    feed.poll();
    frame = feed.next_frame(playback, 0.0);
  }
  return frame;
}

}  // namespace

TEST_CASE("the world's snapshot carries every body's pose and the finger, the shm view passes it whole") {
  prepare_engines();
  const Scene scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json");
  World world(scene, WorldOptions{});
  HapticReport report{};
  report.endpoint = 3;
  report.finger_valid = 1;
  report.finger_m = {-0.03, 0.0, 0.025};
  report.proxy_m = {-0.03, 0.0, 0.025};
  report.force_N = {1.0, 2.0, 3.0};
  world.step(&report);
  world.step(&report);

  const std::string shm = "impetus_test_view_" + std::to_string(getpid());
  ShmWorldViewPublisher publisher(shm);
  auto described = std::make_unique<ViewScene>();
  describe_scene(scene, Coupling::impulse, 20.0, 1, *described);
  publisher.publish_scene(*described);
  auto snapshot = std::make_unique<WorldSnapshot>();
  take_snapshot(world, &report, LoopStats{}, nullptr, *snapshot);
  CHECK(snapshot->body_count == scene.objects.size());
  CHECK(snapshot->frame_index == world.frame().frame_index);
  CHECK(snapshot->world_time_s == world.time_s());
  CHECK(snapshot->used_bytes() < sizeof(WorldSnapshot) / 10);  // a 2-body scene sends a fraction of the capacity
  publisher.publish_snapshot(*snapshot);

  ShmWorldViewReader reader(shm);
  auto scene_read = std::make_unique<ViewScene>();
  REQUIRE(reader.read_scene(*scene_read));
  CHECK(scene_read->body_count == scene.objects.size());
  CHECK(std::string(scene_read->bodies[0].name.data()) == scene.objects[0].name);
  auto read = std::make_unique<WorldSnapshot>();
  REQUIRE(reader.read_snapshot(*read));
  CHECK_FALSE(reader.read_snapshot(*read));  // nothing new
  for (std::uint32_t k = 0; k < read->body_count; ++k) {
    CHECK(read->bodies[k].position_m == to_vec3(world.states()[k].pose.position_m));
  }
  REQUIRE(read->endpoint_count == 1);
  CHECK(read->endpoints[0].endpoint == 3);
  CHECK(read->endpoints[0].force_N == Vec3{1.0, 2.0, 3.0});
  CHECK(reader.rejected() == 0);
}

TEST_CASE("over DDS a live feed shows a world publishing in its partition, every body and every plane whole") {
  prepare_engines();
  const Scene scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/stack.json");
  World world(scene, WorldOptions{});
  HapticReport report{};
  report.finger_valid = 1;
  report.finger_m = {0.03, 0.0, 0.21};  // 1 cm above the top box
  report.proxy_m = report.finger_m;
  for (int step = 0; step < 3; ++step) world.step(&report);

  DdsLinkOptions dds;
  dds.partition = "impetus_test_view_" + std::to_string(getpid());
  DdsWorldViewPublisher publisher(dds);
  auto described = std::make_unique<ViewScene>();
  describe_scene(scene, Coupling::local, 20.0, 1, *described);
  auto snapshot = std::make_unique<WorldSnapshot>();
  take_snapshot(world, &report, LoopStats{}, nullptr, *snapshot);
  REQUIRE(snapshot->body_count == scene.objects.size());
  REQUIRE(snapshot->endpoint_count == 1);
  REQUIRE(snapshot->endpoints[0].plane_count > 0);
  publisher.publish_scene(*described);  // before the viewer exists: transient local, it still gets it

  view::LiveFeed feed(describe(dds), [dds]() -> std::unique_ptr<WorldViewReader> {
    return std::make_unique<DdsWorldViewReader>(dds);
  });
  const std::shared_ptr<const std::string> frame = first_frame(feed, publisher, *snapshot);
  REQUIRE(feed.scene() != nullptr);
  CHECK(feed.scene()->find(scene.objects[0].name) != std::string::npos);
  REQUIRE(frame != nullptr);
  // The frame the page gets is the one a shared-memory viewer would get from the same snapshot.
  std::string expected;
  view::encode_frame(*snapshot, true, 1.0, expected);
  CHECK(*frame == expected);
  CHECK(feed.rejected() == 0);
}

TEST_CASE("a tool's report reaches a live page: its grip's and proxy's poses and torque, over both transports") {
  prepare_engines();
  const Scene scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/peg_in_hole.json");
  World world(scene, WorldOptions{});
  HapticReport report{};
  report.finger_valid = 1;
  report.oriented = 1;
  report.finger_m = {0.0, 0.0, 0.07};
  report.proxy_m = {0.0, 0.0, 0.0705};
  report.finger_wxyz = {0.6, 0.0, 0.8, 0.0};
  report.proxy_wxyz = {0.8, 0.0, 0.6, 0.0};
  report.force_N = {0.8, 0.0, -0.1};
  report.torque_Nm = {0.0, -0.04, 0.0};
  world.step(&report);
  auto snapshot = std::make_unique<WorldSnapshot>();
  take_snapshot(world, &report, LoopStats{}, nullptr, *snapshot);
  REQUIRE(snapshot->endpoint_count == 1);
  CHECK(snapshot->endpoints[0].oriented == 1);
  CHECK(snapshot->endpoints[0].finger_wxyz == report.finger_wxyz);
  CHECK(snapshot->endpoints[0].torque_Nm == report.torque_Nm);

  // Shared memory passes it whole.
  const std::string shm = "impetus_test_view_tool_" + std::to_string(getpid());
  ShmWorldViewPublisher shm_publisher(shm);
  shm_publisher.publish_snapshot(*snapshot);
  ShmWorldViewReader reader(shm);
  auto read = std::make_unique<WorldSnapshot>();
  REQUIRE(reader.read_snapshot(*read));
  CHECK(read->endpoints[0].proxy_wxyz == report.proxy_wxyz);
  CHECK(read->endpoints[0].torque_Nm == report.torque_Nm);

  // A live feed told the scene's tool sends it with the scene, and the endpoint's poses with each frame; over DDS the
  // frame is the one shared memory would give.
  DdsLinkOptions dds;
  dds.partition = "impetus_test_view_tool_" + std::to_string(getpid());
  DdsWorldViewPublisher publisher(dds);
  auto described = std::make_unique<ViewScene>();
  describe_scene(scene, Coupling::local, 20.0, 1, *described);
  publisher.publish_scene(*described);
  view::LiveFeed feed(describe(dds), [dds]() -> std::unique_ptr<WorldViewReader> {
    return std::make_unique<DdsWorldViewReader>(dds);
  });
  feed.set_tool(scene.tool->shape);
  const std::shared_ptr<const std::string> frame = first_frame(feed, publisher, *snapshot);
  REQUIRE(feed.scene() != nullptr);
  CHECK(nlohmann::json::parse(*feed.scene()).at("tool").at("size_m")[2] == 0.04);
  REQUIRE(frame != nullptr);
  view::ViewToolFrame tool;
  tool.valid = true;
  tool.grip = {report.finger_m, report.finger_wxyz};
  tool.proxy = {report.proxy_m, report.proxy_wxyz};
  tool.force_N = report.force_N;
  tool.torque_Nm = report.torque_Nm;
  std::string expected;
  view::encode_frame(*snapshot, true, 1.0, expected, &tool);
  CHECK(*frame == expected);
  CHECK(feed.rejected() == 0);
}

TEST_CASE("a pressed clay slab's snapshot carries its dent, and both transports pass it whole") {
  prepare_engines();
  const Scene scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/clay.json");
  World world(scene, WorldOptions{});
  HapticReport report{};
  report.finger_valid = 1;
  report.finger_m = {0.01, 0.0, 0.031};
  report.proxy_m = report.finger_m;
  world.step(&report);
  auto snapshot = std::make_unique<WorldSnapshot>();
  take_snapshot(world, &report, LoopStats{}, nullptr, *snapshot);
  CHECK(snapshot->dent.object_id == -1);  // nothing dented yet
  // A push beyond yield straight down at (1 cm, 0), as a report brings it: 0.05 N·s, a dent of about 0.9 mm.
  report.world_session = world.frame().world_session;
  report.haptic_session = 7;
  report.tick = 50;
  report.haptic_time_s = 0.05;
  report.entry_count = 1;
  ObjectImpulse& entry = report.entries[0];
  entry.object_id = 0;
  entry.impulse_Ns = {0.0, 0.0, -0.06};
  entry.press_Ns = 0.05;
  entry.press_point_Nsm = {0.05 * 0.01, 0.0, 0.05 * 0.03};
  entry.press_point2_Nsm2 = {0.05 * 0.01 * 0.01, 0.0, 0.05 * 0.01 * 0.03, 0.0, 0.0, 0.05 * 0.03 * 0.03};
  world.step(&report);
  const DeformableSurface* clay = world.deformable(0);
  REQUIRE(clay != nullptr);
  REQUIRE(clay->max_dent_m() > 1e-4);
  take_snapshot(world, &report, LoopStats{}, nullptr, *snapshot);
  const ViewDent& dent = snapshot->dent;
  REQUIRE(dent.object_id == 0);
  CHECK(std::string(snapshot_problem(*snapshot)).empty());
  // Point for point on the cells (1 mm) over the pad (6 mm radius) and a cell of rim: 13 to 15 a side.
  CHECK(dent.dx_m == Approx(0.001));
  CHECK(dent.columns >= 13);
  CHECK(dent.columns <= 15);
  float deepest_m = 0.0f;
  for (std::uint32_t k = 0; k < dent.columns * dent.rows; ++k) deepest_m = std::max(deepest_m, dent.depth_m[k]);
  CHECK(deepest_m == Approx(clay->max_dent_m()).epsilon(1e-6));  // the deepest cell, as a float
  // The rim is undented.
  CHECK(dent.depth_m[0] == 0.0f);

  // The page's frame: the flag, then the dent after the endpoints.
  std::string frame;
  view::encode_frame(*snapshot, true, 1.0, frame);
  const std::vector<double> v = values_of(frame);
  CHECK(v[12] == 1.0);
  REQUIRE(v.size() > view::kDentValues + dent.columns * dent.rows);
  const std::size_t at = v.size() - view::kDentValues - dent.columns * dent.rows;
  CHECK(v[at] == 0.0);                  // body 0
  CHECK(v[at + 1] == static_cast<double>(dent.version));
  CHECK(v[at + 2] == dent.columns);
  CHECK(v[at + 6] == dent.dx_m);

  // Shared memory passes it as written.
  const std::string shm = "impetus_test_view_dent_" + std::to_string(getpid());
  ShmWorldViewPublisher shm_publisher(shm);
  shm_publisher.publish_snapshot(*snapshot);
  ShmWorldViewReader shm_reader(shm);
  auto read = std::make_unique<WorldSnapshot>();
  REQUIRE(shm_reader.read_snapshot(*read));
  std::string shm_frame;
  view::encode_frame(*read, true, 1.0, shm_frame);
  CHECK(shm_frame == frame);

  // DDS too (best effort: published until one arrives).
  DdsLinkOptions dds;
  dds.partition = "impetus_test_view_dent_" + std::to_string(getpid());
  DdsWorldViewPublisher dds_publisher(dds);
  DdsWorldViewReader dds_reader(dds);
  bool got = false;
  for (int attempt = 0; attempt < 400 && !got; ++attempt) {
    dds_publisher.publish_snapshot(*snapshot);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    got = dds_reader.read_snapshot(*read);
  }
  REQUIRE(got);
  std::string dds_frame;
  view::encode_frame(*read, true, 1.0, dds_frame);
  CHECK(dds_frame == frame);

  // A dent that does not fit its grid or has a negative depth is refused by name.
  snapshot->dent.columns = kMaxViewDentSide + 1;
  CHECK_THAT(snapshot_problem(*snapshot), Catch::Contains("dent grid size"));
  snapshot->dent.columns = dent.rows;
  snapshot->dent.depth_m[1] = -1e-3f;
  CHECK_THAT(snapshot_problem(*snapshot), Catch::Contains("dent depth"));
  snapshot->dent.object_id = 5;
  CHECK_THAT(snapshot_problem(*snapshot), Catch::Contains("dent of a body"));
}

TEST_CASE("a snapshot with a bad count, a non-finite pose or a non-unit quaternion is named, not used") {
  auto snapshot = std::make_unique<WorldSnapshot>();
  snapshot->world_period_s = 0.05;
  snapshot->body_count = 2;
  CHECK(std::string(snapshot_problem(*snapshot)).empty());
  snapshot->body_count = kMaxViewBodies + 1;
  CHECK_THAT(snapshot_problem(*snapshot), Catch::Contains("body count"));
  snapshot->body_count = 2;
  snapshot->bodies[1].position_m[2] = NAN;
  CHECK_THAT(snapshot_problem(*snapshot), Catch::Contains("not finite"));
  snapshot->bodies[1].position_m[2] = 0.0;
  snapshot->bodies[1].orientation_wxyz = {0.9, 0.0, 0.0, 0.0};
  CHECK_THAT(snapshot_problem(*snapshot), Catch::Contains("unit quaternion"));
}

TEST_CASE("the scene message carries a loaded mesh's triangles in its body frame, an unknown mesh says why not") {
  const Scene scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/meshes.json");
  auto described = std::make_unique<ViewScene>();
  describe_scene(scene, Coupling::impulse, 20.0, 1, *described);
  // A fifth body whose mesh no file of this process gave (a live viewer without --meshes-from).
  REQUIRE(described->body_count < kMaxViewBodies);
  ViewBodyInfo& unknown = described->bodies[described->body_count++];
  unknown = described->bodies[0];
  unknown.shape.mesh_hash ^= 1;
  REQUIRE(find_mesh_geometry(unknown.shape.mesh_hash) == nullptr);
  const nlohmann::json message = nlohmann::json::parse(view::scene_message(*described, "test", std::nullopt));
  const auto& bodies = message["bodies"];
  REQUIRE(bodies.size() == scene.objects.size() + 1);
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    INFO(scene.objects[k].name);
    const auto* mesh_body = dynamic_cast<const MeshBody*>(find_mesh_geometry(scene.objects[k].shape.mesh_hash));
    REQUIRE(mesh_body != nullptr);
    const TriangleMesh& mesh = mesh_body->bvh().mesh();
    const auto& form = bodies[k]["mesh"];
    REQUIRE(form["drawn"] == "triangles");
    REQUIRE(form["vertices_m"].size() == 3 * mesh.vertices_m.size());
    REQUIRE(form["triangles"].size() == 3 * mesh.triangles.size());
    double worst_m = 0.0;
    for (std::size_t v = 0; v < mesh.vertices_m.size(); ++v) {
      for (int i = 0; i < 3; ++i) {
        worst_m = std::max(worst_m, std::abs(form["vertices_m"][3 * v + i].get<double>() - mesh.vertices_m[v][i]));
      }
    }
    CHECK(worst_m <= 0.5e-6 + 1e-12);  // to the micrometre (view_protocol.h)
    bool same_triangles = true;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      for (int i = 0; i < 3; ++i) {
        same_triangles = same_triangles && form["triangles"][3 * t + i] == mesh.triangles[t][i];
      }
    }
    CHECK(same_triangles);
    CHECK(bodies[k]["mesh_hash"].get<std::string>().size() == 16);
  }
  const auto& missing = bodies.back()["mesh"];
  CHECK(missing["drawn"] == "bound");
  CHECK(missing["why"].get<std::string>().find("--meshes-from") != std::string::npos);
  CHECK_FALSE(bodies.back()["mesh"].contains("vertices_m"));
}

TEST_CASE("a mesh of more triangles than a page is sent is sent coarsened to fit, its shape kept to a cell") {
  // A flat sheet of 2·225² = 101 250 triangles, just over the limit.
  constexpr int kCells = 225;
  static_assert(2 * kCells * kCells > static_cast<int>(view::kMaxViewMeshTriangles));
  const fs::path file = fs::temp_directory_path() / ("impetus_viewer_sheet_" + std::to_string(getpid()) + ".obj");
  {
    std::ofstream obj(file);
    for (int j = 0; j <= kCells; ++j) {
      for (int i = 0; i <= kCells; ++i) obj << "v " << i * 1e-3 << ' ' << j * 1e-3 << " 0\n";
    }
    const auto at = [](int i, int j) { return j * (kCells + 1) + i + 1; };
    for (int j = 0; j < kCells; ++j) {
      for (int i = 0; i < kCells; ++i) {
        obj << "f " << at(i, j) << ' ' << at(i + 1, j) << ' ' << at(i + 1, j + 1) << "\n";
        obj << "f " << at(i, j) << ' ' << at(i + 1, j + 1) << ' ' << at(i, j + 1) << "\n";
      }
    }
  }
  const MeshBody& sheet = MeshBody::load(file.string(), Eigen::Vector3d::Ones(), false);
  fs::remove(file);
  auto described = std::make_unique<ViewScene>();
  described->body_count = 1;
  described->bodies[0].shape = sheet.shape();
  const nlohmann::json message = nlohmann::json::parse(view::scene_message(*described, "test", std::nullopt));
  const auto& form = message["bodies"][0]["mesh"];
  REQUIRE(form["drawn"] == "triangles");
  CHECK(form["coarsened_from"] == 101250);
  const std::size_t triangles = form["triangles"].size() / 3;
  CHECK(triangles <= view::kMaxViewMeshTriangles);
  CHECK(triangles > view::kMaxViewMeshTriangles / 4);  // coarsened as little as it must be, cells grown by 1.25
  // The sheet stays flat and in its square, and covers it but for the half cell lost along each border.
  const double cell_m = form["cell_m"].get<double>();
  const auto& v = form["vertices_m"];
  double area_m2 = 0.0, off_m = 0.0;
  for (std::size_t t = 0; t < triangles; ++t) {
    Eigen::Vector3d corner[3];
    for (int k = 0; k < 3; ++k) {
      const std::size_t index = form["triangles"][3 * t + static_cast<std::size_t>(k)].get<std::size_t>();
      corner[k] = Eigen::Vector3d(v[3 * index].get<double>(), v[3 * index + 1].get<double>(),
                                  v[3 * index + 2].get<double>());
      // Body frame: centred on the sheet's bounding box.
      off_m = std::max({off_m, std::abs(corner[k].z()), std::abs(corner[k].x()) - 0.5 * kCells * 1e-3,
                        std::abs(corner[k].y()) - 0.5 * kCells * 1e-3});
    }
    area_m2 += 0.5 * (corner[1] - corner[0]).cross(corner[2] - corner[0]).z();  // + if wound as the sheet
  }
  const double side_m = kCells * 1e-3;
  INFO(triangles << " triangles on cells of " << cell_m << " m, area " << area_m2 << " m² of " << side_m * side_m);
  CHECK(off_m < 1e-12);
  CHECK(area_m2 <= side_m * side_m * (1.0 + 1e-9));
  CHECK(area_m2 > (side_m - 2.0 * cell_m) * (side_m - 2.0 * cell_m));
}

TEST_CASE("a frame message is the header, 7 values per body, and per endpoint 12 plus 6 per plane") {
  auto snapshot = std::make_unique<WorldSnapshot>();
  snapshot->frame_index = 41;
  snapshot->world_time_s = 2.1;
  snapshot->world_period_s = 0.05;
  snapshot->body_count = 2;
  snapshot->bodies[1].position_m = {0.1, 0.2, 0.3};
  snapshot->endpoint_count = 1;
  snapshot->endpoints[0].finger_valid = 1;
  snapshot->endpoints[0].force_N = {0.0, 0.0, 4.5};
  snapshot->endpoints[0].plane_count = 2;
  snapshot->endpoints[0].planes[1].normal = {0.0, 0.0, 1.0};
  std::string message;
  view::encode_frame(*snapshot, true, 1.0, message);
  const std::vector<double> v = values_of(message);
  REQUIRE(v.size() == view::kFrameHeaderValues + 2 * view::kBodyValues + view::kEndpointValues + 2 * view::kPlaneValues);
  CHECK(v[0] == view::kFrameKind);
  CHECK(v[1] == 41);
  CHECK(v[2] == 2.1);
  CHECK(v[4] == 2);
  CHECK(v[5] == 1);
  CHECK(std::isnan(v[6]));  // no haptic lateness known
  const std::size_t body1 = view::kFrameHeaderValues + view::kBodyValues;
  CHECK(v[body1 + 2] == 0.3);
  CHECK(v[body1 + 3] == 1.0);  // w of the identity
  const std::size_t endpoint = view::kFrameHeaderValues + 2 * view::kBodyValues;
  CHECK(v[endpoint + 1] == 1);
  CHECK(v[endpoint + 10] == 4.5);
  CHECK(v[endpoint + 11] == 2);
  CHECK(v[endpoint + view::kEndpointValues + view::kPlaneValues + 5] == 1.0);
}

TEST_CASE("only the page's files are served, nothing outside its folder, nothing hidden") {
  const fs::path dir = scratch("web");
  std::ofstream(dir / "index.html") << "<html></html>";
  std::ofstream(dir / "viewer.js") << "";
  fs::create_directories(dir / "node_modules/three/build");
  fs::create_directories(dir / "node_modules/three/examples/jsm/controls");
  std::ofstream(dir / "node_modules/three/build/three.module.js") << "";
  std::ofstream(dir / "node_modules/three/examples/jsm/controls/OrbitControls.js") << "";
  std::ofstream(dir / "node_modules/three/package.json") << "{}";
  std::ofstream(dir / "secret.txt") << "no";
  const view::WebRoot web(dir);
  CHECK(web.file_for("/") == dir / "index.html");
  CHECK(web.file_for("/index.html?reload=1") == dir / "index.html");
  CHECK(web.file_for("/viewer.js") == dir / "viewer.js");
  CHECK(web.file_for("/three/build/three.module.js") == dir / "node_modules/three/build/three.module.js");
  CHECK(web.file_for("/three/examples/jsm/controls/OrbitControls.js").has_value());
  CHECK_FALSE(web.file_for("/secret.txt"));
  CHECK_FALSE(web.file_for("/three/build/../package.json"));
  CHECK_FALSE(web.file_for("/three/build/../../../secret.txt"));
  CHECK_FALSE(web.file_for("/three/build/.hidden"));
  CHECK_FALSE(web.file_for("/three/build//three.module.js"));
  CHECK_FALSE(web.file_for("/three/build/three.module.js%00"));
  CHECK_FALSE(web.file_for("/three/build/"));
  CHECK_FALSE(web.file_for("../index.html"));
  CHECK(view::content_type(dir / "viewer.js") == "text/javascript; charset=utf-8");

  fs::remove(dir / "node_modules/three/build/three.module.js");
  CHECK_THROWS_WITH(view::WebRoot(dir), Catch::Contains("three.js is not installed") && Catch::Contains("npm ci"));
}

TEST_CASE("the listen address is HOST:PORT on loopback, another address only with --allow-remote") {
  CHECK(view::parse_listen("127.0.0.1:8080", false).port == 8080);
  CHECK(view::parse_listen("[::1]:0", false).host == "::1");
  CHECK_THROWS_WITH(view::parse_listen("0.0.0.0:8080", false), Catch::Contains("--allow-remote"));
  CHECK(view::parse_listen("0.0.0.0:8080", true).host == "0.0.0.0");
  CHECK_THROWS_WITH(view::parse_listen("127.0.0.1:99999", false), Catch::Contains("0 to 65535"));
  CHECK_THROWS_WITH(view::parse_listen("localhost:80", false), Catch::Contains("not an IP address"));
  CHECK_THROWS_WITH(view::parse_listen("8080", false), Catch::Contains("HOST:PORT"));
}

TEST_CASE("a replay reads a trial's scene and logs (every finger's), a malformed log is named with its line and column") {
  const fs::path dir = scratch("replay");
  std::ofstream(dir / "summary.json")
      << R"({"config": {"scene": ")" << IMPETUS_SOURCE_DIR << R"(/scenes/tap.json", "coupling": "local", "world_rate_hz": 20}})";
  const std::string header = "time_s,cube.x_m,cube.y_m,cube.z_m,cube.qw,cube.qx,cube.qy,cube.qz\n";
  std::ofstream(dir / "world.csv") << header << "0.05,0.03,0,0.025,1,0,0,0\n0.1,0.04,0,0.025,1,0,0,0\n";
  std::ofstream(dir / "haptic.csv")
      << "time_s,finger_x_m,finger_y_m,finger_z_m,proxy_x_m,proxy_y_m,proxy_z_m,force_x_N,force_y_N,force_z_N\n"
      << "0.0,-0.01,0,0.025,-0.01,0,0.025,0,0,0\n0.09,0.01,0,0.025,0.005,0,0.025,10,0,0\n";
  const view::Replay replay(dir.string());
  REQUIRE(replay.frame_count() == 2);
  CHECK(replay.scene().coupling == Coupling::local);
  CHECK(replay.frame_at(0.0) == 0);
  CHECK(replay.frame_at(0.099) == 0);
  CHECK(replay.frame_at(0.1) == 1);
  CHECK(replay.frame_at(5.0) == 1);
  auto snapshot = std::make_unique<WorldSnapshot>();
  replay.snapshot(1, *snapshot);
  CHECK(snapshot->world_time_s == 0.1);
  CHECK(snapshot->bodies[0].position_m[0] == 0.04);
  REQUIRE(snapshot->endpoint_count == 1);
  CHECK(snapshot->endpoints[0].force_N[0] == 10.0);  // the haptic row at or before 0.1 s
  CHECK(std::string(snapshot_problem(*snapshot)).empty());

  // A device of several fingers: the second finger's log joins as a second endpoint.
  std::ofstream(dir / "haptic.endpoint1.csv")
      << "time_s,finger_x,finger_y,finger_z,proxy_x,proxy_y,proxy_z,force_x,force_y,force_z\n"
      << "0.0,0.09,0,0.025,0.09,0,0.025,0,0,0\n0.09,0.07,0,0.025,0.055,0,0.025,-3,0,0\n";
  const view::Replay two_fingers(dir.string());
  two_fingers.snapshot(1, *snapshot);
  REQUIRE(snapshot->endpoint_count == 2);
  CHECK(snapshot->endpoints[0].force_N[0] == 10.0);
  CHECK(snapshot->endpoints[1].endpoint == 1);
  CHECK(snapshot->endpoints[1].force_N[0] == -3.0);
  fs::remove(dir / "haptic.endpoint1.csv");

  std::ofstream(dir / "world.csv") << header << "0.05,0.03,0,0.025,1,0,0,0\n0.1,0.04,oops,0.025,1,0,0,0\n";
  CHECK_THROWS_WITH(view::Replay(dir.string()), Catch::Contains("world.csv:3") && Catch::Contains("column 3") &&
                                                    Catch::Contains("cube.y_m"));
  // A huge token is quoted short; a time that is not finite or runs backwards is named with its line.
  std::ofstream(dir / "world.csv") << header << "0.05,0.03,0,0.025,1,0,0,0\n0.1," << std::string(20'000'000, '7')
                                   << "x,0,0.025,1,0,0,0\n";
  try {
    view::Replay{dir.string()};
    FAIL("a 20 MB token was accepted");
  } catch (const view::ReplayError& error) {
    CHECK(std::string(error.what()).size() < 400);
    CHECK_THAT(error.what(), Catch::Contains("world.csv:3") && Catch::Contains("20000001 characters"));
  }
  for (const char* times : {"0.05,nan", "0.1,0.05", "0.05,inf"}) {
    INFO(times);
    const std::string first(times, std::strchr(times, ','));
    const std::string second(std::strchr(times, ',') + 1);
    std::ofstream(dir / "world.csv") << header << first << ",0.03,0,0.025,1,0,0,0\n" << second
                                     << ",0.04,0,0.025,1,0,0,0\n";
    CHECK_THROWS_WITH(view::Replay(dir.string()), Catch::Contains("world.csv:3: time_s"));
  }
  std::ofstream(dir / "world.csv") << header << "0.05,0.03,0,0.025,1,0,0,0\n0.1,0.04,0,0.025,1,0,0,0\n";
  // A log written before the columns carried their units ("force_x") is read too: its times are checked the same way.
  std::ofstream(dir / "haptic.csv")
      << "time_s,finger_x,finger_y,finger_z,proxy_x,proxy_y,proxy_z,force_x,force_y,force_z\n"
      << "0.09,-0.01,0,0.025,-0.01,0,0.025,0,0,0\n0.0,0.01,0,0.025,0.005,0,0.025,10,0,0\n";
  CHECK_THROWS_WITH(view::Replay(dir.string()), Catch::Contains("haptic.csv:3: time_s") &&
                                                    Catch::Contains("runs backwards"));
  std::ofstream(dir / "world.csv") << "time_s,other.x_m\n0.05,1\n";
  CHECK_THROWS_WITH(view::Replay(dir.string()), Catch::Contains("no column 'cube.x_m'"));
  std::ofstream(dir / "summary.json") << R"({"config": {"scene": "no/such/scene.json"}})";
  CHECK_THROWS_WITH(view::Replay(dir.string()), Catch::Contains("/config/scene") && Catch::Contains("no such file"));
}

}  // namespace impetus

namespace impetus {

TEST_CASE("a mesh tool's triangles go to the page with its shape, as a mesh body's do") {
  const fs::path file = fs::temp_directory_path() / "impetus-viewer-tool-wedge.obj";
  {  // a wedge: a triangular prism, 6 corners, 8 triangles
    std::ofstream obj(file);
    obj << "v 0 0 0\nv 0.02 0 0\nv 0 0.01 0\nv 0 0 0.03\nv 0.02 0 0.03\nv 0 0.01 0.03\n"
        << "f 1 3 2\nf 4 5 6\nf 1 2 5\nf 1 5 4\nf 2 3 6\nf 2 6 5\nf 3 1 4\nf 3 4 6\n";
  }
  ToolShape tool;
  tool.shape = MeshBody::load(file.string(), Eigen::Vector3d::Ones(), true).shape();
  fs::remove(file);
  auto described = std::make_unique<ViewScene>();
  const nlohmann::json message =
      nlohmann::json::parse(view::scene_message(*described, "test", std::nullopt, &tool));
  const auto& form = message.at("tool").at("mesh");
  CHECK(message.at("tool").at("shape") == "mesh");
  REQUIRE(form.at("drawn") == "triangles");
  CHECK(form.at("triangles").size() == 3 * 8);
  CHECK(form.at("vertices_m").size() == 3 * 6);
}

TEST_CASE("a tool's replay carries its shape, and its grip's and proxy's poses from the tool log, into the messages") {
  const fs::path dir = scratch("replay_tool");
  std::ofstream(dir / "summary.json") << R"({"config": {"scene": ")" << IMPETUS_SOURCE_DIR
                                      << R"(/scenes/peg_in_hole.json", "coupling": "local", "world_rate_hz": 20}})";
  std::ofstream(dir / "world.csv") << "time_s,cube.x_m,cube.y_m,cube.z_m,cube.qw,cube.qx,cube.qy,cube.qz\n"
                                   << "0.05,0.08,0,0.015,1,0,0,0\n0.1,0.08,0,0.015,1,0,0,0\n";
  std::ofstream(dir / "haptic.csv")
      << "time_s,finger_x_m,finger_y_m,finger_z_m,proxy_x_m,proxy_y_m,proxy_z_m,force_x_N,force_y_N,force_z_N\n"
      << "0.0,0,0,0.1,0,0,0.1,0,0,0\n0.09,0,0,0.06,0,0,0.061,0,0,2\n";
  // Without the tool's log the grip is shown as a finger's, and no tool.
  CHECK(view::Replay(dir.string()).tool() == nullptr);

  const std::string header =
      "time_s,tick,grip_x_m,grip_y_m,grip_z_m,grip_qw,grip_qx,grip_qy,grip_qz,proxy_x_m,proxy_y_m,proxy_z_m,proxy_qw,"
      "proxy_qx,proxy_qy,proxy_qz,force_x_N,force_y_N,force_z_N,torque_x_Nm,torque_y_Nm,torque_z_Nm,active_contacts,"
      "flags\n";
  std::ofstream(dir / "haptic.tool.csv") << header << "0.0,0,0,0,0.1,1,0,0,0,0,0,0.1,1,0,0,0,0,0,0,0,0,0,0,1\n"
                                         << "0.09,90,0,0,0.06,0.8,0,0.6,0,0,0,0.061,1,0,0,0,0,0,2,0,-0.2,0,4,1\n";
  const view::Replay replay(dir.string());
  REQUIRE(replay.tool() != nullptr);
  CHECK(replay.tool()->shape.kind == ShapeKind::box);
  CHECK(replay.tool()->placement.position_m.z() == Approx(-0.03));
  const view::ViewToolFrame& late = *replay.tool_frame(1);  // the row at or before 0.1 s
  CHECK(late.valid);
  CHECK(late.grip.orientation_wxyz[2] == 0.6);
  CHECK(late.proxy.position_m[2] == 0.061);
  CHECK(late.torque_Nm[1] == -0.2);

  const std::string scene = view::scene_message(replay.scene(), dir.string(), std::nullopt, replay.tool());
  const nlohmann::json tool = nlohmann::json::parse(scene).at("tool");
  CHECK(tool.at("shape") == "box");
  CHECK(tool.at("size_m")[2] == 0.04);
  CHECK(tool.at("placement").at("position_m")[2] == Approx(-0.03));
  CHECK(tool.at("placement").at("orientation_wxyz")[0] == 1.0);

  auto snapshot = std::make_unique<WorldSnapshot>();
  replay.snapshot(1, *snapshot);
  std::string message;
  view::encode_frame(*snapshot, true, 1.0, message, &late);
  const std::vector<double> v = values_of(message);
  const std::size_t before = view::kFrameHeaderValues + snapshot->body_count * view::kBodyValues +
                             view::kEndpointValues;  // the tool follows the one endpoint (no planes, no dent)
  REQUIRE(v.size() == before + view::kToolValues);
  CHECK(v[13] == 1.0);
  CHECK(v[before] == 1.0);            // valid
  CHECK(v[before + 1 + 5] == 0.6);    // the grip's qy
  CHECK(v[before + 8 + 2] == 0.061);  // the proxy's z
  CHECK(v[before + 18 + 1] == -0.2);  // the torque's y

  // A tool log without a column is named; a row without a pose (flags bit 0 clear) shows no tool.
  std::ofstream(dir / "haptic.tool.csv") << "time_s,tick,grip_x_m\n0.0,0,0\n";
  CHECK_THROWS_WITH(view::Replay(dir.string()), Catch::Contains("haptic.tool.csv") && Catch::Contains("grip_y_m"));
  std::ofstream(dir / "haptic.tool.csv") << header << "0.0,0,0,0,0.1,1,0,0,0,0,0,0.1,1,0,0,0,0,0,0,0,0,0,0,0\n";
  CHECK_FALSE(view::Replay(dir.string()).tool_frame(1)->valid);

  // Past the log's end, after a last tick without a pose (the device's session over), the tool rests at its last
  // pose; within the log such a tick still hides it.
  std::ofstream(dir / "haptic.tool.csv") << header << "0.0,0,0,0,0.1,1,0,0,0,0,0,0.1,1,0,0,0,0,0,0,0,0,0,0,1\n"
                                         << "0.03,30,0,0,0.08,1,0,0,0,0,0,0.08,1,0,0,0,0,0,0,0,0,0,0,0\n"
                                         << "0.06,60,0,0,0.07,1,0,0,0,0,0,0.07,1,0,0,0,0,0,0,0,0,0,0,1\n"
                                         << "0.07,70,0,0,0.07,1,0,0,0,0,0,0.07,1,0,0,0,0,0,0,0,0,0,0,0\n";
  const view::Replay ended(dir.string());
  CHECK_FALSE(ended.tool_frame(0)->valid);  // 0.05 s: the row at 0.03, within the log, has no pose
  REQUIRE(ended.tool_frame(1)->valid);  // 0.1 s, past the log's end
  CHECK(ended.tool_frame(1)->grip.position_m[2] == 0.07);
}

TEST_CASE("a replay page plays, pauses, seeks and changes speed on its own clock, bad controls are refused") {
  const fs::path dir = scratch("replay_feed");
  std::ofstream(dir / "summary.json") << R"({"config": {"scene": ")" << IMPETUS_SOURCE_DIR
                                      << R"(/scenes/tap.json", "coupling": "impulse", "world_rate_hz": 20}})";
  std::ofstream world(dir / "world.csv");
  world << "time_s,cube.x_m,cube.y_m,cube.z_m,cube.qw,cube.qx,cube.qy,cube.qz\n";
  for (int i = 1; i <= 20; ++i) world << i * 0.05 << ',' << 0.03 + 0.01 * i << ",0,0.025,1,0,0,0\n";
  world.close();
  view::ReplayFeed feed(dir.string());
  const auto frame_time = [](const std::shared_ptr<const std::string>& message) {
    REQUIRE(message != nullptr);
    return values_of(*message)[2];
  };
  view::Playback page;
  CHECK(frame_time(feed.next_frame(page, 0.0)) == 0.05);  // a new page starts at the first frame
  CHECK(feed.next_frame(page, 0.01) == nullptr);          // nothing new within a frame
  CHECK(frame_time(feed.next_frame(page, 0.1)) == Approx(0.15));
  REQUIRE(feed.control(page, nlohmann::json::parse(R"({"speed": 4})")));
  CHECK(frame_time(feed.next_frame(page, 0.1)) == Approx(0.55));  // 0.15 + 4 × 0.1
  REQUIRE(feed.control(page, nlohmann::json::parse(R"({"play": false})")));
  const auto paused = feed.next_frame(page, 0.0);  // sent again: it carries playing = 0
  CHECK(values_of(*paused)[view::kFrameHeaderValues - 6] == 0.0);
  CHECK(feed.next_frame(page, 1.0) == nullptr);  // paused: the clock stands
  REQUIRE(feed.control(page, nlohmann::json::parse(R"({"seek": 0.5})")));
  CHECK(frame_time(feed.next_frame(page, 1.0)) == Approx(0.5));
  REQUIRE(feed.control(page, nlohmann::json::parse(R"({"play": true})")));
  const auto at_end = feed.next_frame(page, 100.0);
  CHECK(frame_time(at_end) == Approx(1.0));  // stops at the end, on the last frame, saying it stopped
  CHECK(values_of(*at_end)[view::kFrameHeaderValues - 6] == 0.0);
  CHECK(feed.next_frame(page, 1.0) == nullptr);

  view::Playback other;  // another page keeps its own clock
  CHECK(frame_time(feed.next_frame(other, 0.0)) == 0.05);

  for (const char* bad : {R"({"speed": 0})", R"({"speed": 1e9})", R"({"seek": "x"})", R"({"play": 1})",
                          R"({"jump": 1})", R"({"play": true, "speed": 2})", R"([1, 2])", R"("play")", "{}"}) {
    INFO(bad);
    CHECK_FALSE(feed.control(page, nlohmann::json::parse(bad)));
  }
}

}  // namespace impetus

TEST_CASE("the viewer answers only requests naming it as Host, and WebSockets only from its own page") {
  using impetus::view::HostRule;
  using impetus::view::host_problem;
  using impetus::view::origin_problem;
  HostRule loopback;
  loopback.port = 8080;
  for (const char* host : {"127.0.0.1:8080", "localhost:8080", "LOCALHOST:8080", "[::1]:8080", "127.0.0.2:8080"}) {
    INFO(host);
    CHECK(host_problem(host, loopback).empty());
  }
  // DNS rebinding: another site's name pointed at 127.0.0.1.
  CHECK_THAT(host_problem("evil.example:8080", loopback), Catch::Contains("not a loopback name"));
  CHECK_THAT(host_problem("127.0.0.1:9090", loopback), Catch::Contains("port 9090"));
  CHECK_THAT(host_problem("127.0.0.1", loopback), Catch::Contains("port 80"));  // no port: 80
  CHECK_THAT(host_problem("", loopback), Catch::Contains("no Host"));
  for (const char* malformed : {"127.0.0.1:", "127.0.0.1:80x", "[::1", "[::1]x", ":8080", "127.0.0.1:99999"}) {
    INFO(malformed);
    CHECK_THAT(host_problem(malformed, loopback), Catch::Contains("is not HOST[:PORT]"));
  }
  CHECK(host_problem(std::string(10000, 'a'), loopback).size() < 300);  // the client's text is quoted short

  HostRule remote;
  remote.port = 8080;
  remote.loopback_only = false;
  remote.names = {"lab-pc"};
  for (const char* host : {"192.168.1.20:8080", "[fe80::1]:8080", "lab-pc:8080", "localhost:8080"}) {
    INFO(host);
    CHECK(host_problem(host, remote).empty());
  }
  CHECK_THAT(host_problem("evil.example:8080", remote), Catch::Contains("--allow-host"));

  // Origin: none (not a browser), or the page's own.
  CHECK(origin_problem("", "127.0.0.1:8080").empty());
  CHECK(origin_problem("http://127.0.0.1:8080", "127.0.0.1:8080").empty());
  CHECK(origin_problem("http://LocalHost:8080", "localhost:8080").empty());
  CHECK_THAT(origin_problem("http://evil.example", "127.0.0.1:8080"), Catch::Contains("not this viewer's page"));
  CHECK_FALSE(origin_problem("null", "127.0.0.1:8080").empty());
  CHECK_FALSE(origin_problem("http://127.0.0.1:8081", "127.0.0.1:8080").empty());
  CHECK_FALSE(origin_problem("https://127.0.0.1:8080", "127.0.0.1:8080").empty());
}
