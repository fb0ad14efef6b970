// SPDX-License-Identifier: Apache-2.0
#include "viewer/viewer_node.h"

#include "common/runtime/ascii.h"
#include "common/link/dds/dds_world_view.h"

#include "common/link/shm/names.h"
#include "common/link/shm/shm_touch_port.h"
#include "common/mesh/mesh_object.h"
#include "common/runtime/process.h"
#include "common/tool/tool_block.h"
#include "viewer/view_feed.h"
#include "viewer/touch_control.h"
#include "viewer/view_server.h"
#include "viewer/web_root.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/steady_timer.hpp>

#include <charconv>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>

namespace impetus::view {

namespace asio = boost::asio;

namespace {

std::vector<std::string> lower_case(std::vector<std::string> names) {
  for (std::string& name : names) name = ascii_lower(name);
  return names;
}

}  // namespace

ListenAddress parse_listen(const std::string& text, bool allow_remote) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) {
    throw std::invalid_argument("--listen " + text + ": expected HOST:PORT, e.g. 127.0.0.1:8080");
  }
  ListenAddress address;
  address.host = text.substr(0, colon);
  if (address.host.size() > 2 && address.host.front() == '[' && address.host.back() == ']') {
    address.host = address.host.substr(1, address.host.size() - 2);  // [::1]:8080
  }
  unsigned port = 0;
  const char* first = text.data() + colon + 1;
  const char* last = text.data() + text.size();
  const auto [end, error] = std::from_chars(first, last, port);
  if (error != std::errc() || end != last || port > 65535) {
    throw std::invalid_argument("--listen " + text + ": the port must be 0 to 65535");
  }
  address.port = static_cast<std::uint16_t>(port);
  boost::system::error_code bad;
  const asio::ip::address ip = asio::ip::make_address(address.host, bad);
  if (bad) throw std::invalid_argument("--listen " + text + ": '" + address.host + "' is not an IP address");
  if (!ip.is_loopback() && !allow_remote) {
    throw std::invalid_argument("--listen " + text + ": not a loopback address; anyone who can reach it would see the "
                                "session. Add --allow-remote if that is what you want");
  }
  return address;
}

ViewerNode::ViewerNode(ViewerOptions options, std::filesystem::path executable)
    : options_(std::move(options)), executable_(std::move(executable)) {}

