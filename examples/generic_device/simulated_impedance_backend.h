// SPDX-License-Identifier: Apache-2.0
#pragma once
// A simulated impedance device behind ImpedanceBackend, beside the real ones (docs/architecture.md §7): an end effector
// that stays where it is put, or moves by a fixed step per reading (one reading per lockstep tick), and a record of the
// forces written to it. Faults on request: silence (its readings go stale), NaN, a position anywhere, any reading age,
// unplugging (a device lost), closing (a clean end, as spidar_sim detaches when its trajectory ends).
//
// Positions are in the device frame and the device's length unit, forces in the device frame (newtons), exactly what
// a vendor backend would see. One thread: the test drives it between the servo's calls. poll() and write_force()
// never allocate.

#include "examples/generic_device/generic_impedance_device.h"

#include <Eigen/Core>

#include <cstdint>
#include <limits>

namespace impetus {

class SimulatedImpedanceBackend final : public ImpedanceBackend {
 public:
  BackendState state() const override { return state_; }

  bool poll(DeviceReading& out) override {
    if (state_ != BackendState::connected || !answering_) return false;
    out.position_units = position_units_;
    out.age_s = age_s_;
    position_units_ += step_units_;
    ++readings_;
    if (close_after_readings_ > 0 && readings_ >= close_after_readings_) state_ = BackendState::closed;
    return true;
  }

  void write_force(const Eigen::Vector3d& force_device_N) override {
    last_force_device_N_ = force_device_N;
    if (force_device_N.norm() > largest_force_device_N_.norm()) largest_force_device_N_ = force_device_N;
    ++writes_;
  }

  // The device's side.
  void place(const Eigen::Vector3d& position_units) { position_units_ = position_units; }
  void move_each_reading(const Eigen::Vector3d& step_units) { step_units_ = step_units; }
  void set_age_s(double age_s) { age_s_ = age_s; }
  void go_silent() { answering_ = false; }  // connected, but no new readings: the last one ages
  void answer() { answering_ = true; }
  void return_nan() { position_units_.setConstant(std::numeric_limits<double>::quiet_NaN()); }
  void unplug() { state_ = BackendState::absent; }
  void plug_in() { state_ = BackendState::connected; }
  void close() { state_ = BackendState::closed; }
  // Closes by itself after the n-th reading (0: never).
  void close_after_readings(std::uint64_t n) { close_after_readings_ = n; }

  // What was written to it.
  const Eigen::Vector3d& last_force_device_N() const { return last_force_device_N_; }
  const Eigen::Vector3d& largest_force_device_N() const { return largest_force_device_N_; }
  std::uint64_t writes() const { return writes_; }
  std::uint64_t readings() const { return readings_; }

 private:
  BackendState state_ = BackendState::connected;
  bool answering_ = true;
  Eigen::Vector3d position_units_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d step_units_ = Eigen::Vector3d::Zero();
  double age_s_ = 0.0;
  std::uint64_t close_after_readings_ = 0;
  Eigen::Vector3d last_force_device_N_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d largest_force_device_N_ = Eigen::Vector3d::Zero();
  std::uint64_t writes_ = 0;
  std::uint64_t readings_ = 0;
};

}  // namespace impetus
