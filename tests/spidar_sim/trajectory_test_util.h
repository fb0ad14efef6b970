// SPDX-License-Identifier: Apache-2.0
#pragma once
// Helpers shared by the trajectory tests: write a CSV to a private temporary file, and sample a trajectory densely.

#include "spidar_sim/trajectory.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace impetus::test {

// A file in the temporary directory that is removed when the object goes out of scope.
class TempFile {
 public:
  TempFile(const std::string& name, const std::string& content) {
    static int counter = 0;
    path_ = std::filesystem::temp_directory_path() /
            ("impetus_spidar_sim_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + "_" + name);
    std::ofstream(path_) << content;
  }
  ~TempFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace impetus::test
