// SPDX-License-Identifier: Apache-2.0
#include "viewer/touch_control.h"

#include "common/runtime/loop_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace impetus::view {
namespace {

constexpr std::int64_t kReopenEvery_ns = 500'000'000;  // looking for an absent device twice a second is enough
constexpr std::size_t kMaxTokenChars = 64;

// Equal strings, in a time that does not depend on where they first differ: a page on this machine cannot find the
// token a digit at a time by timing its refusals.
bool same_secret(std::string_view a, std::string_view b) {
  unsigned char differ = a.size() == b.size() ? 0 : 1;
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t i = 0; i < n; ++i) differ |= static_cast<unsigned char>(a[i] ^ b[i]);
  return differ == 0;
}

nlohmann::json vec(const Vec3& v) { return nlohmann::json::array({v[0], v[1], v[2]}); }

}  // namespace

std::string new_touch_token() {
  std::random_device device;
  std::string token;
  for (int i = 0; i < 4; ++i) {
    char part[9];
    std::snprintf(part, sizeof part, "%08x", static_cast<unsigned>(device()));
    token += part;
  }
  return token;
}

TouchControl::TouchControl(PortOpener open, std::string token, Clock clock)
    : open_(std::move(open)), token_(std::move(token)), clock_(clock != nullptr ? clock : &monotonic_now_ns) {}

bool TouchControl::port_ready() {
  if (port_ && port_->host_alive()) return true;
  const std::int64_t now_ns = clock_();
  if (port_ == nullptr && now_ns < next_open_ns_) return false;
  port_.reset();
  next_open_ns_ = now_ns + kReopenEvery_ns;
  try {
    port_ = open_();
  } catch (const std::exception& error) {
    port_problem_ = error.what();
    port_.reset();
  }
  if (port_ == nullptr) return false;
  // A device's successor knows nothing of the page that held its predecessor: that page takes it again.
  holder_ = 0;
  return true;
}

nlohmann::json TouchControl::state(const char* name, const std::string& reason) const {
  nlohmann::json reply = {{"type", "touch"}, {"state", name}};
  if (!reason.empty()) reply["reason"] = reason;
  HandState hand{};
  if (port_ && port_->latest_hand(hand)) {
    reply["hand"] = {{"finger_m", vec(hand.finger_m)},
                     {"workspace_min_m", vec(hand.workspace_min_m)},
                     {"workspace_max_m", vec(hand.workspace_max_m)},
                     {"max_force_N", hand.max_force_N}};
  }
  return reply;
}

nlohmann::json TouchControl::on_message(std::uint64_t page, bool from_page, const nlohmann::json& message, bool& ok) {
  ok = false;
  const auto what = message.find("touch");
  if (page == 0 || what == message.end() || !what->is_string()) return nullptr;
  const std::string& kind = what->get_ref<const std::string&>();
  if (kind == "take") {
    if (message.size() != 2 || !message.contains("token") || !message["token"].is_string() ||
        message["token"].get_ref<const std::string&>().size() > kMaxTokenChars) {
      return nullptr;
    }
    ok = true;
    return take(page, from_page, message);
  }
  if (kind == "target") {
    const auto target = message.find("target_m");
    if (message.size() != 2 || target == message.end() || !target->is_array() || target->size() != 3) return nullptr;
    Vec3 t{};
    for (int a = 0; a < 3; ++a) {
      if (!(*target)[a].is_number()) return nullptr;
      t[a] = (*target)[a].get<double>();
      if (!std::isfinite(t[a]) || std::abs(t[a]) > kMaxTouchTarget_m) return nullptr;
    }
    ok = true;
    if (page != holder_) return state("watching");
    if (!port_ready() || page != holder_) return state("watching", "the web hand restarted: take it again");
    const std::int64_t now_ns = clock_();
    longest_gap_ns_ = std::max(longest_gap_ns_, now_ns - input_.received_ns);
    ++targets_;
    input_.target_m = t;
    input_.received_ns = now_ns;
    port_->publish_input(input_);
    return nullptr;
  }
  if (kind == "release") {
    if (message.size() != 1) return nullptr;
    ok = true;
    if (page == holder_) release(clock_());
    return state("released");
  }
  return nullptr;
}

nlohmann::json TouchControl::without_touch(const nlohmann::json& message, bool& ok) {
  const auto what = message.find("touch");
  ok = what != message.end() && what->is_string();
  if (!ok) return nullptr;
  return {{"type", "touch"}, {"state", "unavailable"}, {"reason", "this viewer does not take input (start it with --touch)"}};
}

nlohmann::json TouchControl::take(std::uint64_t page, bool from_page, const nlohmann::json& message) {
  if (token_.empty()) {
    ++refusals_;
    return state("unavailable", "this viewer does not take input (start it with --touch)");
  }
  if (!from_page) {
    ++refusals_;
    return state("refused", "only a page this viewer served (a browser page of its own origin) may take the hand");
  }
  if (!same_secret(message["token"].get_ref<const std::string&>(), token_)) {
    ++refusals_;
    return state("refused", "wrong token: open the address the viewer printed");
  }
  if (!port_ready()) {
    ++refusals_;
    return state("unavailable", port_problem_);
  }
  if (holder_ != 0 && holder_ != page) {
    ++refusals_;
    return state("watching", "another page holds the hand");
  }
  if (holder_ != page) {
    holder_ = page;
    HandState hand{};
    input_ = TouchInput{};
    input_.page = page;
    // The target starts where the fingertip rests; the page sends its own from there.
    if (port_->latest_hand(hand)) input_.target_m = hand.finger_m;
  }
  input_.received_ns = clock_();
  input_.released_ns = 0;
  port_->publish_input(input_);
  return state("holding");
}

void TouchControl::release(std::int64_t now_ns) {
  if (holder_ == 0) return;
  holder_ = 0;
  if (!port_) return;
  input_.released_ns = now_ns;
  port_->publish_input(input_);
}

void TouchControl::page_closed(std::uint64_t page) {
  if (page != 0 && page == holder_) release(clock_());
}

}  // namespace impetus::view
