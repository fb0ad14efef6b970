// SPDX-License-Identifier: Apache-2.0
#include "examples/generic_device/generic_impedance_device.h"

#include "common/runtime/json_node.h"
#include "common/runtime/message_text.h"
#include "common/runtime/process.h"

#include <nlohmann/json.hpp>

#include <Eigen/LU>

#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

namespace impetus {
namespace {

// How often wait_attached() asks the backend (the SPIDAR's port polls at the same rate, shm_device_port.cpp).
constexpr std::chrono::milliseconds kAttachPoll{1};

// Relative margin above max_force_N that is still "at the limit": the servo scales a force to the limit as f·(max/|f|),
// which comes out up to an ulp above it in about one direction in five. That rounding is not a saturation.
constexpr double kLimitRoundingMargin = 1e-12;

// NaN fails every comparison, so each bound below refuses it too.
bool within(const Eigen::Vector3d& v, double bound) { return (v.array().abs() <= bound).all(); }

std::string rotation_error(const Eigen::Matrix3d& rotation) {
  if (!rotation.allFinite()) return "must hold nine finite numbers";
  const double off = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(off <= GenericDeviceBounds::kRotationTolerance)) {
    return "must be orthonormal (RᵀR = I within " + readable(GenericDeviceBounds::kRotationTolerance) +
           " per entry), is off by " + readable(off);
  }
  // A reflection would turn the right-handed world frame into a left-handed one: forces would push the wrong way.
  if (!(rotation.determinant() > 0.0)) return "must be a rotation (determinant +1), not a reflection";
  return "";
}

// Appended piece by piece: GCC 12 reports a false -Wrestrict for "literal" + std::string at -O3.
std::string vector_text(const Eigen::Vector3d& v) {
  std::string text(1, '[');
  text += readable(v.x());
  text += ", ";
  text += readable(v.y());
  text += ", ";
  text += readable(v.z());
  text += ']';
  return text;
}

[[noreturn]] void fail(const std::string& path, const std::string& key, const std::string& reason) {
  throw GenericDeviceConfigError(path + ": " + key + ": " + reason);
}

const nlohmann::json& required(const nlohmann::json& document, const std::string& path, const char* key) {
  if (!document.contains(key)) fail(path, key, "missing (every key but max_reading_age_s is required)");
  return document.at(key);
}

double number(const nlohmann::json& value, const std::string& path, const std::string& key) {
  if (!value.is_number()) fail(path, key, "must be a number, got " + quote_json(value));
  return value.get<double>();
}

Eigen::Vector3d vector3(const nlohmann::json& value, const std::string& path, const std::string& key) {
  if (!value.is_array() || value.size() != 3) fail(path, key, "must be [x, y, z], got " + quote_json(value));
  return {number(value[0], path, key), number(value[1], path, key), number(value[2], path, key)};
}

Eigen::Matrix3d matrix3(const nlohmann::json& value, const std::string& path, const std::string& key) {
  if (!value.is_array() || value.size() != 3) {
    fail(path, key, "must be three rows of three numbers, got " + quote_json(value));
  }
  Eigen::Matrix3d matrix;
  for (int row = 0; row < 3; ++row) matrix.row(row) = vector3(value[row], path, key).transpose();
  return matrix;
}

}  // namespace

