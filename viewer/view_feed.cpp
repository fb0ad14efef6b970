// SPDX-License-Identifier: Apache-2.0
#include "viewer/view_feed.h"

#include "common/runtime/loop_stats.h"
#include "viewer/view_encoding.h"
#include "viewer/view_protocol.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace impetus::view {

ViewReaderOpener shm_view_opener(const std::string& shm) {
  return [shm]() -> std::unique_ptr<WorldViewReader> {
    try {
      auto reader = std::make_unique<ShmWorldViewReader>(shm);
      // A segment left by a world that died: its successor will replace it.
      if (!reader->world_alive()) return nullptr;
      return reader;
    } catch (const SegmentError& error) {
      // Missing or under construction: the world has not started yet. Anything else (another build's layout) is
      // worth saying.
      if (error.transient()) return nullptr;
      throw std::runtime_error(error.what());
    }
  };
}

LiveFeed::LiveFeed(const std::string& shm) : LiveFeed(shm, shm_view_opener(shm)) {}

LiveFeed::LiveFeed(std::string where, ViewReaderOpener open)
    : where_(std::move(where)),
      open_(std::move(open)),
      scene_(std::make_unique<ViewScene>()),
      snapshot_(std::make_unique<WorldSnapshot>()) {}

std::uint64_t LiveFeed::rejected() const { return rejected_before_ + (reader_ ? reader_->rejected() : 0); }

void LiveFeed::try_attach() {
  const std::int64_t now_ns = monotonic_now_ns();
  if (now_ns < next_attach_ns_) return;
  next_attach_ns_ = now_ns + 100'000'000;  // a world is looked for every 100 ms while there is none
  try {
    reader_ = open_();
    if (!reader_) return;
    std::fprintf(stderr, "viewer: attached to the world at %s\n", reader_->name().c_str());
    last_problem_.clear();
  } catch (const std::runtime_error& error) {
    // Said once, and looked for again in case the world is restarted with a matching build.
    if (last_problem_ != error.what()) {
      last_problem_ = error.what();
      std::fprintf(stderr, "viewer: %s\n", error.what());
    }
  }
}

void LiveFeed::poll() {
  if (!reader_) try_attach();
  if (!reader_) return;
  if (reader_->read_scene(*scene_)) {
    have_scene_ = true;
    scene_message_ =
        std::make_shared<const std::string>(scene_message(*scene_, where_, std::nullopt, tool_ ? &*tool_ : nullptr));
    ++scene_serial_;
  }
  if (have_scene_ && reader_->read_snapshot(*snapshot_) && snapshot_->body_count == scene_->body_count) {
    auto message = std::make_shared<std::string>();
    encode_frame(*snapshot_, true, 1.0, *message, tool_ ? &tool_frame() : nullptr);
    frame_message_ = std::move(message);
    ++frame_serial_;
    ++snapshots_read_;
  }
  if (!reader_->world_alive()) {
    std::fprintf(stderr, "viewer: the world at %s has left; waiting for one to start\n", reader_->name().c_str());
    rejected_before_ += reader_->rejected();
    reader_.reset();
  }
}

const ViewToolFrame& LiveFeed::tool_frame() {
  tool_frame_ = ViewToolFrame{};
  for (std::uint32_t e = 0; e < snapshot_->endpoint_count; ++e) {
    const ViewEndpoint& endpoint = snapshot_->endpoints[e];
    if (endpoint.oriented == 0) continue;
    tool_frame_.valid = endpoint.finger_valid != 0;
    tool_frame_.grip = {endpoint.finger_m, endpoint.finger_wxyz};
    tool_frame_.proxy = {endpoint.proxy_m, endpoint.proxy_wxyz};
    tool_frame_.force_N = endpoint.force_N;
    tool_frame_.torque_Nm = endpoint.torque_Nm;
    break;
  }
  return tool_frame_;
}

std::shared_ptr<const std::string> LiveFeed::next_frame(Playback& playback, double /*elapsed_s*/) {
  if (frame_message_ == nullptr || playback.frame_serial == frame_serial_) return nullptr;
  playback.frame_serial = frame_serial_;
  return frame_message_;
}

bool LiveFeed::control(Playback& /*playback*/, const nlohmann::json& message) { return message.is_object(); }

ReplayFeed::ReplayFeed(const std::string& dir)
    : replay_(dir), snapshot_(std::make_unique<WorldSnapshot>()) {
  scene_message_ = std::make_shared<const std::string>(
      scene_message(replay_.scene(), dir, ReplayRange{replay_.start_s(), replay_.end_s(), replay_.frame_count()},
                    replay_.tool()));
}

std::shared_ptr<const std::string> ReplayFeed::next_frame(Playback& playback, double elapsed_s) {
  if (playback.frame == SIZE_MAX) playback.time_s = replay_.start_s();  // a new page starts at the beginning
  if (playback.playing) {
    playback.time_s += elapsed_s * playback.speed;
    if (playback.time_s >= replay_.end_s()) {  // stop at the end, showing the trial's final state
      playback.time_s = replay_.end_s();
      playback.playing = false;
      playback.frame = SIZE_MAX - 1;  // resend: the page learns it stopped
    }
  }
  const std::size_t frame = replay_.frame_at(playback.time_s);
  if (frame == playback.frame) return nullptr;
  playback.frame = frame;
  replay_.snapshot(frame, *snapshot_);
  auto message = std::make_shared<std::string>();
  encode_frame(*snapshot_, playback.playing, playback.speed, *message, replay_.tool_frame(frame));
  return message;
}

bool ReplayFeed::control(Playback& playback, const nlohmann::json& message) {
  if (!message.is_object() || message.size() != 1) return false;
  const auto entry = message.begin();
  const std::string& key = entry.key();
  const nlohmann::json& value = entry.value();
  if (key == "play" && value.is_boolean()) {
    playback.playing = value.get<bool>();
    if (playback.playing && playback.time_s >= replay_.end_s()) playback.time_s = replay_.start_s();  // play again
  } else if (key == "speed" && value.is_number()) {
    const double speed = value.get<double>();
    if (!(speed >= kMinReplaySpeed && speed <= kMaxReplaySpeed)) return false;
    playback.speed = speed;
  } else if (key == "seek" && value.is_number()) {
    const double time_s = value.get<double>();
    if (!std::isfinite(time_s)) return false;
    playback.time_s = std::clamp(time_s, replay_.start_s(), replay_.end_s());
  } else {
    return false;
  }
  playback.frame = SIZE_MAX - 1;  // send the frame again: it carries the new playing flag and speed
  return true;
}

}  // namespace impetus::view