int ViewerNode::run() {
  const ListenAddress address = parse_listen(options_.listen, options_.allow_remote);
  if (options_.touch && !options_.replay_dir.empty()) {
    throw std::invalid_argument("--touch steers a live world's web hand; a replay has none");
  }
  if (options_.touch && options_.allow_remote && !options_.allow_remote_touch) {
    throw std::invalid_argument("--touch with --allow-remote would let pages on other machines steer the hand (and "
                                "push the world); add --allow-remote-touch if that is what you want");
  }
  const WebRoot web(options_.web_dir.empty() ? WebRoot::find_default(executable_) : options_.web_dir);
  // The meshes' triangles are registered by their hash, which the world's scene names for each mesh body.
  if (!options_.meshes_from.empty()) load_scene_meshes(options_.meshes_from);
  std::unique_ptr<ViewFeed> feed;
  LiveFeed* live = nullptr;
  if (!options_.replay_dir.empty()) {
    auto replay = std::make_unique<ReplayFeed>(options_.replay_dir);
    std::fprintf(stderr, "viewer: replaying %s: %zu frames, %.3f to %.3f s\n", options_.replay_dir.c_str(),
                 replay->replay().frame_count(), replay->replay().start_s(), replay->replay().end_s());
    feed = std::move(replay);
  } else {
    std::unique_ptr<LiveFeed> live_feed;
    if (options_.link.kind == LinkKind::dds) {
      const DdsLinkOptions dds = options_.link.dds;
      live_feed = std::make_unique<LiveFeed>(describe(dds), [dds]() -> std::unique_ptr<WorldViewReader> {
        return std::make_unique<DdsWorldViewReader>(dds);
      });
    } else {
      live_feed = std::make_unique<LiveFeed>(options_.shm);
    }
    if (!options_.meshes_from.empty()) {
      if (const std::optional<ToolBlock> tool = load_scene_tool(options_.meshes_from)) live_feed->set_tool(tool->shape);
    }
    live = live_feed.get();
    feed = std::move(live_feed);
  }

  // Declared before the server and its io_context: pages hold it until their last handler has run.
  std::optional<TouchControl> touch;
  if (options_.touch) {
    const std::string shm = options_.shm;
    touch.emplace(
        [shm]() -> std::unique_ptr<TouchPortClient> {
          try {
            return std::make_unique<ShmTouchPortClient>(shm);
          } catch (const SegmentError& error) {
            if (!error.transient()) throw;
            throw std::runtime_error("no web hand device is running on '" + shm + "' (haptic_controller --shm " + shm +
                                     " --device web --clock realtime)");
          }
        },
        new_touch_token());
  }

  asio::io_context io(1);
  std::unique_ptr<ViewServer> server_owner;
  try {
    server_owner = std::make_unique<ViewServer>(io, asio::ip::tcp::endpoint{asio::ip::make_address(address.host),
                                                                            address.port},
                                                web, *feed, lower_case(options_.allow_hosts),
                                                touch ? &*touch : nullptr);
  } catch (const boost::system::system_error& error) {
    throw std::runtime_error("--listen " + options_.listen + ": cannot serve there: " + error.code().message() +
                             (error.code() == boost::asio::error::address_in_use
                                  ? " (another viewer? choose another port, or port 0 for any free one)"
                                  : ""));
  }
  ViewServer& server = *server_owner;
  const auto bound = server.local_endpoint();
  const std::string host = bound.address().is_v6() ? "[" + bound.address().to_string() + "]" : bound.address().to_string();
  std::printf("viewer: serving http://%s:%u/ (%s)\n", host.c_str(), static_cast<unsigned>(bound.port()),
              options_.replay_dir.empty()
                  ? (options_.link.kind == LinkKind::dds ? "live, world on " + describe(options_.link.dds)
                                                         : "live, world '" + options_.shm + "'")
                        .c_str()
                                          : ("replay of " + options_.replay_dir).c_str());
  if (touch) {
    std::printf("viewer: touch the world: http://%s:%u/?touch=%s (the web hand on '%s'; one page at a time holds it)\n",
                host.c_str(), static_cast<unsigned>(bound.port()), touch->token().c_str(),
                touch_port_name(options_.shm).c_str());
  }
  std::fflush(stdout);
  server.start();

  // Stop requests (SIGINT, SIGTERM) and the duration are checked every 50 ms.
  const auto deadline = options_.duration_s > 0.0
                            ? std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                     std::chrono::duration<double>(options_.duration_s))
                            : std::chrono::steady_clock::time_point::max();
  asio::steady_timer watch(io);
  std::function<void()> check_stop = [&] {
    if (g_stop_requested.load() || std::chrono::steady_clock::now() >= deadline) {
      server.stop();
      return;
    }
    watch.expires_after(std::chrono::milliseconds(50));
    watch.async_wait([&](boost::system::error_code error) {
      if (!error) check_stop();
    });
  };
  check_stop();
  io.run();

  const ServerCounters& c = server.counters();
  std::fprintf(stderr,
               "viewer: %llu pages, %llu frames sent (%llu dropped for slow pages), %.1f MB, %llu requests, %llu "
               "answered with an error (%llu of them another site's), %llu connections refused",
               static_cast<unsigned long long>(c.pages), static_cast<unsigned long long>(c.frames_sent),
               static_cast<unsigned long long>(c.frames_dropped), static_cast<double>(c.bytes_sent) * 1e-6,
               static_cast<unsigned long long>(c.http_requests), static_cast<unsigned long long>(c.http_errors),
               static_cast<unsigned long long>(c.foreign_requests), static_cast<unsigned long long>(c.refused));
  if (live != nullptr) {
    std::fprintf(stderr, ", %llu snapshots read, %llu rejected", static_cast<unsigned long long>(live->snapshots_read()),
                 static_cast<unsigned long long>(live->rejected()));
  }
  if (touch) {
    std::fprintf(stderr, ", touch: %llu targets (longest gap %.1f ms), %llu takes refused",
                 static_cast<unsigned long long>(touch->targets()), static_cast<double>(touch->longest_gap_ns()) * 1e-6,
                 static_cast<unsigned long long>(touch->refusals()));
  }
  std::fprintf(stderr, "\n");
  return 0;
}

}  // namespace impetus::view
