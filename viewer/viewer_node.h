// SPDX-License-Identifier: Apache-2.0
#pragma once
// The viewer node (docs/architecture.md §1.3, paper §6.1 "graphics"): attaches read-only to a running world's view, or
// reads a finished trial, and serves the page that shows it. It never writes anything the world or the haptic loop
// reads; with --touch it writes one thing, the controlling page's target, into the web hand's touch port
// (viewer/touch_control.h).

#include "common/link/link_options.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace impetus::view {

struct ViewerOptions {
  std::string shm = "impetus";   // live: the world's --shm name
  LinkOptions link;              // live: shared memory on this host (shm), or DDS from any host (link.dds)
  std::string replay_dir;        // replay: a trial folder (run.sh --out); takes precedence over shm
  std::string listen = "127.0.0.1:8080";
  bool allow_remote = false;     // serve on an address other than loopback
  std::vector<std::string> allow_hosts;  // with allow_remote: DNS names the page may be reached by (Host header)
  // Live: a page holding the run's token steers the web hand (haptic_controller --device web) on "<shm>.touch".
  bool touch = false;
  bool allow_remote_touch = false;  // touch with allow_remote: input from pages on other machines
  std::filesystem::path web_dir; // the page's files; empty: WebRoot::find_default
  std::string meshes_from;       // live: the world's scene file, whose meshes the page is sent (a replay reads its own)
  double duration_s = 0.0;       // 0: until stopped
};

// "HOST:PORT" → address and port; throws std::invalid_argument naming the value. A non-loopback host needs
// `allow_remote` (the viewer shows a lab's session to whoever can reach the port).
struct ListenAddress {
  std::string host;
  std::uint16_t port = 0;
};
ListenAddress parse_listen(const std::string& text, bool allow_remote);

class ViewerNode {
 public:
  explicit ViewerNode(ViewerOptions options, std::filesystem::path executable);
  // Serves until the duration or a stop request; prints "viewer: serving http://HOST:PORT/" on stdout once listening,
  // and its counters on stderr at the end. Returns the exit status.
  int run();

 private:
  ViewerOptions options_;
  std::filesystem::path executable_;
};

}  // namespace impetus::view
