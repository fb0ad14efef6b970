// SPDX-License-Identifier: Apache-2.0
// impetus._impetus: the compiled half of the Python package (python/impetus/__init__.py is the public half). It runs
// an in-process trial (loop/in_process_trial.h) with the GIL released and reads the CSV logs into numpy arrays; the
// Python half chooses defaults, names the arguments and shapes the results.

#include "loop/in_process_trial.h"
#include "world_manager/defaults.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
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

// The trial's summary.json document as text (the Python half parses it into a dict).
std::string run_trial(const std::string& scene, const std::string& trajectory, const std::vector<std::string>& fingers,
                      const std::vector<std::vector<std::string>>& followers, const std::string& coupling,
                      std::uint64_t phase_ticks, std::optional<double> world_rate_hz, std::optional<int> substeps,
                      std::optional<double> stiffness_Npm, std::optional<double> damping_Nspm, double link_delay_s,
                      double duration_s, const std::string& out_dir) {
  impetus::InProcessTrialOptions options;
  options.scene_path = scene;
  options.trajectory = trajectory;
  options.fingers = fingers;
  options.followers = followers;
  options.coupling = parse_coupling(coupling);
  options.phase_ticks = phase_ticks;
  options.world_rate_hz = world_rate_hz;
  options.substeps = substeps;
  if (stiffness_Npm) options.stiffness_Npm = *stiffness_Npm;
  if (damping_Nspm) options.damping_Nspm = *damping_Nspm;
  options.link_delay_s = link_delay_s;
  options.duration_s = duration_s;
  options.out_dir = out_dir;
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

}  // namespace

PYBIND11_MODULE(_impetus, module) {
  module.doc() = "Impetus' compiled core; use the impetus package, not this module.";
  // numpy's C API is looked up once, here, while Python imports this module on one thread. Looked up later, on first
  // use (pybind11 does it under a function-local static while holding the GIL), threads calling read_log at once
  // deadlock: one holds the static's guard and waits for the GIL in numpy's import, another holds the GIL and waits
  // for the guard.
  py::module_::import("numpy");
  (void)py::dtype::of<double>();
  module.def("run_trial", &run_trial, py::arg("scene"), py::arg("trajectory"), py::arg("fingers"), py::arg("followers"),
             py::arg("coupling"),
             py::arg("phase_ticks"), py::arg("world_rate_hz"), py::arg("substeps"), py::arg("stiffness_Npm"),
             py::arg("damping_Nspm"), py::arg("link_delay_s"), py::arg("duration_s"), py::arg("out_dir"));
  module.def("read_log", &read_log, py::arg("path"));
  module.def("defaults", [] { return impetus::defaults_document().dump(); });
}
