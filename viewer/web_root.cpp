// SPDX-License-Identifier: Apache-2.0
#include "viewer/web_root.h"

#include <algorithm>
#include <system_error>

namespace impetus::view {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kThreeModule = "node_modules/three/build/three.module.js";

// A relative path of plain components: letters, digits, '.', '_', '-' separated by '/', none empty or hidden.
bool plain_relative_path(std::string_view path) {
  if (path.empty()) return false;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string_view part = path.substr(start, end - start);
    if (part.empty() || part.front() == '.') return false;
    const bool plain = std::all_of(part.begin(), part.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
             c == '-';
    });
    if (!plain) return false;
    start = end + 1;
  }
  return true;
}

bool has_page(const fs::path& dir) {
  std::error_code error;
  return fs::is_regular_file(dir / "index.html", error) && fs::is_regular_file(dir / "viewer.js", error);
}

}  // namespace

WebRoot::WebRoot(fs::path dir) : dir_(std::move(dir)) {
  if (!has_page(dir_)) {
    throw std::runtime_error("--web " + dir_.string() + ": no index.html and viewer.js there (the viewer's page)");
  }
  std::error_code error;
  if (!fs::is_regular_file(dir_ / kThreeModule, error)) {
    throw std::runtime_error("--web " + dir_.string() + ": three.js is not installed (" + std::string(kThreeModule) +
                             " is missing); run scripts/deps.sh, or: npm ci --prefix " + dir_.string());
  }
}

std::optional<fs::path> WebRoot::file_for(std::string_view target) const {
  const std::size_t query = target.find_first_of("?#");
  if (query != std::string_view::npos) target = target.substr(0, query);
  if (target == "/" || target == "/index.html") return dir_ / "index.html";
  if (target == "/viewer.js") return dir_ / "viewer.js";
  if (target == "/touch.js") return dir_ / "touch.js";
  if (target == "/tool.js") return dir_ / "tool.js";
  if (target == "/touch_worker.js") return dir_ / "touch_worker.js";
  for (const std::string_view prefix : {std::string_view("/three/build/"), std::string_view("/three/examples/jsm/")}) {
    if (target.substr(0, prefix.size()) != prefix) continue;
    const std::string_view rest = target.substr(prefix.size());
    if (!plain_relative_path(rest)) return std::nullopt;
    const fs::path file = dir_ / "node_modules" / fs::path(std::string(prefix.substr(1))) / fs::path(std::string(rest));
    std::error_code error;
    if (!fs::is_regular_file(file, error)) return std::nullopt;
    return file;
  }
  return std::nullopt;
}

fs::path WebRoot::find_default(const fs::path& executable) {
  std::error_code error;
  const fs::path bin = fs::weakly_canonical(executable, error).parent_path();
  const fs::path candidates[] = {bin.parent_path() / "share" / "impetus" / "viewer" / "web",
                                 fs::path(IMPETUS_SOURCE_DIR) / "viewer" / "web"};
  for (const fs::path& candidate : candidates) {
    if (has_page(candidate)) return candidate;
  }
  return candidates[1];
}

std::string_view content_type(const fs::path& file) {
  const std::string extension = file.extension().string();
  if (extension == ".html") return "text/html; charset=utf-8";
  if (extension == ".js") return "text/javascript; charset=utf-8";
  if (extension == ".css") return "text/css; charset=utf-8";
  if (extension == ".json") return "application/json";
  if (extension == ".png") return "image/png";
  return "application/octet-stream";
}

}  // namespace impetus::view
