// SPDX-License-Identifier: Apache-2.0
#pragma once
// A finished trial, read back for the viewer's replay (viewer --replay DIR): the scene its summary names, every world
// step's poses from world.csv, and the finger, proxy and force from haptic.csv at each step's time; for a tool in the
// hand, the grip's and the proxy's poses and the wrench from haptic.tool.csv. Planes are not logged, so a replay shows
// none.

#include "common/contract/world_view.h"
#include "viewer/view_encoding.h"

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace impetus::view {

class ReplayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Replay {
 public:
  // Reads DIR/summary.json (config.scene, config.coupling, config.world_rate_hz), the scene file it names (as given,
  // or relative to DIR, its parent, or the source tree), DIR/world.csv and, if present, DIR/haptic.csv. Throws
  // ReplayError naming the file, and the line and column where a log is malformed.
  explicit Replay(const std::string& dir);

  const ViewScene& scene() const { return *scene_; }
  const std::string& dir() const { return dir_; }
  std::size_t frame_count() const { return times_s_.size(); }
  double start_s() const { return times_s_.front(); }
  double end_s() const { return times_s_.back(); }
  double time_s(std::size_t frame) const { return times_s_[frame]; }
  // The last frame at or before `time_s` (the first if before it).
  std::size_t frame_at(double time_s) const;
  // Fills `out` with frame `frame` (< frame_count()).
  void snapshot(std::size_t frame, WorldSnapshot& out) const;
  // The scene's tool and its poses at frame `frame`, when the trial had a tool and logged it (nullptr otherwise).
  const ToolShape* tool() const { return tool_frames_.empty() ? nullptr : &tool_; }
  const ViewToolFrame* tool_frame(std::size_t frame) const {
    return tool_frames_.empty() ? nullptr : &tool_frames_[frame];
  }

 private:
  std::string dir_;
  std::unique_ptr<ViewScene> scene_;
  double world_period_s_ = 0.0;
  std::vector<double> times_s_;
  std::vector<ViewBodyPose> poses_;  // frame_count × body_count, frame-major
  // Per endpoint (at most kMaxViewEndpoints), its finger at every frame.
  std::vector<std::vector<ViewEndpoint>> endpoints_;
  ToolShape tool_;
  std::vector<ViewToolFrame> tool_frames_;  // per frame; empty without a tool log
};

}  // namespace impetus::view
