// SPDX-License-Identifier: Apache-2.0
// Fuzz target: what a viewer takes from the world view segment, which another process writes and the viewer cannot
// trust. Input: one selector byte, then the bytes of a snapshot (selector bit 0 clear) or of a scene (set); short
// input leaves the rest zero, as in a fresh segment.
// snapshot_problem() / scene_problem() must not crash on any bytes. When they accept, what the viewer then does must
// work: a snapshot's frame message has exactly the length view_protocol.h gives for its counts, every value finite
// but the lateness; a scene's message is valid JSON naming every body, whatever bytes the names hold.

#include "common/contract/world_view.h"
#include "fuzz/fuzz_check.h"
#include "viewer/view_encoding.h"
#include "viewer/view_protocol.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

namespace {

using namespace impetus;

void run_snapshot(const std::uint8_t* data, std::size_t size) {
  static auto snapshot = std::make_unique<WorldSnapshot>();  // static: ~120 KB, too big for the fuzzer's stack
  *snapshot = WorldSnapshot{};
  std::memcpy(snapshot.get(), data, size < sizeof(WorldSnapshot) ? size : sizeof(WorldSnapshot));
  if (*snapshot_problem(*snapshot) != '\0') return;
  static std::string message;
  view::encode_frame(*snapshot, true, 1.0, message);
  std::size_t values = view::kFrameHeaderValues + snapshot->body_count * view::kBodyValues;
  for (std::uint32_t e = 0; e < snapshot->endpoint_count; ++e) {
    values += view::kEndpointValues + snapshot->endpoints[e].plane_count * view::kPlaneValues;
  }
  FUZZ_CHECK(message.size() == values * sizeof(double));
  for (std::size_t i = 0; i < values; ++i) {
    double value;
    std::memcpy(&value, message.data() + i * sizeof(double), sizeof value);
    FUZZ_CHECK(i == 6 || std::isfinite(value));  // [6]: haptic lateness, NaN when unknown
  }
}

void run_scene(const std::uint8_t* data, std::size_t size) {
  static auto scene = std::make_unique<ViewScene>();
  *scene = ViewScene{};
  std::memcpy(scene.get(), data, size < sizeof(ViewScene) ? size : sizeof(ViewScene));
  if (*scene_problem(*scene) != '\0') return;
  const std::string text = view::scene_message(*scene, "fuzz", std::nullopt);
  const nlohmann::json message = nlohmann::json::parse(text, nullptr, false);
  FUZZ_CHECK(!message.is_discarded());
  FUZZ_CHECK(message["bodies"].size() == scene->body_count);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  if (data[0] & 1u) {
    run_scene(data + 1, size - 1);
  } else {
    run_snapshot(data + 1, size - 1);
  }
  return 0;
}
