// SPDX-License-Identifier: Apache-2.0
#include "viewer/request_check.h"

#include "common/runtime/ascii.h"

#include <boost/asio/ip/address.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>

namespace impetus::view {
namespace {

// At most this much of a header is quoted in a message: a header is the client's text.
std::string quoted(std::string_view text) {
  constexpr std::size_t kQuote = 80;
  std::string out;
  for (const char c : text.substr(0, kQuote)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return "'" + out + (text.size() > kQuote ? "…'" : "'");
}

struct HostPort {
  std::string name;  // lower case; an IPv6 literal keeps its brackets
  std::uint32_t port = 80;
  bool valid = false;
};

HostPort split(std::string_view host) {
  HostPort out;
  std::string_view name = host;
  std::string_view port;
  if (!host.empty() && host.front() == '[') {
    const auto close = host.find(']');
    if (close == std::string_view::npos) return out;
    name = host.substr(0, close + 1);
    const std::string_view rest = host.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') return out;
      port = rest.substr(1);
    }
  } else if (const auto colon = host.rfind(':'); colon != std::string_view::npos) {
    name = host.substr(0, colon);
    port = host.substr(colon + 1);
  }
  if (name.empty()) return out;
  if (!port.empty() || (host.size() > name.size())) {
    std::uint32_t value = 0;
    const auto [end, error] = std::from_chars(port.data(), port.data() + port.size(), value);
    if (error != std::errc() || end != port.data() + port.size() || port.empty() || value > 65535) return out;
    out.port = value;
  }
  out.name = ascii_lower(name);
  out.valid = true;
  return out;
}

// The address an IP literal names (an IPv6 literal without its brackets), or nothing if `name` is not one.
bool ip_literal(const std::string& name, boost::asio::ip::address& out) {
  std::string bare = name;
  if (bare.size() >= 2 && bare.front() == '[' && bare.back() == ']') bare = bare.substr(1, bare.size() - 2);
  boost::system::error_code error;
  out = boost::asio::ip::make_address(bare, error);
  return !error;
}

}  // namespace

std::string host_problem(std::string_view host, const HostRule& rule) {
  if (host.empty()) return "no Host header";
  const HostPort parsed = split(host);
  if (!parsed.valid) return "Host " + quoted(host) + " is not HOST[:PORT]";
  if (parsed.port != rule.port) {
    return "Host " + quoted(host) + " names port " + std::to_string(parsed.port) + ", not this viewer's " +
           std::to_string(rule.port);
  }
  boost::asio::ip::address address;
  const bool literal = ip_literal(parsed.name, address);
  if (parsed.name == "localhost" || (literal && address.is_loopback())) return "";
  if (!rule.loopback_only) {
    if (literal) return "";
    if (std::find(rule.names.begin(), rule.names.end(), parsed.name) != rule.names.end()) return "";
    return "Host " + quoted(host) + " is not an address of this viewer (an IP address, localhost, this machine's "
           "name or a name given with --allow-host)";
  }
  return "Host " + quoted(host) + " is not a loopback name (localhost, 127.0.0.1 or [::1]): the viewer listens on "
         "loopback only";
}

std::string origin_problem(std::string_view origin, std::string_view host) {
  if (origin.empty()) return "";
  if (ascii_lower(origin) == "http://" + ascii_lower(host)) return "";
  return "Origin " + quoted(origin) + " is not this viewer's page (http://" + std::string(host.substr(0, 80)) + ")";
}

}  // namespace impetus::view
