// SPDX-License-Identifier: Apache-2.0
// impetus._impetus: the compiled half of the Python package (python/impetus/__init__.py is the public half). It runs
// an in-process trial (loop/in_process_trial.h) with the GIL released and reads the CSV logs into numpy arrays; the
// Python half chooses defaults, names the arguments and shapes the results.

#include "loop/in_process_trial.h"
#include "loop/simulation.h"
#include "loop/tool_loop.h"
#include "spidar_sim/trajectory.h"
#include "world_manager/defaults.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <mutex>
#include <optional>
#include <span>
#include <utility>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

namespace py = pybind11;

namespace {

impetus::Coupling parse_coupling(const std::string& name) {
  for (const impetus::Coupling coupling :
       {impetus::Coupling::impulse, impetus::Coupling::position, impetus::Coupling::local}) {
    if (name == impetus::to_string(coupling)) return coupling;
  }
  throw std::invalid_argument("coupling: must be impulse, position or local, not '" + name + "'");
}

// A trajectory from an N x 4 array of waypoints (t, x, y, z in s and m), named `description` in messages.
impetus::Trajectory trajectory_from_array(const py::array_t<double, py::array::c_style | py::array::forcecast>& table,
                                          const std::string& description) {
  if (table.ndim() != 2 || table.shape(1) != 4 || table.shape(0) == 0) {
    throw std::invalid_argument(description + ": must be an N x 4 array of waypoints (t_s, x_m, y_m, z_m), N >= 1");
  }
  std::vector<impetus::Waypoint> waypoints(static_cast<std::size_t>(table.shape(0)));
  const auto rows = table.unchecked<2>();
  for (py::ssize_t i = 0; i < table.shape(0); ++i) {
    waypoints[static_cast<std::size_t>(i)] = {rows(i, 0), {rows(i, 1), rows(i, 2), rows(i, 3)}};
  }
  return impetus::Trajectory::from_waypoints(waypoints, description);
}

// What every in-process run takes from the Python half: the scene (a file, or JSON text named `scene` in messages),
// the coupling, the rates, the contact spring and damper, the link delay and the log directory.
impetus::InProcessTrialOptions trial_options(const std::string& scene, const std::string& scene_text,
                                             const std::string& coupling, bool passivity, std::uint64_t phase_ticks,
                                             std::optional<double> world_rate_hz, std::optional<int> substeps,
                                             const std::optional<std::string>& engine,
                                             std::optional<double> stiffness_Npm, std::optional<double> damping_Nspm,
                                             double link_delay_s, double link_loss, double link_loss_burst,
                                             const std::string& out_dir) {
  impetus::InProcessTrialOptions options;
  options.scene_path = scene;
  options.scene_text = scene_text;
  options.coupling = parse_coupling(coupling);
  options.passivity = passivity;
  options.phase_ticks = phase_ticks;
  options.world_rate_hz = world_rate_hz;
  options.substeps = substeps;
  options.engine = engine;
  if (stiffness_Npm) options.stiffness_Npm = *stiffness_Npm;
  if (damping_Nspm) options.damping_Nspm = *damping_Nspm;
  options.link_delay_s = link_delay_s;
  options.link_loss = link_loss;
  options.link_loss_burst = link_loss_burst;
  options.out_dir = out_dir;
  return options;
}

// The trial's summary.json document as text (the Python half parses it into a dict). The first user's fingers are
// `trajectory`, or `fingers` (NAME=TRAJECTORY specs), or `finger_paths`: (name, spec, waypoints) per finger, each
// played from its N x 4 waypoints when they are given and from its spec (a built-in or a CSV file) otherwise.
using FingerPath = std::tuple<std::string, std::string, std::optional<py::array_t<double>>>;
std::string run_trial(const std::string& scene, const std::string& scene_text, const std::string& trajectory,
                      const std::vector<std::string>& fingers, const std::vector<FingerPath>& finger_paths,
                      const std::vector<std::vector<std::string>>& followers, const std::string& coupling,
                      bool passivity, std::uint64_t phase_ticks, std::optional<double> world_rate_hz, std::optional<int> substeps,
                      const std::optional<std::string>& engine, std::optional<double> stiffness_Npm,
                      std::optional<double> damping_Nspm, double link_delay_s, double link_loss,
                      double link_loss_burst, double duration_s, const std::string& out_dir) {
  impetus::InProcessTrialOptions options =
      trial_options(scene, scene_text, coupling, passivity, phase_ticks, world_rate_hz, substeps, engine, stiffness_Npm,
                    damping_Nspm, link_delay_s, link_loss, link_loss_burst, out_dir);
  options.trajectory = trajectory;
  options.fingers = fingers;
  for (const auto& [name, spec, table] : finger_paths) {
    try {
      impetus::Trajectory path = table ? trajectory_from_array(*table, "array") : impetus::load_trajectory(spec);
      options.finger_paths.push_back({name, std::move(path)});
    } catch (const std::exception& error) {
      throw std::invalid_argument("trajectory '" + name + "': " + error.what());
    }
  }
  options.followers = followers;
  options.duration_s = duration_s;
  // The trial runs on a thread of its own and touches no Python object, so other Python threads run meanwhile. This
  // thread waits for it with the GIL released and, every kSignalCheck, takes the GIL to let Python run its signal
  // handlers: Ctrl-C in the main thread ends the trial between two ticks and raises KeyboardInterrupt here, however
  // long the trial would have run.
  constexpr auto kSignalCheck = std::chrono::milliseconds(50);
  std::atomic<bool> stop{false};
  options.stop = &stop;
  std::string text;
  std::exception_ptr failure;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  std::thread trial([&] {
    try {
      text = impetus::run_in_process_trial(options).dump();
    } catch (...) {
      failure = std::current_exception();
    }
    const std::lock_guard<std::mutex> lock(mutex);
    done = true;
    finished.notify_one();
  });
  bool interrupted = false;
  for (;;) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex);
      if (finished.wait_for(lock, kSignalCheck, [&] { return done; })) break;
    }
    if (!interrupted && PyErr_CheckSignals() != 0) {
      interrupted = true;  // the handler's exception is set; it is raised once the trial has stopped
      stop.store(true);
    }
  }
  {
    py::gil_scoped_release release;
    trial.join();
  }
  if (interrupted) throw py::error_already_set();
  if (failure) std::rethrow_exception(failure);
  return text;
}

