// SPDX-License-Identifier: Apache-2.0
#include "common/link/dds/open_world_link.h"

#include "common/link/dds/dds_world_link.h"
#include "common/link/dds/dds_world_view.h"
#include "common/link/shm/shm_world_link.h"
#include "common/link/shm/shm_world_view.h"
#include "common/link/world_view_tee.h"

namespace impetus {

std::unique_ptr<WorldLinkClient> open_world_link_client(const LinkOptions& options, const std::string& shm,
                                                         ClockMode clock, double wait_s, std::uint32_t endpoints) {
  if (options.kind == LinkKind::dds) {
    return std::make_unique<DdsWorldLinkClient>(options.dds, clock, wait_s, endpoints);
  }
  return std::make_unique<ShmWorldLinkClient>(shm, clock, wait_s, endpoints);
}

std::unique_ptr<WorldLinkServer> open_world_link_server(const LinkOptions& options, const std::string& shm,
                                                         const WorldLinkInfo& info) {
  if (options.kind == LinkKind::dds) return std::make_unique<DdsWorldLinkServer>(options.dds, info);
  return std::make_unique<ShmWorldLinkServer>(shm, info);
}

std::unique_ptr<WorldViewPublisher> open_world_view_publisher(const LinkOptions& options, const std::string& shm) {
  auto tee = std::make_unique<WorldViewTee>();
  tee->add(std::make_unique<ShmWorldViewPublisher>(shm));
  if (options.kind == LinkKind::dds) tee->add(std::make_unique<DdsWorldViewPublisher>(options.dds));
  return tee;
}

std::string link_name(const WorldLinkServer& link) {
  if (const auto* dds = dynamic_cast<const DdsWorldLinkServer*>(&link)) return dds->name();
  if (const auto* shm = dynamic_cast<const ShmWorldLinkServer*>(&link)) return "'" + shm->name() + "'";
  return "in-process";
}

nlohmann::json link_summary(const WorldLinkClient& link, const LinkOptions& options) {
  const auto* dds = dynamic_cast<const DdsWorldLinkClient*>(&link);
  if (dds == nullptr) return nullptr;
  return {{"domain", options.dds.domain_id}, {"partition", options.dds.partition}, {"reports_sent", dds->reports_sent()},
          {"other_worlds", dds->other_worlds()}, {"foreign_frames", dds->foreign_frames()}};
}

nlohmann::json link_summary(const WorldLinkServer& link, const LinkOptions& options) {
  const auto* dds = dynamic_cast<const DdsWorldLinkServer*>(&link);
  if (dds == nullptr) return nullptr;
  return {{"domain", options.dds.domain_id},
          {"partition", options.dds.partition},
          {"refused_endpoints", dds->refused_endpoints()},
          {"foreign_reports", dds->foreign_reports()},
          {"released_slots", dds->released_slots()}};
}

}  // namespace impetus
