// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/web_hand.h"

#include "common/runtime/loop_stats.h"
#include "common/runtime/staleness.h"

#include <algorithm>
#include <stdexcept>

namespace impetus {

namespace {

// One tick's step is at most this long: after a host stall the hand is not integrated over the whole gap in one go
// with the force of the tick before it (the finger would be thrown by a force that held for 1 ms).
constexpr double kMaxStep_s = 0.005;

}  // namespace

WebHand::WebHand(const WebHandParams& params, TouchPortHost& port, Clock clock)
    : params_(params),
      port_(port),
      clock_(clock != nullptr ? clock : &monotonic_now_ns),
      finger_(params.hand, to_eigen(params.rest_m)),
      target_m_(to_eigen(params.rest_m)) {
  if (!(params.max_force_N > 0.0) || !(params.max_target_speed_mps > 0.0) || !(params.workspace_side_m > 0.0)) {
    throw std::invalid_argument("web hand: max_force_N, max_target_speed_mps and workspace_side_m must be > 0");
  }
  limits_.max_force_N = params.max_force_N;
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5 * params.workspace_side_m);
  workspace_min_m_ = to_eigen(params.workspace_centre_m) - half;
  workspace_max_m_ = to_eigen(params.workspace_centre_m) + half;
  sample_.position_m = finger_.position_m();
  sample_.valid = true;
  sample_.present = false;
}

WebHand::WebHand(const WebHandParams& params, std::unique_ptr<TouchPortHost> port) : WebHand(params, *port) {
  owned_port_ = std::move(port);
}

const FingerSample* WebHand::read(std::uint64_t, double now_s) {
  const std::int64_t now_ns = clock_();
  const double dt_s = last_now_s_ < 0.0 ? 0.0 : std::clamp(now_s - last_now_s_, 0.0, kMaxStep_s);
  last_now_s_ = now_s;

  TouchInput input{};
  const bool have = port_.latest_input(input);
  const auto stale_ns = static_cast<std::int64_t>(kTouchInputStale_s * 1e9);
  // A page holds the hand while it says so and was heard from within the staleness limit. A reception time in the
  // future (more than a tick ahead: not one this host's clock wrote) is not a heartbeat.
  const bool heard = have && input.received_ns <= now_ns + 1'000'000 && now_ns - input.received_ns <= stale_ns;
  const bool holding = have && input.page != 0 && input.released_ns == 0 && heard;

  if (page_ != 0 && (!holding || input.page != page_)) {
    // The page that held the hand ended: by its own word (released_ns), by silence, or by another page's hold (a
    // page takes the hand only after the last let go, viewer/touch_control.h, so this is the same hand let go first).
    const bool said_so = have && input.released_ns != 0;
    let_go(now_ns, said_so ? input.released_ns : input.received_ns, !said_so && input.page == page_);
  }
  if (holding && page_ == 0) {
    page_ = input.page;
    ++counters_.holds;
    target_m_ = finger_.position_m();  // the hand takes the fingertip where it rests: no jump
  }

  if (page_ != 0) {
    // The target moves toward the pointer's (clamped to the workspace) at most max_target_speed_mps.
    const Eigen::Vector3d wanted = to_eigen(input.target_m).cwiseMax(workspace_min_m_).cwiseMin(workspace_max_m_);
    const Eigen::Vector3d previous = target_m_;
    const Eigen::Vector3d step = wanted - target_m_;
    const double reach_m = params_.max_target_speed_mps * dt_s;
    const double distance_m = step.norm();
    target_m_ = distance_m <= reach_m ? wanted : Eigen::Vector3d(target_m_ + step * (reach_m / distance_m));
    if (dt_s > 0.0) {
      finger_.step(target_m_, (target_m_ - previous) / dt_s, force_N_, dt_s);
    }
  }
  counters_.rejected_inputs = port_.rejected_inputs();

  sample_.position_m = finger_.position_m();
  sample_.valid = sample_.position_m.allFinite();
  sample_.present = page_ != 0;

  HandState hand{};
  hand.heartbeat_ns = now_ns;
  hand.finger_m = to_vec3(finger_.position_m());
  hand.workspace_min_m = to_vec3(workspace_min_m_);
  hand.workspace_max_m = to_vec3(workspace_max_m_);
  hand.page = page_;
  hand.max_force_N = params_.max_force_N;
  port_.publish_hand(hand);
  return &sample_;
}

void WebHand::let_go(std::int64_t now_ns, std::int64_t ended_ns, bool timed_out) {
  page_ = 0;
  force_N_.setZero();
  finger_.stop();
  target_m_ = finger_.position_m();
  ++(timed_out ? counters_.timeouts : counters_.releases);
  counters_.last_release_ns = now_ns;
  if (ended_ns > 0 && ended_ns <= now_ns) {
    counters_.max_release_delay_s =
        std::max(counters_.max_release_delay_s, static_cast<double>(now_ns - ended_ns) * 1e-9);
  }
}

bool WebHand::command(std::uint64_t, const Eigen::Vector3d& force_N, bool render) {
  // Nobody holds the hand: the minimum output, whatever the servo asks.
  if (!render || page_ == 0 || !force_N.allFinite()) {
    force_N_.setZero();
    return true;
  }
  const double norm_N = force_N.norm();
  if (norm_N <= params_.max_force_N) {
    force_N_ = force_N;
    return true;
  }
  force_N_ = force_N * (params_.max_force_N / norm_N);
  ++saturations_;
  return false;
}

DeviceCounters WebHand::counters() const {
  DeviceCounters counters;
  counters.saturations = saturations_;
  counters.rejected_frames = counters_.rejected_inputs;
  return counters;
}

nlohmann::json WebHand::details() const {
  return {{"kind", "web"},
          {"source", params_.source},
          {"holds", counters_.holds},
          {"releases", counters_.releases},
          {"timeouts", counters_.timeouts},
          {"rejected_inputs", counters_.rejected_inputs},
          {"last_release_ns", counters_.last_release_ns},
          {"max_release_delay_s", counters_.max_release_delay_s}};
}

}  // namespace impetus
