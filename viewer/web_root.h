// SPDX-License-Identifier: Apache-2.0
#pragma once
// The page's files (viewer/web) and which request targets name them. Only these are served: "/" and "/index.html",
// "/viewer.js", "/touch.js" and "/touch_worker.js", and three.js's own files under "/three/build/" and "/three/examples/jsm/" (from the pinned npm
// package in web/node_modules/three). A target with "..", a hidden component, or characters outside
// [A-Za-z0-9._-/] names nothing.

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace impetus::view {

class WebRoot {
 public:
  // Checks that `dir` has the page and three.js; throws std::runtime_error saying what is missing and how to get it.
  explicit WebRoot(std::filesystem::path dir);

  std::optional<std::filesystem::path> file_for(std::string_view target) const;
  const std::filesystem::path& dir() const { return dir_; }

  // The first folder that has the page: next to an installed viewer (PREFIX/share/impetus/viewer/web), then the
  // source tree's viewer/web. `executable` is the viewer's own path.
  static std::filesystem::path find_default(const std::filesystem::path& executable);

 private:
  std::filesystem::path dir_;
};

// The Content-Type for a served file, by its extension.
std::string_view content_type(const std::filesystem::path& file);

}  // namespace impetus::view
