// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which transport carries the world link (docs/architecture.md §2), as the daemons' --link flags choose it: shared
// memory on one host (the default; lockstep and real time), or DDS across hosts (real time; common/link/dds).

#include "common/link/link_loss.h"

#include <cstdint>
#include <string>

namespace impetus {

enum class LinkKind { shm, dds };

// Where a DDS world link meets: a DDS domain (an id) and a partition (a name) within it. Worlds and controllers with
// the same pair see each other, on this host or across the network; any other pair is invisible.
struct DdsLinkOptions {
  std::uint32_t domain_id = 0;
  std::string partition = "impetus";
  // DDS Security (authentication, access control, encryption): a folder made by scripts/dds_security.sh with this
  // participant's credentials (dds_participant.h lists the files). Empty: an open link, which anyone on the network
  // segment can join.
  std::string security_dir;
  // A delay and loss stage on what this process receives (common/link/delay_stage.h), for experiments where the
  // kernel cannot delay the network (no netem): frames for a controller, reports for a world. Give both ends the
  // same values for a symmetric link. Off by default (0 and no loss).
  double delay_s = 0.0;
  LinkLoss loss;
};

// The longest delay the stage holds: a second, as the in-process link's delay line.
inline constexpr double kMaxDdsDelay_s = 1.0;

// Highest domain id: the RTPS port mapping (7400 + 250·domain + offsets) stays below 65536 up to 232.
inline constexpr std::uint32_t kMaxDdsDomainId = 232;

struct LinkOptions {
  LinkKind kind = LinkKind::shm;
  DdsLinkOptions dds;
};

}  // namespace impetus
