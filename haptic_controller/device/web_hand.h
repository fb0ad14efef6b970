// SPDX-License-Identifier: Apache-2.0
#pragma once
// The web hand (docs/architecture.md §1.2 "The web hand"): a HapticDevice without hardware. A simulated fingertip,
// held by a hand that follows a target the viewer's page sets (common/hand/finger.h, the same hand as spidar_sim's),
// is pushed by the forces the servo commands, so the finger still stops at surfaces. A person steers it with a pointer.
//
// Safety, as for a real device: while no page holds control, or the controlling page let go (closed, hidden,
// released) or fell silent for kTouchInputStale_s (common/runtime/staleness.h), the finger is not present (the servo
// renders its minimum output) and the fingertip is held at rest where it was. A new hold starts the hand's target at
// the fingertip, and the target follows the pointer at most max_target_speed_mps, inside the workspace.
//
// Real time only: a person's pointer does not wait for lockstep turns. Called from the servo thread: read() and
// command() do not allocate, lock, block or throw.

#include "common/contract/touch.h"
#include "common/hand/finger.h"
#include "common/link/touch_port.h"
#include "haptic_controller/device/haptic_device.h"
#include "haptic_controller/device/web_hand_params.h"

#include <cstdint>
#include <memory>

namespace impetus {

// What the hand counts, for summary.json's haptic.device.
struct WebHandCounters {
  std::uint64_t holds = 0;           // times a page took the hand
  std::uint64_t releases = 0;        // times a page let go and said so (closed, hidden, released)
  std::uint64_t timeouts = 0;        // times a page fell silent and the hand let go
  std::uint64_t rejected_inputs = 0; // unusable inputs the port dropped
  std::int64_t last_release_ns = 0;  // CLOCK_MONOTONIC of the tick the hand last let go (its force was off from it)
  // Longest time from a page's end (its release, or its last message when it fell silent) to the tick that let go.
  double max_release_delay_s = 0.0;
};

class WebHand final : public HapticDevice {
 public:
  using Clock = std::int64_t (*)();  // CLOCK_MONOTONIC ns; tests pass their own
  // `port` must outlive the hand. Throws std::invalid_argument for unusable parameters.
  WebHand(const WebHandParams& params, TouchPortHost& port, Clock clock = nullptr);
  // The same, owning its port.
  WebHand(const WebHandParams& params, std::unique_ptr<TouchPortHost> port);

  const DeviceLimits& limits() const override { return limits_; }
  bool wait_attached() override { return false; }  // real time only
  const FingerSample* read(std::uint64_t tick, double now_s) override;
  bool command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) override;
  void end_session() override {}
  DeviceCounters counters() const override;
  nlohmann::json details() const override;

  const WebHandCounters& hand_counters() const { return counters_; }
  const Finger& finger() const { return finger_; }
  // The target the hand follows now (the pointer's, speed-limited and inside the workspace).
  const Eigen::Vector3d& target_m() const { return target_m_; }

 private:
  void let_go(std::int64_t now_ns, std::int64_t ended_ns, bool timed_out);

  WebHandParams params_;
  std::unique_ptr<TouchPortHost> owned_port_;
  TouchPortHost& port_;
  Clock clock_;
  DeviceLimits limits_;
  Eigen::Vector3d workspace_min_m_, workspace_max_m_;
  Finger finger_;
  Eigen::Vector3d target_m_;
  Eigen::Vector3d force_N_ = Eigen::Vector3d::Zero();  // commanded on the last tick, pushing the fingertip over this one
  std::uint64_t page_ = 0;  // the page holding the hand; 0: nobody
  double last_now_s_ = -1.0;
  FingerSample sample_;
  WebHandCounters counters_;
  std::uint64_t saturations_ = 0;
};

}  // namespace impetus
