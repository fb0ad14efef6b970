// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where a viewer's frames come from: a running world (LiveFeed: read-only shared memory on the world's host, or DDS
// from anywhere) or a finished trial's logs (ReplayFeed). The server calls a feed from its one thread only.

#include "common/contract/world_view.h"
#include "common/link/shm/shm_world_view.h"
#include "viewer/replay.h"
#include "viewer/view_encoding.h"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace impetus::view {

// One page's place in the feed: what it was last sent and, in a replay, its own clock.
struct Playback {
  std::uint64_t scene_serial = 0;  // the scene it was sent
  std::uint64_t frame_serial = 0;  // live: the frame it was sent
  std::size_t frame = SIZE_MAX;    // replay: the frame it was sent
  double time_s = 0.0;             // replay: trial time shown
  double speed = 1.0;
  bool playing = true;
};

class ViewFeed {
 public:
  virtual ~ViewFeed() = default;
  // Picks up whatever is new (a scene, a frame, a world that came or went). Cheap when nothing is.
  virtual void poll() = 0;
  // The scene message (nullptr until there is a scene) and its serial, which changes when the scene does.
  virtual std::shared_ptr<const std::string> scene() const = 0;
  virtual std::uint64_t scene_serial() const = 0;
  // The frame message `playback` should be sent now, or nullptr if it has it already. Advances a replay's clock by
  // `elapsed_s` of wall time.
  virtual std::shared_ptr<const std::string> next_frame(Playback& playback, double elapsed_s) = 0;
  // A page's control message (view_protocol.h §3); false if it is not one (the server then closes that page).
  virtual bool control(Playback& playback, const nlohmann::json& message) = 0;
  // How often poll() and next_frame() are worth calling.
  virtual double poll_period_s() const = 0;
};

// Opens a reader of a running world's view: nullptr while there is none yet (looked for again later); throws
// std::runtime_error for a problem worth saying (said once, and looked for again in case it goes away).
using ViewReaderOpener = std::function<std::unique_ptr<WorldViewReader>()>;
// The world's view in shared memory "<shm>.view", on this host.
ViewReaderOpener shm_view_opener(const std::string& shm);

class LiveFeed final : public ViewFeed {
 public:
  // A world in shared memory.
  explicit LiveFeed(const std::string& shm);
  // Any world `open` finds; `where` names it on the page.
  LiveFeed(std::string where, ViewReaderOpener open);

  void poll() override;
  std::shared_ptr<const std::string> scene() const override { return scene_message_; }
  std::uint64_t scene_serial() const override { return scene_serial_; }
  std::shared_ptr<const std::string> next_frame(Playback& playback, double elapsed_s) override;
  bool control(Playback& playback, const nlohmann::json& message) override;
  // 2 ms: a frame reaches the page within 2 ms of the world publishing it, for a poll that costs one load when idle.
  double poll_period_s() const override { return 0.002; }

  std::uint64_t snapshots_read() const { return snapshots_read_; }
  std::uint64_t rejected() const;
  // The tool in the hand the world's scene names (viewer --meshes-from SCENE; common/tool/tool_block.h): drawn at the
  // pose of the first endpoint whose reports say they are a tool's (HapticReport::oriented).
  void set_tool(const ToolShape& tool) { tool_ = tool; }

 private:
  void try_attach();
  // The tool's poses in the snapshot (not valid when no endpoint is a tool's).
  const ViewToolFrame& tool_frame();

  std::string where_;
  ViewReaderOpener open_;
  std::unique_ptr<WorldViewReader> reader_;
  std::uint64_t rejected_before_ = 0;  // rejections counted by readers of worlds that left
  std::int64_t next_attach_ns_ = 0;
  std::string last_problem_;
  std::unique_ptr<ViewScene> scene_;
  std::unique_ptr<WorldSnapshot> snapshot_;
  bool have_scene_ = false;
  std::shared_ptr<const std::string> scene_message_;
  std::uint64_t scene_serial_ = 0;
  std::shared_ptr<const std::string> frame_message_;
  std::uint64_t frame_serial_ = 0;
  std::uint64_t snapshots_read_ = 0;
  std::optional<ToolShape> tool_;
  ViewToolFrame tool_frame_;
};

class ReplayFeed final : public ViewFeed {
 public:
  explicit ReplayFeed(const std::string& dir);  // throws ReplayError

  void poll() override {}
  std::shared_ptr<const std::string> scene() const override { return scene_message_; }
  std::uint64_t scene_serial() const override { return 1; }
  std::shared_ptr<const std::string> next_frame(Playback& playback, double elapsed_s) override;
  bool control(Playback& playback, const nlohmann::json& message) override;
  double poll_period_s() const override { return 1.0 / 60.0; }  // the page's frame rate

  const Replay& replay() const { return replay_; }

 private:
  Replay replay_;
  std::shared_ptr<const std::string> scene_message_;
  std::unique_ptr<WorldSnapshot> snapshot_;
};

}  // namespace impetus::view
