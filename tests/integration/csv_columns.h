// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reads a numeric CSV log (header row, then rows of numbers) into columns by header name.

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace impetus::test {

inline std::map<std::string, std::vector<double>> read_csv_columns(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> names;
  std::map<std::string, std::vector<double>> columns;
  if (!std::getline(in, line)) return columns;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (std::size_t k = 0; k < names.size() && std::getline(row, cell, ','); ++k) {
      columns[names[k]].push_back(std::stod(cell));
    }
  }
  return columns;
}

}  // namespace impetus::test