std::string generic_device_config_error(const GenericDeviceConfig& config) {
  using Bounds = GenericDeviceBounds;
  const DeviceCalibration& calibration = config.calibration;
  const std::string rotation = rotation_error(calibration.rotation_device_to_world);
  if (!rotation.empty()) return "rotation_device_to_world: " + rotation;
  if (!within(calibration.offset_m, Bounds::kMaxReach_m)) {
    return "offset_m: must hold three numbers within ±" + readable(Bounds::kMaxReach_m) + " m, got " +
           vector_text(calibration.offset_m);
  }
  if (!(calibration.metres_per_unit > 0.0 && calibration.metres_per_unit <= Bounds::kMaxMetresPerUnit)) {
    return "metres_per_unit: must be positive and at most " + readable(Bounds::kMaxMetresPerUnit) + ", got " +
           readable(calibration.metres_per_unit);
  }
  if (!within(config.workspace_min_m, Bounds::kMaxReach_m)) {
    return "workspace_min_m: must hold three numbers within ±" + readable(Bounds::kMaxReach_m) + " m, got " +
           vector_text(config.workspace_min_m);
  }
  if (!within(config.workspace_max_m, Bounds::kMaxReach_m)) {
    return "workspace_max_m: must hold three numbers within ±" + readable(Bounds::kMaxReach_m) + " m, got " +
           vector_text(config.workspace_max_m);
  }
  if (!(config.workspace_min_m.array() < config.workspace_max_m.array()).all()) {
    return "workspace_max_m: must exceed workspace_min_m " + vector_text(config.workspace_min_m) +
           " on every axis, got " + vector_text(config.workspace_max_m);
  }
  if (!(config.max_force_N > 0.0 && config.max_force_N <= Bounds::kMaxForce_N)) {
    return "max_force_N: must be positive and at most " + readable(Bounds::kMaxForce_N) + ", got " +
           readable(config.max_force_N);
  }
  if (!(config.max_reading_age_s > 0.0 && config.max_reading_age_s <= kDeviceStale_s)) {
    return "max_reading_age_s: must be positive and at most the device staleness limit " + readable(kDeviceStale_s) +
           " s, got " + readable(config.max_reading_age_s);
  }
  return "";
}

GenericDeviceConfig load_generic_device_config(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw GenericDeviceConfigError(path + ": cannot open the device file");
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {  // parse errors, and numbers too large for a double
    throw GenericDeviceConfigError(path + ": not valid JSON: " + excerpt(error.what()));
  }
  if (!document.is_object()) throw GenericDeviceConfigError(path + ": must be a JSON object");
  static const char* const kKeys[] = {"rotation_device_to_world", "offset_m",    "metres_per_unit",
                                      "workspace_min_m",          "workspace_max_m", "max_force_N",
                                      "max_reading_age_s"};
  for (const auto& item : document.items()) {
    bool known = false;
    for (const char* name : kKeys) known = known || item.key() == name;
    if (!known) {
      fail(path, excerpt(item.key(), 80), "unknown key (known: rotation_device_to_world, offset_m, metres_per_unit, "
                                          "workspace_min_m, workspace_max_m, max_force_N, max_reading_age_s)");
    }
  }
  GenericDeviceConfig config;
  DeviceCalibration& calibration = config.calibration;
  calibration.rotation_device_to_world =
      matrix3(required(document, path, "rotation_device_to_world"), path, "rotation_device_to_world");
  calibration.offset_m = vector3(required(document, path, "offset_m"), path, "offset_m");
  calibration.metres_per_unit = number(required(document, path, "metres_per_unit"), path, "metres_per_unit");
  config.workspace_min_m = vector3(required(document, path, "workspace_min_m"), path, "workspace_min_m");
  config.workspace_max_m = vector3(required(document, path, "workspace_max_m"), path, "workspace_max_m");
  config.max_force_N = number(required(document, path, "max_force_N"), path, "max_force_N");
  if (document.contains("max_reading_age_s")) {
    config.max_reading_age_s = number(document.at("max_reading_age_s"), path, "max_reading_age_s");
  }
  const std::string error = generic_device_config_error(config);
  if (!error.empty()) throw GenericDeviceConfigError(path + ": " + error);
  return config;
}

GenericImpedanceDevice::GenericImpedanceDevice(const GenericDeviceConfig& config, ImpedanceBackend& backend)
    : config_(config), backend_(backend) {
  const std::string error = generic_device_config_error(config);
  if (!error.empty()) throw std::invalid_argument("generic impedance device: " + error);
  rotation_world_to_device_ = config.calibration.rotation_device_to_world.transpose();  // a rotation's inverse
  limits_.max_force_N = config.max_force_N;
  write_minimum();
}

GenericImpedanceDevice::~GenericImpedanceDevice() { write_minimum(); }