// A log written by the nodes (a header row of column names, then rows of numbers: docs/architecture.md §4) as its
// header and a rows x columns float64 array. Throws std::runtime_error naming the file, line and column of a bad value.
py::tuple read_log(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot be read");
  std::string line;
  if (!std::getline(file, line)) throw std::runtime_error(path + ": empty (no header row)");
  std::vector<std::string> header;
  for (std::size_t start = 0;;) {
    const std::size_t comma = line.find(',', start);
    header.push_back(line.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  std::vector<double> values;
  std::size_t rows = 0;
  while (std::getline(file, line)) {
    if (line.empty()) continue;
    const char* cursor = line.c_str();
    for (std::size_t column = 0; column < header.size(); ++column) {
      char* end = nullptr;
      errno = 0;
      const double value = std::strtod(cursor, &end);
      const char expected = column + 1 < header.size() ? ',' : '\0';
      if (end == cursor || *end != expected) {
        throw std::runtime_error(path + ": line " + std::to_string(rows + 2) + ", column '" + header[column] +
                                 "': not a number or a wrong count of values");
      }
      values.push_back(value);
      cursor = end + (expected == ',' ? 1 : 0);
    }
    ++rows;
  }
  py::array_t<double> table({rows, header.size()});
  std::copy(values.begin(), values.end(), table.mutable_data());
  return py::make_tuple(header, table);
}

// An objects x `width` array whose row i `fill(i, row)` writes: one quantity of every scene object.
template <typename Fill>
py::array_t<double> object_rows(std::size_t objects, std::size_t width, Fill&& fill) {
  py::array_t<double> out({objects, width});
  for (std::size_t i = 0; i < objects; ++i) fill(i, out.mutable_data(i));
  return out;
}

// The closed loop (loop/simulation.h) for the Python half: steps with the GIL released and hands back each tick's
// records as numpy arrays, one per quantity, ticks x fingers (x 3).
class ClosedLoop {
 public:
  ClosedLoop(const std::string& scene, const std::string& scene_text,
             const std::vector<std::pair<std::string, std::array<double, 3>>>& fingers, const std::string& coupling,
             bool passivity, std::uint64_t phase_ticks, std::optional<double> world_rate_hz, std::optional<int> substeps,
             const std::optional<std::string>& engine, std::optional<double> stiffness_Npm,
             std::optional<double> damping_Nspm, double link_delay_s, double link_loss, double link_loss_burst,
             const std::string& out_dir) {
    impetus::SimulationOptions options;
    options.trial = trial_options(scene, scene_text, coupling, passivity, phase_ticks, world_rate_hz, substeps, engine,
                                  stiffness_Npm, damping_Nspm, link_delay_s, link_loss, link_loss_burst, out_dir);
    for (const auto& [name, start_m] : fingers) options.fingers.push_back({name, start_m});
    options.trial.stop = &stop_;
    py::gil_scoped_release release;
    simulation_ = std::make_unique<impetus::Simulation>(options);
  }
  ~ClosedLoop() {
    py::gil_scoped_release release;
    simulation_.reset();
  }

  // `targets`: None, or a ticks x fingers x 3 array (the Python half shapes it). Returns a dict of arrays.
  py::dict step(std::uint64_t ticks, const std::optional<py::array_t<double, py::array::c_style |
                                                                         py::array::forcecast>>& targets) {
    const std::size_t fingers = simulation_->finger_count();
    std::vector<impetus::Vec3> points;
    if (targets) {
      if (targets->ndim() != 3 || static_cast<std::uint64_t>(targets->shape(0)) != ticks ||
          static_cast<std::size_t>(targets->shape(1)) != fingers || targets->shape(2) != 3) {
        throw std::invalid_argument("targets: must be ticks x fingers x 3");
      }
      points.resize(ticks * fingers);
      std::copy_n(targets->data(), points.size() * 3, points.front().data());
    }
    records_.resize(ticks * fingers);
    // Long runs are cut into chunks so Ctrl-C is seen between them (KeyboardInterrupt, the ticks taken kept).
    constexpr std::uint64_t kChunkTicks = 20000;
    std::uint64_t done = 0;
    while (done < ticks) {
      const std::uint64_t chunk = std::min(kChunkTicks, ticks - done);
      const std::span<const impetus::Vec3> chunk_targets =
          points.empty() ? std::span<const impetus::Vec3>() : std::span(points).subspan(done * fingers, chunk * fingers);
      const std::span<impetus::FingerTick> chunk_out = std::span(records_).subspan(done * fingers, chunk * fingers);
      std::uint64_t taken = 0;
      {
        py::gil_scoped_release release;
        taken = simulation_->step(chunk, chunk_targets, chunk_out);
      }
      done += taken;
      if (taken < chunk || (done < ticks && PyErr_CheckSignals() != 0)) break;
    }
    if (PyErr_Occurred() != nullptr) throw py::error_already_set();
    return records(done, fingers);
  }

  void set_target(std::size_t finger, const std::array<double, 3>& target_m) {
    simulation_->set_target(finger, target_m);
  }
  void set_hand_force(std::size_t finger, const std::array<double, 3>& force_N) {
    simulation_->set_hand_force(finger, force_N);
  }

  // Every object now: a dict of arrays, objects x 3 (x 4 for the orientation).
  py::dict objects() const {
    const std::vector<impetus::SimulationObject> objects = simulation_->objects();
    const std::size_t n = objects.size();
    using Object = impetus::SimulationObject;
    using Field = impetus::Vec3 Object::*;
    static constexpr std::pair<const char*, Field> kVectors[] = {
        {"position_m", &Object::position_m},
        {"velocity_mps", &Object::velocity_mps},
        {"angular_velocity_radps", &Object::angular_velocity_radps},
        {"impulse_Ns", &Object::impulse_Ns}};
    py::dict out;
    for (const auto& [name, field] : kVectors) {
      out[name] = object_rows(n, 3, [&](std::size_t i, double* row) {
        std::copy_n((objects[i].*field).data(), 3, row);
      });
    }
    out["orientation_wxyz"] = object_rows(n, 4, [&](std::size_t i, double* row) {
      std::copy_n(objects[i].orientation_wxyz.data(), 4, row);
    });
    return out;
  }

  std::string finish() {
    py::gil_scoped_release release;
    return simulation_->finish().dump();
  }

  std::uint64_t ticks() const { return simulation_->ticks(); }
  double tick_period_s() const { return simulation_->tick_period_s(); }
  double device_time_s() const { return simulation_->device_time_s(); }
  bool finished() const { return simulation_->finished(); }
  std::vector<std::string> object_names() const { return simulation_->object_names(); }
  std::vector<std::string> warnings() const { return simulation_->warnings(); }

 private:
  py::dict records(std::uint64_t ticks, std::size_t fingers) const {
    const std::size_t n = static_cast<std::size_t>(ticks);
    py::array_t<double> time(static_cast<py::ssize_t>(n));
    py::array_t<std::int32_t> planes({n, fingers});
    using Field = impetus::Vec3 impetus::FingerTick::*;
    static constexpr std::pair<const char*, Field> kVectors[] = {
        {"target_m", &impetus::FingerTick::target_m},
        {"finger_m", &impetus::FingerTick::finger_m},
        {"finger_velocity_mps", &impetus::FingerTick::finger_velocity_mps},
        {"proxy_m", &impetus::FingerTick::proxy_m},
        {"force_N", &impetus::FingerTick::force_N},
        {"object_impulse_Ns", &impetus::FingerTick::object_impulse_Ns},
    };
    py::dict out;
    for (std::size_t i = 0; i < n; ++i) {
      time.mutable_data()[i] = records_[i * fingers].time_s;
      for (std::size_t k = 0; k < fingers; ++k) planes.mutable_data()[i * fingers + k] = records_[i * fingers + k].active_planes;
    }
    out["time_s"] = time;
    for (const auto& [name, field] : kVectors) {
      py::array_t<double> values({n, fingers, std::size_t{3}});
      double* cursor = values.mutable_data();
      for (std::size_t r = 0; r < n * fingers; ++r, cursor += 3) std::copy_n((records_[r].*field).data(), 3, cursor);
      out[name] = values;
    }
    out["active_planes"] = planes;
    return out;
  }

  std::atomic<bool> stop_{false};
  std::unique_ptr<impetus::Simulation> simulation_;
  std::vector<impetus::FingerTick> records_;
};

// A pose from seven numbers: position (m), then the orientation as a unit quaternion w, x, y, z (normalised here;
// the Python half checks it is near unit).
impetus::GripPose pose_from(const double* v) {
  return {Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Quaterniond(v[3], v[4], v[5], v[6]).normalized()};
}

void pose_into(const impetus::GripPose& pose, double* position, double* wxyz) {
  std::copy_n(pose.position_m.data(), 3, position);
  wxyz[0] = pose.orientation.w();
  wxyz[1] = pose.orientation.x();
  wxyz[2] = pose.orientation.y();
  wxyz[3] = pose.orientation.z();
}

// The tool loop (loop/tool_loop.h) for the Python half: steps with the GIL released and hands back each tick's
// records as numpy arrays, one per quantity (ticks x 3, or ticks x 4 for orientations).
class ToolClosedLoop {
 public:
  ToolClosedLoop(const std::string& scene, const std::string& scene_text, const std::string& coupling,
                 std::optional<double> world_rate_hz, const std::array<double, 7>& start, const std::string& out_dir,
                 const std::string& device) {
    impetus::ToolLoopOptions options;
    options.out_dir = out_dir;
    options.device = device;
    options.scene_path = scene;
    options.scene_text = scene_text;
    options.coupling = parse_coupling(coupling);
    options.world_rate_hz = world_rate_hz;
    options.start = pose_from(start.data());
    py::gil_scoped_release release;
    loop_ = std::make_unique<impetus::ToolLoop>(options);
  }
  ~ToolClosedLoop() {
    py::gil_scoped_release release;
    loop_.reset();
  }

  // `targets`: None, or ticks x 7 poses. Returns a dict of arrays.
  py::dict step(std::uint64_t ticks, const std::optional<py::array_t<double, py::array::c_style |
                                                                         py::array::forcecast>>& targets) {
    std::vector<impetus::GripPose> poses;
    if (targets) {
      if (targets->ndim() != 2 || static_cast<std::uint64_t>(targets->shape(0)) != ticks || targets->shape(1) != 7) {
        throw std::invalid_argument("targets: must be ticks x 7 (x, y, z, w, qx, qy, qz)");
      }
      poses.reserve(ticks);
      for (std::uint64_t i = 0; i < ticks; ++i) poses.push_back(pose_from(targets->data(static_cast<py::ssize_t>(i))));
    }
    records_.resize(ticks);
    constexpr std::uint64_t kChunkTicks = 20000;  // Ctrl-C is seen between chunks, as the finger's closed loop
    std::uint64_t done = 0;
    while (done < ticks) {
      const std::uint64_t chunk = std::min(kChunkTicks, ticks - done);
      const std::span<const impetus::GripPose> chunk_targets =
          poses.empty() ? std::span<const impetus::GripPose>() : std::span(poses).subspan(done, chunk);
      {
        py::gil_scoped_release release;
        loop_->step(chunk, chunk_targets, std::span(records_).subspan(done, chunk));
      }
      done += chunk;
      if (done < ticks && PyErr_CheckSignals() != 0) break;
    }
    if (PyErr_Occurred() != nullptr) throw py::error_already_set();
    return records(done);
  }

  void set_target(const std::array<double, 7>& target) { loop_->set_target(pose_from(target.data())); }

  // Every object now: a dict of arrays, objects x 3 (x 4 for the orientation).
  py::dict objects() const {
    const std::vector<impetus::ToolLoopObject> objects = loop_->objects();
    const std::size_t n = objects.size();
    using Object = impetus::ToolLoopObject;
    using Field = Eigen::Vector3d Object::*;
    static constexpr std::pair<const char*, Field> kVectors[] = {
        {"velocity_mps", &Object::velocity_mps},
        {"angular_velocity_radps", &Object::angular_velocity_radps},
        {"impulse_Ns", &Object::impulse_Ns},
        {"angular_impulse_Nms", &Object::angular_impulse_Nms}};
    py::dict out;
    for (const auto& [name, field] : kVectors) {
      out[name] = object_rows(n, 3, [&](std::size_t i, double* row) {
        std::copy_n((objects[i].*field).data(), 3, row);
      });
    }
    out["position_m"] = object_rows(n, 3, [&](std::size_t i, double* row) {
      std::copy_n(objects[i].pose.position_m.data(), 3, row);
    });
    out["orientation_wxyz"] = object_rows(n, 4, [&](std::size_t i, double* row) {
      const Eigen::Quaterniond& q = objects[i].pose.orientation;
      row[0] = q.w(), row[1] = q.x(), row[2] = q.y(), row[3] = q.z();
    });
    return out;
  }

  std::string finish() {
    py::gil_scoped_release release;
    return loop_->finish().dump();
  }
  std::uint64_t ticks() const { return loop_->ticks(); }
  double tick_period_s() const { return loop_->tick_period_s(); }
  bool finished() const { return loop_->finished(); }
  std::vector<std::string> object_names() const { return loop_->object_names(); }

 private:
  py::dict records(std::uint64_t ticks) const {
    const std::size_t n = static_cast<std::size_t>(ticks);
    py::array_t<double> time(static_cast<py::ssize_t>(n));
    py::array_t<std::int32_t> active(static_cast<py::ssize_t>(n));
    using Pose = impetus::GripPose impetus::ToolTick::*;
    static constexpr std::pair<const char*, Pose> kPoses[] = {
        {"target", &impetus::ToolTick::target}, {"grip", &impetus::ToolTick::grip},
        {"hand", &impetus::ToolTick::hand}, {"proxy", &impetus::ToolTick::proxy}};
    using Vector = Eigen::Vector3d impetus::ToolTick::*;
    static constexpr std::pair<const char*, Vector> kVectors[] = {
        {"force_N", &impetus::ToolTick::force_N}, {"torque_Nm", &impetus::ToolTick::torque_Nm},
        {"strings_force_N", &impetus::ToolTick::strings_force_N},
        {"strings_torque_Nm", &impetus::ToolTick::strings_torque_Nm}};
    py::dict out;
    for (std::size_t i = 0; i < n; ++i) {
      time.mutable_data()[i] = records_[i].time_s;
      active.mutable_data()[i] = records_[i].active;
    }
    out["time_s"] = time;
    out["active"] = active;
    for (const auto& [name, field] : kPoses) {
      py::array_t<double> position({n, std::size_t{3}}), wxyz({n, std::size_t{4}});
      for (std::size_t i = 0; i < n; ++i) {
        pose_into(records_[i].*field, position.mutable_data(i), wxyz.mutable_data(i));
      }
      out[py::str(std::string(name) + "_m")] = position;
      out[py::str(std::string(name) + "_wxyz")] = wxyz;
    }
    for (const auto& [name, field] : kVectors) {
      py::array_t<double> values({n, std::size_t{3}});
      for (std::size_t i = 0; i < n; ++i) std::copy_n((records_[i].*field).data(), 3, values.mutable_data(i));
      out[name] = values;
    }
    return out;
  }

  std::unique_ptr<impetus::ToolLoop> loop_;
  std::vector<impetus::ToolTick> records_;
};

// Where a trajectory (a built-in spec or a CSV file) puts the target at each of `times_s`: an N x 3 array (m).
py::array_t<double> sample_trajectory(const std::string& spec, const py::array_t<double, py::array::c_style |
                                                                                   py::array::forcecast>& times_s) {
  const impetus::Trajectory trajectory = impetus::load_trajectory(spec);
  const std::size_t n = static_cast<std::size_t>(times_s.size());
  py::array_t<double> out({n, std::size_t{3}});
  for (std::size_t i = 0; i < n; ++i) {
    const impetus::Vec3 point = trajectory.position_at(times_s.data()[i]);
    std::copy_n(point.data(), 3, out.mutable_data(i));
  }
  return out;
}

}  // namespace

PYBIND11_MODULE(_impetus, module) {
  module.doc() = "Impetus' compiled core; use the impetus package, not this module.";
  // numpy's C API is looked up once, here, while Python imports this module on one thread. Looked up later, on first
  // use (pybind11 does it under a function-local static while holding the GIL), threads calling read_log at once
  // deadlock: one holds the static's guard and waits for the GIL in numpy's import, another holds the GIL and waits
  // for the guard.
  py::module_::import("numpy");
  (void)py::dtype::of<double>();
  module.def("run_trial", &run_trial, py::arg("scene"), py::arg("scene_text"), py::arg("trajectory"),
             py::arg("fingers"), py::arg("finger_paths"), py::arg("followers"), py::arg("coupling"),
             py::arg("passivity"), py::arg("phase_ticks"), py::arg("world_rate_hz"), py::arg("substeps"), py::arg("engine"),
             py::arg("stiffness_Npm"), py::arg("damping_Nspm"), py::arg("link_delay_s"), py::arg("link_loss"),
             py::arg("link_loss_burst"), py::arg("duration_s"),
             py::arg("out_dir"));
  module.def("read_log", &read_log, py::arg("path"));
  module.def("sample_trajectory", &sample_trajectory, py::arg("spec"), py::arg("times_s"));
  py::class_<ClosedLoop>(module, "ClosedLoop")
      .def(py::init<const std::string&, const std::string&,
                    const std::vector<std::pair<std::string, std::array<double, 3>>>&, const std::string&, bool,
                    std::uint64_t, std::optional<double>, std::optional<int>, const std::optional<std::string>&,
                    std::optional<double>, std::optional<double>, double, double, double, const std::string&>(),
           py::arg("scene"), py::arg("scene_text"), py::arg("fingers"), py::arg("coupling"), py::arg("passivity"),
           py::arg("phase_ticks"),
           py::arg("world_rate_hz"), py::arg("substeps"), py::arg("engine"), py::arg("stiffness_Npm"),
           py::arg("damping_Nspm"),
           py::arg("link_delay_s"), py::arg("link_loss"), py::arg("link_loss_burst"), py::arg("out_dir"))
      .def("step", &ClosedLoop::step, py::arg("ticks"), py::arg("targets"))
      .def("set_target", &ClosedLoop::set_target, py::arg("finger"), py::arg("target_m"))
      .def("set_hand_force", &ClosedLoop::set_hand_force, py::arg("finger"), py::arg("force_N"))
      .def("objects", &ClosedLoop::objects)
      .def("finish", &ClosedLoop::finish)
      .def_property_readonly("ticks", &ClosedLoop::ticks)
      .def_property_readonly("tick_period_s", &ClosedLoop::tick_period_s)
      .def_property_readonly("device_time_s", &ClosedLoop::device_time_s)
      .def_property_readonly("finished", &ClosedLoop::finished)
      .def_property_readonly("object_names", &ClosedLoop::object_names)
      .def_property_readonly("warnings", &ClosedLoop::warnings);
  py::class_<ToolClosedLoop>(module, "ToolClosedLoop")
      .def(py::init<const std::string&, const std::string&, const std::string&, std::optional<double>,
                    const std::array<double, 7>&, const std::string&, const std::string&>(),
           py::arg("scene"), py::arg("scene_text"), py::arg("coupling"), py::arg("world_rate_hz"), py::arg("start"),
           py::arg("out_dir"), py::arg("device"))
      .def("step", &ToolClosedLoop::step, py::arg("ticks"), py::arg("targets"))
      .def("set_target", &ToolClosedLoop::set_target, py::arg("target"))
      .def("objects", &ToolClosedLoop::objects)
      .def("finish", &ToolClosedLoop::finish)
      .def_property_readonly("ticks", &ToolClosedLoop::ticks)
      .def_property_readonly("tick_period_s", &ToolClosedLoop::tick_period_s)
      .def_property_readonly("finished", &ToolClosedLoop::finished)
      .def_property_readonly("object_names", &ToolClosedLoop::object_names);
  module.def("defaults", [] { return impetus::defaults_document().dump(); });
}
