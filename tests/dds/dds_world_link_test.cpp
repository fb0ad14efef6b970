// SPDX-License-Identifier: Apache-2.0
// The DDS world link with both ends in this process (Cyclone delivers within a process without the network; the
// daemons' tests in tests/integration and tests/dds/netns_test.sh cross real sockets and hosts). Each test meets in a
// partition of its own, so tests running at once do not see each other.

#include "common/link/dds/dds_codec.h"
#include "common/link/dds/dds_world_link.h"
#include "tests/support/allocation_counter.h"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <thread>

namespace impetus {
namespace {

DdsLinkOptions partition(const std::string& name) {
  DdsLinkOptions options;
  options.partition = "impetus_test_" + name + "_" + std::to_string(getpid());
  return options;
}

WorldLinkInfo realtime_info() {
  WorldLinkInfo info;
  info.world_rate_hz = 20.0;
  info.world_period_s = 0.05;
  info.clock = ClockMode::realtime;
  info.coupling = Coupling::local;
  return info;
}

// A world end that answers: something must take the reports in, as a world's steps do (latest_report), for slots to
// be handed out. Polls `done` until it holds or `timeout_s` passes.
bool serve_until(DdsWorldLinkServer& server, const std::function<bool()>& done, double timeout_s = 10.0) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  HapticReport scratch;
  while (std::chrono::steady_clock::now() < give_up) {
    for (std::uint32_t slot = 0; slot < kMaxEndpoints; ++slot) server.latest_report(slot, scratch);
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

// Attaches a client on another thread while this one serves the world (the client's constructor waits for its slots).
std::unique_ptr<DdsWorldLinkClient> attach(DdsWorldLinkServer& server, const DdsLinkOptions& options,
                                           std::uint32_t endpoints, double wait_s = 10.0) {
  std::unique_ptr<DdsWorldLinkClient> client;
  std::exception_ptr error;
  std::atomic<bool> finished{false};
  std::thread attacher([&] {
    try {
      client = std::make_unique<DdsWorldLinkClient>(options, ClockMode::realtime, wait_s, endpoints);
    } catch (...) {
      error = std::current_exception();
    }
    finished.store(true);
  });
  serve_until(server, [&] { return finished.load(); }, wait_s + 5.0);
  attacher.join();
  if (error) std::rethrow_exception(error);
  return client;
}

PlaneFrame box_frame(std::uint64_t index) {
  PlaneFrame frame{};
  frame.frame_index = index;
  frame.world_session = 77;
  frame.world_time_s = 0.05 * static_cast<double>(index);
  frame.world_period_s = 0.05;
  frame.coupling = Coupling::local;
  frame.stiffness_Npm = 2000.0;
  frame.gravity_mps2 = {0.0, 0.0, -9.81};
  frame.world_substep_s = 0.005;
  frame.reach_radius_m = 0.1;
  frame.plane_count = 2;
  for (std::uint32_t k = 0; k < 2; ++k) {
    Plane& plane = frame.planes[k];
    plane.object_id = static_cast<std::int32_t>(k);
    plane.flags = kPlaneDynamic;
    plane.point_m = {0.005, 0.001 * k, 0.025};
    plane.normal = {-1.0, 0.0, 0.0};
    plane.com_m = {0.03, 0.0, 0.025};
    plane.velocity_mps = {0.1, 0.0, 0.0};
    plane.static_friction = 0.6;
    plane.dynamic_friction = 0.4;
    plane.extent_m = 0.043;
    plane.shape.kind = ShapeKind::box;
    plane.shape.box_size_m = {0.05, 0.05, 0.05};
    plane.body_axis_x = {1.0, 0.0, 0.0};
    plane.body_axis_y = {0.0, 1.0, 0.0};
    plane.inverse_mass_per_kg = 1.0;
    plane.inverse_inertia_world = {2400.0, 0.0, 0.0, 0.0, 2400.0, 0.0, 0.0, 0.0, 2400.0};
    plane.local_contact_count = 1;
    plane.local_contacts[0].normal = {0.0, 0.0, 1.0};
    plane.local_contacts[0].friction = 0.06;
    plane.local_contacts[0].flags = kContactHolds;
  }
  return frame;
}

HapticReport report_of(std::uint64_t session, EndpointId endpoint, std::uint64_t tick) {
  HapticReport report{};
  report.tick = tick;
  report.haptic_session = session;
  report.endpoint = endpoint;
  report.world_session = 77;
  report.haptic_time_s = 0.001 * static_cast<double>(tick);
  report.finger_m = {0.01, 0.0, 0.025};
  report.proxy_m = {0.005, 0.0, 0.025};
  report.finger_valid = 1;
  report.entry_count = 3;
  for (std::uint32_t k = 0; k < 3; ++k) {
    report.entries[k].object_id = static_cast<std::int32_t>(k);
    report.entries[k].epoch = 1;
    report.entries[k].impulse_Ns = {0.001 * static_cast<double>(tick), -0.5 * k, 1e-9};
    report.entries[k].last_tick = tick;
  }
  return report;
}

// Two frames are the same frame if their sealed encodings are the same bytes.
bool same(const PlaneFrame& a, const PlaneFrame& b) {
  static wire::PlaneFrame wa, wb;
  wa = {};
  wb = {};
  encode(a, wa);
  encode(b, wb);
  return used_bytes(wa) == used_bytes(wb) && std::memcmp(&wa, &wb, used_bytes(wa)) == 0;
}
bool same(const HapticReport& a, const HapticReport& b) {
  static wire::HapticReport wa, wb;
  wa = {};
  wb = {};
  encode(a, wa);
  encode(b, wb);
  return used_bytes(wa) == used_bytes(wb) && std::memcmp(&wa, &wb, used_bytes(wa)) == 0;
}

}  // namespace

TEST_CASE("a frame and a report keep every bit through the DDS types, and a count that disagrees is refused") {
  static wire::PlaneFrame sent, received;
  sent = {};
  received = {};
  encode(box_frame(5), sent);
  DdsFrameSample frame_sample;
  to_dds(sent, 42, 3, 7, *frame_sample);
  CHECK((*frame_sample).client_id == 42);
  CHECK((*frame_sample).client_endpoint == 3);
  REQUIRE(from_dds(*frame_sample, received));
  CHECK(std::memcmp(&sent, &received, used_bytes(sent)) == 0);
  static PlaneFrame decoded;
  CHECK(decode(received, decoded) == FrameError::ok);

  // The seal travels: a value changed on the way is caught by decode().
  (*frame_sample).planes._buffer[1].point_m.z += 1e-9;
  REQUIRE(from_dds(*frame_sample, received));
  CHECK(decode(received, decoded) == FrameError::checksum);
  // A count the sequence does not hold cannot even be laid out.
  (*frame_sample).plane_count = 3;
  CHECK_FALSE(from_dds(*frame_sample, received));

  static wire::HapticReport sent_report, received_report;
  sent_report = {};
  received_report = {};
  encode(report_of(9, 1, 1234), sent_report);
  DdsReportSample report_sample;
  to_dds(sent_report, 42, 1, 7, *report_sample);
  REQUIRE(from_dds(*report_sample, received_report));
  CHECK(std::memcmp(&sent_report, &received_report, used_bytes(sent_report)) == 0);
  (*report_sample).entries._length = 2;
  CHECK_FALSE(from_dds(*report_sample, received_report));
}

TEST_CASE("a frame's dent patch travels over DDS only when it has one, and keeps every bit") {
  static wire::PlaneFrame sent, received;
  static PlaneFrame frame, decoded;
  frame = box_frame(5);
  sent = {};
  encode(frame, sent);
  DdsFrameSample sample;
  to_dds(sent, 42, 3, 7, *sample);
  CHECK((*sample).dent_patch.height_m._length == 0);  // no patch: none of its 8 KB sent
  REQUIRE(from_dds(*sample, received));
  CHECK(std::memcmp(&sent, &received, used_bytes(sent)) == 0);

  // A patch: every height, bit for bit, and the frame's seal holds.
  frame.dent_patch.object_id = 0;
  frame.dent_patch.origin_m = {-0.0155, -0.0155, 0.03};
  frame.dent_patch.axis_x = {1.0, 0.0, 0.0};
  frame.dent_patch.axis_y = {0.0, 1.0, 0.0};
  frame.dent_patch.spacing_m = 0.001;
  for (std::size_t k = 0; k < frame.dent_patch.height_m.size(); ++k) {
    frame.dent_patch.height_m[k] = 0.015 - 1e-6 * static_cast<double>(k % 97);
  }
  sent = {};
  encode(frame, sent);
  to_dds(sent, 42, 3, 7, *sample);
  CHECK((*sample).dent_patch.height_m._length == kDentPatchSide * kDentPatchSide);
  REQUIRE(from_dds(*sample, received));
  CHECK(std::memcmp(&sent, &received, used_bytes(sent)) == 0);
  REQUIRE(decode(received, decoded) == FrameError::ok);
  CHECK(decoded.dent_patch.height_m == frame.dent_patch.height_m);
  // Heights for a frame without a patch, or a patch cut short, are refused.
  (*sample).dent_patch.height_m._length = 10;
  CHECK_FALSE(from_dds(*sample, received));
}

TEST_CASE("over DDS a controller is given a slot, its frames arrive whole and the world reads its newest report") {
  const DdsLinkOptions options = partition("cross");
  DdsWorldLinkServer server(options, realtime_info());
  const auto client = attach(server, options, 2);
  CHECK(client->info().world_rate_hz == 20.0);
  CHECK(client->info().coupling == Coupling::local);
  CHECK(client->attaches() == 1);
  CHECK(client->world_alive());

  // Frames on the client's two slots (0 and 1: the first controller takes the first slots) reach its endpoints.
  static PlaneFrame received;
  for (std::uint32_t endpoint = 0; endpoint < 2; ++endpoint) {
    PlaneFrame frame = box_frame(10 + endpoint);
    frame.endpoint = endpoint;
    bool arrived = false;
    // Frames are best effort: publish until one arrives (on a host without loss the first does).
    for (int attempt = 0; attempt < 200 && !arrived; ++attempt) {
      server.publish_frame(endpoint, frame);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      arrived = client->receive_frame(endpoint, received);
    }
    REQUIRE(arrived);
    CHECK(same(received, frame));
  }
  CHECK_FALSE(client->receive_frame(0, received));  // nothing new

  // The newest report of each endpoint reaches its slot.
  const HapticReport first = report_of(5, 0, 100), second = report_of(5, 1, 100);
  client->publish_report(first);
  client->publish_report(second);
  HapticReport latest0, latest1;
  REQUIRE(serve_until(server, [&] {
    return server.latest_report(0, latest0) && latest0.tick == 100 && server.latest_report(1, latest1) &&
           latest1.tick == 100;
  }));
  CHECK(same(latest0, first));
  CHECK(same(latest1, second));
  CHECK(server.rejected_reports() == 0);
  CHECK(client->rejected_frames() == 0);
}

TEST_CASE("over DDS controllers share the world's eight slots, a ninth endpoint is refused with the numbers, and a "
          "controller that leaves frees its slots") {
  const DdsLinkOptions options = partition("slots");
  DdsWorldLinkServer server(options, realtime_info());
  auto five = attach(server, options, 5);
  auto three = attach(server, options, 3);
  try {
    attach(server, options, 1, 1.0);
    FAIL("a ninth endpoint was served");
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    INFO(message);
    CHECK(message.find("0 of 1 endpoint slot") != std::string::npos);
    CHECK(message.find("0 free of 8") != std::string::npos);
    CHECK(message.find(options.partition) != std::string::npos);
  }
  CHECK(server.refused_endpoints() == 1);
  five.reset();  // leaves: its writer disposes its keys
  REQUIRE(serve_until(server, [&] { return server.released_slots() == 5; }));
  auto another = attach(server, options, 4);  // now there is room
  CHECK(another->attaches() == 1);
}

TEST_CASE("the DDS link refuses lockstep and names the domain and partition when no world answers") {
  const DdsLinkOptions options = partition("nobody");
  WorldLinkInfo lockstep = realtime_info();
  lockstep.clock = ClockMode::lockstep;
  CHECK_THROWS_AS(DdsWorldLinkServer(options, lockstep), std::invalid_argument);
  CHECK_THROWS_AS(DdsWorldLinkClient(options, ClockMode::lockstep, 1.0, 1), std::invalid_argument);
  CHECK_THROWS_AS(DdsWorldLinkClient(options, ClockMode::realtime, 1.0, 9), std::invalid_argument);
  DdsLinkOptions bad_domain = options;
  bad_domain.domain_id = kMaxDdsDomainId + 1;
  CHECK_THROWS_AS(DdsWorldLinkClient(bad_domain, ClockMode::realtime, 1.0, 1), std::invalid_argument);
  try {
    DdsWorldLinkClient client(options, ClockMode::realtime, 0.3, 1);
    FAIL("attached to no world");
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    INFO(message);
    CHECK(message.find("no world manager answered") != std::string::npos);
    CHECK(message.find("domain 0 partition '" + options.partition + "'") != std::string::npos);
  }
}

#if IMPETUS_COUNT_ALLOCATIONS
TEST_CASE("the servo's side of the DDS link allocates nothing") {
  const DdsLinkOptions options = partition("alloc");
  DdsWorldLinkServer server(options, realtime_info());
  const auto client = attach(server, options, 1);
  static PlaneFrame received;
  const PlaneFrame frame = box_frame(1);
  bool arrived = false;
  for (int attempt = 0; attempt < 200 && !arrived; ++attempt) {
    server.publish_frame(0, frame);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    arrived = client->receive_frame(0, received);
  }
  REQUIRE(arrived);
  HapticReport report = report_of(3, 0, 1);
  // What one servo tick calls, a thousand times. (The counter sees operator new on every thread; Cyclone's own
  // threads allocate with malloc, which it does not see.)
  test::start_counting_allocations();
  for (std::uint64_t tick = 1; tick <= 1000; ++tick) {
    report.tick = tick;
    client->publish_report(report);
    client->receive_frame(0, received);
  }
  CHECK(test::stop_counting_allocations() == 0);
}
#endif

}  // namespace impetus
