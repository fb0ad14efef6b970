// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link a daemon's --link names, opened in one place (docs/architecture.md §2): shared memory by name, or
// DDS by domain and partition. The daemons ask this instead of naming a transport.

#include "common/link/link_options.h"
#include "common/link/world_link.h"
#include "common/contract/world_view.h"
#include "common/runtime/lockstep.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>

namespace impetus {

// The haptic side's end for `endpoints` fingers: shared memory named `shm`, or DDS. Waits up to `wait_s` for the
// world; throws std::runtime_error when it does not come, std::invalid_argument for options the transport cannot use.
std::unique_ptr<WorldLinkClient> open_world_link_client(const LinkOptions& options, const std::string& shm,
                                                         ClockMode clock, double wait_s, std::uint32_t endpoints);
// The world's end, serving `info`.
std::unique_ptr<WorldLinkServer> open_world_link_server(const LinkOptions& options, const std::string& shm,
                                                         const WorldLinkInfo& info);
// The world view's publisher (docs/architecture.md §1): "<shm>.view" for viewers on this host (read-only), and over DDS
// too when `options` name DDS.
std::unique_ptr<WorldViewPublisher> open_world_view_publisher(const LinkOptions& options, const std::string& shm);
// Where a link is, for messages: "'NAME'" in shared memory, DDS's domain and partition.
std::string link_name(const WorldLinkServer& link);
// What a transport adds to a daemon's summary (DDS: domain, partition and its counters), or null for none.
nlohmann::json link_summary(const WorldLinkClient& link, const LinkOptions& options);
nlohmann::json link_summary(const WorldLinkServer& link, const LinkOptions& options);

}  // namespace impetus
