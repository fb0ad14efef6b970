// SPDX-License-Identifier: Apache-2.0
#pragma once
// A generic 3-DoF impedance device behind HapticDevice (haptic_controller/device/haptic_device.h): a linkage that
// reports where its end effector is and renders the force it is told to. This is the worked example of
// docs/devices.md. It is assembled from parts, each testable alone:
//   ImpedanceBackend        the vendor's I/O: a position in the device's own frame and length unit in, a force in the
//                           device frame out (SimulatedImpedanceBackend stands in for hardware in the tests);
//   DeviceCalibration       device frame → world frame: rotation, offset, length unit;
//   GenericImpedanceDevice  staleness and range checks, the force limit, minimum output (zero force).
//
// Units and frames: what the servo sees is SI in the world frame (metres, newtons, seconds; right-handed, z up,
// docs/architecture.md §4). Only the backend speaks the device frame.
//
// Threading: one servo thread owns the device. read(), command() and counters() never allocate, lock, throw or block;
// wait_attached() sleeps (lockstep only, between ticks). The constructor and load_generic_device_config() throw for
// a bad configuration: they run before the loop.

#include "common/runtime/staleness.h"
#include "haptic_controller/device/haptic_device.h"

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace impetus {

// One reading from the backend.
struct DeviceReading {
  // The end effector in the device frame, in the device's length unit (DeviceCalibration::metres_per_unit).
  Eigen::Vector3d position_units = Eigen::Vector3d::Zero();
  // How old the reading already was when poll() returned it (sampling and transport latency, the backend's own
  // clock), seconds. A backend that cannot tell reports 0; a negative or NaN age makes the reading stale.
  double age_s = 0.0;
};

enum class BackendState {
  connected,  // a device is there and answering (or about to)
  absent,     // no device now (not plugged in yet, or gone); one may still come
  closed,     // the backend has shut down for good (a clean exit): no device will come
};

// The vendor's side. Every call is made from the servo thread and must return at once: no allocation, lock, blocking
// I/O or exception. A backend that needs blocking I/O runs it on its own thread and hands over the newest reading
// through a wait-free slot (e.g. SeqlockChannel, common/link/shm/seqlock.h, which also works in ordinary memory).
class ImpedanceBackend {
 public:
  virtual ~ImpedanceBackend() = default;

  virtual BackendState state() const = 0;
  // True and `out` filled if a reading arrived since the last call; false if nothing new (`out` untouched).
  virtual bool poll(DeviceReading& out) = 0;
  // Renders `force_device_N` (device frame, newtons) until the next call. Called every tick; zero is the minimum
  // output. Must be harmless while the device is absent.
  virtual void write_force(const Eigen::Vector3d& force_device_N) = 0;
};

// Device frame → world frame: position_world_m = rotation_device_to_world · (metres_per_unit · position_units)
// + offset_m. Forces go back by the rotation alone (newtons are newtons in either frame): force_device_N =
// rotation_device_to_worldᵀ · force_N. Every field starts as NaN, so a field nobody set is refused, not zero.
struct DeviceCalibration {
  // A proper rotation (orthonormal, determinant +1): its columns are the device's x, y, z axes in the world frame.
  Eigen::Matrix3d rotation_device_to_world = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The device frame's origin in the world frame, metres.
  Eigen::Vector3d offset_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Metres per device length unit: 1 for a device that reports metres, 0.001 for millimetres. It also scales motion:
  // a value above the true unit magnifies the workspace, and the stiffness felt per real metre by the same factor.
  double metres_per_unit = std::numeric_limits<double>::quiet_NaN();
};

struct GenericDeviceConfig {
  DeviceCalibration calibration;
  // The reachable box in the device frame, metres (after metres_per_unit): readings outside it are refused (a
  // linkage cannot be there, so the reading is wrong).
  Eigen::Vector3d workspace_min_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d workspace_max_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Largest force magnitude the device renders (DeviceLimits::max_force_N); larger commands keep their direction and
  // are scaled down to it, counted as saturations.
  double max_force_N = std::numeric_limits<double>::quiet_NaN();
  // A reading older than this is stale: no finger, minimum output. At most the project's device staleness limit
  // (common/runtime/staleness.h), which is also the default: a device may be stricter, never more lenient.
  double max_reading_age_s = kDeviceStale_s;
};

// Bounds a configuration must respect, with their reasons.
struct GenericDeviceBounds {
  static constexpr double kMaxReach_m = 10.0;          // offsets and workspace corners: a room, as for the SPIDAR
  static constexpr double kMaxMetresPerUnit = 1.0;      // a unit above a metre cannot place a finger on a surface
  static constexpr double kMaxForce_N = 1000.0;         // beyond any device a person should hold (as for the SPIDAR)
  static constexpr double kRotationTolerance = 1e-6;    // |RᵀR − I| per entry: six printed digits pass
};

// "" if `config` is usable, else "key: reason" for the first field that is not (key as in the JSON file).
std::string generic_device_config_error(const GenericDeviceConfig& config);

// A device file (JSON, e.g. examples/generic_device/generic_device.json). Every key is required except
// max_reading_age_s; unknown keys and unusable values are errors naming the file and the key.
class GenericDeviceConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
GenericDeviceConfig load_generic_device_config(const std::string& path);

class GenericImpedanceDevice final : public HapticDevice {
 public:
  // `backend` must outlive the device. Throws std::invalid_argument for a configuration that
  // generic_device_config_error() refuses. Commands zero force at once: the device starts at minimum output.
  GenericImpedanceDevice(const GenericDeviceConfig& config, ImpedanceBackend& backend);
  // Commands zero force: a process that ends outside the node's loop (an exception) must not leave it pushing.
  ~GenericImpedanceDevice() override;
  GenericImpedanceDevice(const GenericImpedanceDevice&) = delete;
  GenericImpedanceDevice& operator=(const GenericImpedanceDevice&) = delete;

  const DeviceLimits& limits() const override { return limits_; }
  // Lockstep: sleeps in 1 ms steps until the backend is connected; false once it is closed, the session ended or a
  // stop was requested (common/runtime/process.h g_stop_requested).
  bool wait_attached() override;
  // The finger in the world frame. nullptr: no device, no reading yet, or the newest reading is older than
  // max_reading_age_s. A sample with valid == false: the newest reading is non-finite or outside the workspace
  // (counted once per reading in rejected_frames).
  const FingerSample* read(std::uint64_t tick, double now_s) override;
  // Writes `force_N` (world frame) rotated into the device frame; a magnitude above max_force_N (beyond rounding) is
  // scaled down to it (same direction, counted, returns false). Zero force when `render` is false, after the session
  // ended, when this tick's read() gave no valid sample, or for a non-finite force (counted in refused_forces(),
  // returns false).
  bool command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) override;
  // Zero force from now on; wait_attached() returns false.
  void end_session() override;
  DeviceCounters counters() const override;

  // Ticks on which a reading existed but was too old.
  std::uint64_t stale_reads() const { return stale_reads_; }
  // Non-finite forces asked of command() (the servo never sends one; a bug upstream must not reach the motors).
  std::uint64_t refused_forces() const { return refused_forces_; }
  // The force last written to the backend, device frame.
  const Eigen::Vector3d& last_force_device_N() const { return last_force_device_N_; }

 private:
  bool connected_now();  // asks the backend, counts a device that vanished mid-session
  void take_reading(const DeviceReading& reading, double now_s);
  void write_minimum();

  GenericDeviceConfig config_;
  Eigen::Matrix3d rotation_world_to_device_;
  ImpedanceBackend& backend_;
  DeviceLimits limits_;
  FingerSample sample_;
  bool have_reading_ = false;    // a reading arrived since the device (re)connected
  double reading_age_s_ = 0.0;   // its age when it arrived
  double received_s_ = 0.0;      // servo time when it arrived
  bool have_sample_ = false;     // this tick's read() gave a sample
  bool was_connected_ = false;
  bool session_ended_ = false;
  Eigen::Vector3d last_force_device_N_ = Eigen::Vector3d::Zero();
  std::uint64_t saturations_ = 0;
  std::uint64_t rejected_readings_ = 0;
  std::uint64_t devices_lost_ = 0;
  std::uint64_t stale_reads_ = 0;
  std::uint64_t refused_forces_ = 0;
};

}  // namespace impetus
