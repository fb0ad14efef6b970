// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/shm_device_port.h"

#include "common/link/shm/names.h"
#include "common/link/shm/open_segment.h"
#include "common/link/shm/wire_frames.h"
#include "common/runtime/process.h"
#include "common/runtime/staleness.h"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>

namespace impetus {
namespace {

// Longest a lockstep device may take for one tick before the host calls it stuck (a hang detector, not a deadline).
constexpr double kTurnTimeout_s = 60.0;

}  // namespace

ShmDevicePortHost::ShmDevicePortHost(const std::string& shm, ClockMode clock, double haptic_period_s,
                                     const DeviceDescription& device, unsigned finger)
    : segment_(Segment<DevicePortLayout>::create(device_port_name(shm, finger), [&](DevicePortLayout& port) {
        port.clock = clock;
        port.haptic_period_s = haptic_period_s;
        port.device_hash = device.hash;
        device.source.copy(port.device_source.data(), port.device_source.size() - 1);
      })) {}

// Its turn semaphores are re-initialised first, while no live device can be waiting on them (the slot is still
// held), so stale posts cannot leak into the next attach.
void ShmDevicePortHost::release_device() {
  segment_->device_turn.reset();
  segment_->detaching.store(0, std::memory_order_release);
  segment_->device_pid.store(0, std::memory_order_release);
  attached_pid_ = 0;
  last_sequence_ = 0;
  have_state_ = false;
}

const DeviceState* ShmDevicePortHost::read_state() {
  if (!segment_->state.try_read(state_wire_, last_sequence_)) return nullptr;
  if (decode(state_wire_, state_) != FrameError::ok) {
    ++rejected_;
    return nullptr;
  }
  have_state_ = true;
  return &state_;
}

const DeviceState* ShmDevicePortHost::lockstep_turn(std::uint64_t tick) {
  const std::int32_t pid = segment_->device_pid.load(std::memory_order_acquire);
  if (pid == 0) return nullptr;
  attached_pid_ = pid;
  segment_->device_turn.give(tick);
  const TurnResult result = segment_->device_turn.wait_done([&] { return process_alive(pid); }, kTurnTimeout_s);
  const bool detaching = segment_->detaching.load(std::memory_order_acquire) != 0;
  if (result != TurnResult::ok || detaching) {
    if (!detaching) {
      // Not a detach: the device died, stopped answering or its turn was corrupted. Lockstep time waits for the next
      // device, so say so rather than wait in silence.
      std::fprintf(stderr, "haptic_controller: the device (pid %d) is lost mid-session: %s; lockstep waits for a "
                           "device to attach (Ctrl-C or SIGTERM to stop)\n", static_cast<int>(pid), to_string(result));
      ++devices_lost_;
    }
    release_device();
    return nullptr;
  }
  return read_state();
}

const DeviceState* ShmDevicePortHost::latest_state(double now_s) {
  const std::int32_t pid = segment_->device_pid.load(std::memory_order_acquire);
  if (pid == 0) return nullptr;
  if (pid != attached_pid_) {
    attached_pid_ = pid;
    fresh_s_ = now_s;  // a new device gets the full grace period for its first state
  }
  if (segment_->detaching.load(std::memory_order_acquire) != 0) {
    release_device();
    return nullptr;
  }
  if (read_state()) fresh_s_ = now_s;
  if (device_stale(now_s - fresh_s_) || !have_state_) {
    // A stale device gets minimum output; a dead one also loses its slot so that a new device can attach.
    if (!process_alive(pid)) {
      ++devices_lost_;
      release_device();
    }
    return nullptr;
  }
  return &state_;
}

void ShmDevicePortHost::send_command(const DeviceCommand& command) {
  encode(command, command_wire_);
  if (!segment_->command.write(command_wire_)) ++repairs_;
}

bool ShmDevicePortHost::wait_for_device() {
  while (segment_->device_pid.load(std::memory_order_acquire) == 0) {
    if (g_stop_requested.load()) return false;
    usleep(1'000);
  }
  return true;
}

void ShmDevicePortHost::end_session() { segment_->device_turn.request_shutdown(); }

ShmDevicePortClient::ShmDevicePortClient(const std::string& shm, ClockMode clock, double timeout_s,
                                         const DeviceDescription& device, unsigned finger)
    : segment_(open_when_ready<DevicePortLayout>(device_port_name(shm, finger), timeout_s)) {
  if (segment_->clock != clock) {
    throw std::runtime_error(std::string("the haptic controller runs --clock ") + to_string(segment_->clock) +
                             " but the device was started with --clock " + to_string(clock));
  }
  if (segment_->device_hash != device.hash) {
    const std::string host_source(segment_->device_source.data());
    throw std::runtime_error("the haptic controller drives the device described by '" + host_source +
                             "' but this device is described by '" + device.source +
                             "', and the two differ: start both with the same --device");
  }
  // A slot held by a live device is an error; one held by a dead device is freed by the host within a few ticks.
  const auto me = static_cast<std::int32_t>(getpid());
  for (double waited_s = 0.0;; waited_s += 0.01) {
    std::int32_t expected = 0;
    if (segment_->device_pid.compare_exchange_strong(expected, me)) return;
    if (waited_s > timeout_s) {
      throw std::runtime_error("the device port is held by process " + std::to_string(expected) +
                               " (another spidar_sim?)");
    }
    if (g_stop_requested.load()) throw std::runtime_error("stopped while waiting for the device port");
    usleep(10'000);
  }
}

ShmDevicePortClient::~ShmDevicePortClient() {
  if (!detached_) segment_->detaching.store(1, std::memory_order_release);
}

bool ShmDevicePortClient::latest_command(DeviceCommand& out) { return commands_.read(segment_->command, out); }

void ShmDevicePortClient::publish_state(const DeviceState& state) {
  encode(state, state_wire_);
  if (!segment_->state.write(state_wire_)) ++repairs_;
}

void ShmDevicePortClient::publish_stats(const LoopStats& stats) {
  if (!segment_->device_stats.write(stats)) ++repairs_;
}

TurnResult ShmDevicePortClient::wait_turn() {
  return segment_->device_turn.wait_turn([&] { return !g_stop_requested.load() && segment_.creator_alive(); });
}

void ShmDevicePortClient::finish_turn() { segment_->device_turn.finish(); }

void ShmDevicePortClient::detach() {
  segment_->detaching.store(1, std::memory_order_release);
  detached_ = true;
}

}  // namespace impetus
