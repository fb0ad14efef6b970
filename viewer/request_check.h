// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which requests the viewer answers, by their Host and Origin headers: what keeps another web site open in the user's
// browser from reading the live world.
//
// Host: a page on evil.example whose DNS name is re-pointed at 127.0.0.1 (DNS rebinding) sends its requests with
// `Host: evil.example`. So the Host header must name this server: on a loopback listen address a loopback name
// (localhost, 127.x.y.z, [::1]); on another address (--allow-remote) any IP address literal (rebinding needs a DNS
// name), localhost, this machine's host name, or a name given with --allow-host. The port must be the one listened on.
// Origin: a browser sends it with every WebSocket opening, and a page of another site may open a WebSocket to any
// address. So an Origin, when present, must be the viewer's own page: http://<the Host header>. Clients that are not
// browsers send none and are answered.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace impetus::view {

struct HostRule {
  std::uint16_t port = 0;                 // the port listened on
  bool loopback_only = true;              // the listen address is loopback
  std::vector<std::string> names;         // more DNS names accepted (lower case): the host name, --allow-host
};

// Why a request with this Host header is refused, or "" if it is answered. `host` is the header's value as sent.
std::string host_problem(std::string_view host, const HostRule& rule);

// Why a request with this Origin header is refused, or "" if it is answered (`origin` empty: no Origin header).
std::string origin_problem(std::string_view origin, std::string_view host);

}  // namespace impetus::view
