// SPDX-License-Identifier: Apache-2.0
#pragma once
// The viewer's HTTP and WebSocket server (Boost.Beast), on one thread: the page's files from a WebRoot, at /ws a
// WebSocket per page fed from a ViewFeed (view_protocol.h), and at /ws/touch a page's touch socket, which carries only
// touch messages (view_protocol.h §4).
//
// A page that reads slowly is sent only the newest frame when it is ready for one (never a queue that grows); a
// request that is too large, too slow, or for anything but the page's files gets an HTTP error or is closed; beyond
// kMaxConnections connections new ones are closed at once. None of this can reach the world: the feed reads it
// through a read-only mapping.

#include "viewer/request_check.h"
#include "viewer/touch_control.h"
#include "viewer/view_feed.h"
#include "viewer/web_root.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace impetus::view {

class WsSession;

struct ServerCounters {
  std::uint64_t http_requests = 0;
  std::uint64_t http_errors = 0;       // 4xx answers
  std::uint64_t foreign_requests = 0;  // refused for their Host or Origin (another site's page)
  std::uint64_t pages = 0;             // WebSocket connections accepted
  std::uint64_t refused = 0;           // connections closed at once: too many open
  std::uint64_t frames_sent = 0;
  std::uint64_t frames_dropped = 0;    // replaced by a newer one before a slow page was ready for it
  std::uint64_t bytes_sent = 0;
  std::size_t open_connections = 0;
  std::uint64_t page_serial = 0;       // the last page's serial (pages are numbered from 1)
};

class ViewServer {
 public:
  static constexpr std::size_t kMaxConnections = 64;

  // Binds and listens on `endpoint` (port 0: any free port); throws boost::system::system_error if it cannot.
  // Requests are answered only with a Host header naming this server and, if they carry one, the Origin of its own
  // page (request_check.h); `host_names` are DNS names accepted beside the loopback names, the IP literals of a
  // non-loopback listen address and this machine's host name (lower case).
  // `touch` (may be null: no page steers anything) decides which page steers the web hand; it must outlive the server.
  ViewServer(boost::asio::io_context& io, const boost::asio::ip::tcp::endpoint& endpoint, const WebRoot& web,
             ViewFeed& feed, std::vector<std::string> host_names = {}, TouchControl* touch = nullptr);
  ~ViewServer();

  boost::asio::ip::tcp::endpoint local_endpoint() const { return acceptor_.local_endpoint(); }
  const ServerCounters& counters() const { return *counters_; }

  // Starts accepting and feeding; returns at once (the io_context's run() does the work).
  void start();
  // Closes the listening socket and every page; run() then returns once their last handlers finish.
  void stop();

 private:
  void accept();
  void tick();

  boost::asio::io_context& io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer timer_;
  const WebRoot& web_;
  ViewFeed& feed_;
  TouchControl* touch_;
  HostRule host_rule_;
  // Shared with the sessions: a session may outlive the server by the handlers io_context still holds.
  std::shared_ptr<ServerCounters> counters_;
  std::vector<std::weak_ptr<WsSession>> pages_;
  std::int64_t last_tick_ns_ = 0;
  bool stopped_ = false;
};

}  // namespace impetus::view
