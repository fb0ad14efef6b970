// SPDX-License-Identifier: Apache-2.0
// Replays inputs through a fuzz target without libFuzzer, so the default (g++) build runs the seed corpus and every
// recorded crash as a CTest test. Arguments are files or directories (directories: every regular file in them, in
// name order so failures reproduce). A failing input aborts inside the target; the line printed before it names the
// file. An argument that does not exist is an error, so a misspelt corpus path cannot pass vacuously; an empty
// directory is fine (fuzz/regressions/<target>/ holds only a README until a crash is recorded).
//
// A file ending in ".gen" is a recipe for an input too large to keep in the repository (10^6 nesting levels, a 50 MB
// token): each line is "COUNT TEXT", and the input is TEXT repeated COUNT times, line after line. In TEXT, "\n" is a
// newline and "\\" a backslash; nothing else is special.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;

bool is_input(const fs::path& path) {
  // Documentation next to the inputs is not an input.
  return fs::is_regular_file(path) && path.filename() != "README.md";
}

// Expands a ".gen" recipe (see the top of this file); false if a line is not "COUNT TEXT".
bool expand_recipe(const std::vector<char>& recipe, std::vector<char>& out) {
  const std::string text(recipe.begin(), recipe.end());
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    if (line.empty()) continue;
    const std::size_t space = line.find(' ');
    if (space == std::string::npos || space == 0) return false;
    const unsigned long long count = std::strtoull(line.substr(0, space).c_str(), nullptr, 10);
    std::string piece;
    for (std::size_t k = space + 1; k < line.size(); ++k) {
      if (line[k] == '\\' && k + 1 < line.size() && (line[k + 1] == 'n' || line[k + 1] == '\\')) {
        piece += line[k + 1] == 'n' ? '\n' : '\\';
        ++k;
      } else {
        piece += line[k];
      }
    }
    for (unsigned long long i = 0; i < count; ++i) out.insert(out.end(), piece.begin(), piece.end());
  }
  return true;
}

int replay(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "fuzz replay: cannot read %s\n", path.c_str());
    return 1;
  }
  std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (path.extension() == ".gen") {
    std::vector<char> expanded;
    if (!expand_recipe(bytes, expanded)) {
      std::fprintf(stderr, "fuzz replay: %s: each line must be COUNT TEXT\n", path.c_str());
      return 1;
    }
    bytes.swap(expanded);
  }
  std::fprintf(stderr, "fuzz replay: %s (%zu bytes)\n", path.c_str(), bytes.size());
  // Copy into an exact-size heap buffer, as libFuzzer does, so ASan builds catch reads past the end.
  std::vector<std::uint8_t> input(bytes.begin(), bytes.end());
  LLVMFuzzerTestOneInput(input.data(), input.size());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const fs::path arg = argv[i];
    if (fs::is_directory(arg)) {
      for (const fs::directory_entry& entry : fs::directory_iterator(arg)) {
        if (is_input(entry.path())) inputs.push_back(entry.path());
      }
    } else if (is_input(arg)) {
      inputs.push_back(arg);
    } else {
      std::fprintf(stderr, "fuzz replay: no such input file or directory: %s\n", argv[i]);
      return 2;
    }
  }
  std::sort(inputs.begin(), inputs.end());
  int failures = 0;
  for (const fs::path& input : inputs) failures += replay(input);
  std::fprintf(stderr, "fuzz replay: %zu inputs, %d unreadable\n", inputs.size(), failures);
  return failures == 0 ? 0 : 1;
}