bool GenericImpedanceDevice::connected_now() {
  const BackendState state = backend_.state();
  const bool connected = state == BackendState::connected;
  if (was_connected_ && !connected) {
    // Gone without the backend closing: lost mid-session (a closed backend left cleanly).
    if (state == BackendState::absent && !session_ended_) ++devices_lost_;
    have_reading_ = false;  // a device that comes back starts from its own first reading, never from this one
  }
  was_connected_ = connected;
  return connected;
}

bool GenericImpedanceDevice::wait_attached() {
  for (;;) {
    if (session_ended_) return false;
    if (connected_now()) return true;
    if (backend_.state() == BackendState::closed || g_stop_requested.load()) return false;
    std::this_thread::sleep_for(kAttachPoll);
  }
}

void GenericImpedanceDevice::take_reading(const DeviceReading& reading, double now_s) {
  have_reading_ = true;
  received_s_ = now_s;
  // An age the backend got wrong (negative, NaN) proves nothing about freshness: the reading counts as stale.
  reading_age_s_ = reading.age_s >= 0.0 ? reading.age_s : std::numeric_limits<double>::infinity();
  const Eigen::Vector3d position_device_m = config_.calibration.metres_per_unit * reading.position_units;
  // Comparisons with NaN are false, so a non-finite coordinate fails the workspace test as well.
  const bool inside = (position_device_m.array() >= config_.workspace_min_m.array()).all() &&
                      (position_device_m.array() <= config_.workspace_max_m.array()).all();
  sample_.valid = inside;
  if (!inside) {
    ++rejected_readings_;
    return;
  }
  // Device frame → world frame: x_world = R · x_device + offset.
  sample_.position_m = config_.calibration.rotation_device_to_world * position_device_m + config_.calibration.offset_m;
}

const FingerSample* GenericImpedanceDevice::read(std::uint64_t /*tick*/, double now_s) {
  have_sample_ = false;
  if (session_ended_ || !connected_now()) return nullptr;
  DeviceReading reading;
  if (backend_.poll(reading)) take_reading(reading, now_s);
  if (!have_reading_) return nullptr;
  // Its age at this tick: its age on arrival plus the servo time since (an infinite age fails the test too).
  if (!(reading_age_s_ + (now_s - received_s_) <= config_.max_reading_age_s)) {
    ++stale_reads_;
    return nullptr;
  }
  have_sample_ = true;
  return &sample_;
}

bool GenericImpedanceDevice::command(std::uint64_t /*tick*/, const Eigen::Vector3d& force_N, bool render) {
  if (!render || session_ended_ || !have_sample_ || !sample_.valid) {
    write_minimum();
    return true;  // the minimum output is always rendered exactly
  }
  if (!force_N.allFinite()) {
    ++refused_forces_;
    write_minimum();
    return false;
  }
  // |f| ≤ max_force_N with the direction kept: f ← f · max_force_N / |f|. stableNorm: a huge finite force must not
  // overflow to an infinite norm, which would scale it to zero instead of to the limit.
  const double magnitude_N = force_N.stableNorm();
  const bool saturated = magnitude_N > limits_.max_force_N * (1.0 + kLimitRoundingMargin);
  Eigen::Vector3d rendered_N = force_N;
  if (saturated) {
    rendered_N *= limits_.max_force_N / magnitude_N;
    ++saturations_;
  }
  // World frame → device frame: f_device = Rᵀ · f_world (a force has no offset and no length unit).
  last_force_device_N_ = rotation_world_to_device_ * rendered_N;
  backend_.write_force(last_force_device_N_);
  return !saturated;
}

void GenericImpedanceDevice::end_session() {
  session_ended_ = true;
  write_minimum();
}

void GenericImpedanceDevice::write_minimum() {
  last_force_device_N_.setZero();
  backend_.write_force(last_force_device_N_);
}

DeviceCounters GenericImpedanceDevice::counters() const {
  DeviceCounters counters;
  counters.saturations = saturations_;
  counters.rejected_frames = rejected_readings_;
  counters.devices_lost = devices_lost_;
  counters.channel_repairs = 0;  // no sequence words between the servo and this backend
  return counters;
}

}  // namespace impetus
