// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which page steers the web hand (haptic_controller --device web), and what it may send (view_protocol.h §4).
//
// Rules: control is off unless the viewer was started with --touch. A page takes the hand only with the run's token
// (a random one per viewer, printed in the page's address) and only from a browser page of this viewer's own origin
// (the server checked Host and Origin; a client without an Origin header is not a page the viewer served). One page
// holds the hand at a time: others watch until it lets go (closes, hides, releases), then may take it. The holder's
// messages are its heartbeat: the port carries the time each arrived, and the device lets go of a page silent for
// kTouchInputStale_s (common/runtime/staleness.h).
//
// Used from the server's one thread.

#include "common/contract/touch.h"
#include "common/link/touch_port.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace impetus::view {

// A random token of 128 bits, as 32 hexadecimal digits (from the system's random device).
std::string new_touch_token();

class TouchControl {
 public:
  using PortOpener = std::function<std::unique_ptr<TouchPortClient>()>;  // throws or returns nullptr: no device yet
  using Clock = std::int64_t (*)();                                      // CLOCK_MONOTONIC ns
  // `open` finds the web hand's port, looked for again when absent (at most every 0.5 s); `token` is the run's.
  TouchControl(PortOpener open, std::string token, Clock clock = nullptr);

  // A touch message (an object with a "touch" key) from page `page` (a serial, nonzero); `from_page` is whether its
  // WebSocket came from a browser page of this viewer (an Origin header that passed the server's check). Returns the
  // reply to send that page, or null for none. False in `ok` for a message that breaks the protocol (the server
  // closes that page).
  nlohmann::json on_message(std::uint64_t page, bool from_page, const nlohmann::json& message, bool& ok);
  // The answer of a viewer that takes no input, for the same messages.
  static nlohmann::json without_touch(const nlohmann::json& message, bool& ok);
  // Page `page` is gone (closed, lost): it lets go if it held the hand.
  void page_closed(std::uint64_t page);

  const std::string& token() const { return token_; }
  std::uint64_t holder() const { return holder_; }
  std::uint64_t refusals() const { return refusals_; }
  std::uint64_t targets() const { return targets_; }
  // Longest time between two messages of the page that held the hand (its heartbeat's worst gap), ns.
  std::int64_t longest_gap_ns() const { return longest_gap_ns_; }

 private:
  nlohmann::json take(std::uint64_t page, bool from_page, const nlohmann::json& message);
  nlohmann::json state(const char* name, const std::string& reason = {}) const;
  void release(std::int64_t now_ns);
  bool port_ready();

  PortOpener open_;
  std::string token_;
  Clock clock_;
  std::unique_ptr<TouchPortClient> port_;
  std::int64_t next_open_ns_ = 0;
  std::string port_problem_ = "no web hand device is running (haptic_controller --device web)";
  std::uint64_t holder_ = 0;
  TouchInput input_{};
  std::uint64_t refusals_ = 0;
  std::uint64_t targets_ = 0;
  std::int64_t longest_gap_ns_ = 0;
};

}  // namespace impetus::view
