// SPDX-License-Identifier: Apache-2.0
#include "common/link/dds/dds_participant.h"

#include <dds/dds.h>

#include <cstdlib>
#include <mutex>
#include <set>
#include <stdexcept>

namespace impetus {

std::string describe(const DdsLinkOptions& options) {
  return "DDS domain " + std::to_string(options.domain_id) + " partition '" + options.partition + "'";
}

std::int32_t dds_check(std::int32_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error(what + ": " + dds_strretcode(status));
  return status;
}

std::string dds_domain_config() {
  std::string config;
  if (const char* user = std::getenv("CYCLONEDDS_URI"); user != nullptr && *user != '\0') config = std::string(user) + ",";
  const int lease_ms = static_cast<int>(kDdsLease_s * 1000.0);
  config += "<Discovery><LeaseDuration>" + std::to_string(lease_ms) + "ms</LeaseDuration></Discovery>";
  return config;
}

namespace {

// Creates domain `id` with our configuration the first time a participant in it is asked for. It lives until the
// process exits (Cyclone tears it down then): participants come and go, the configuration stays one.
void ensure_domain(std::uint32_t id) {
  static std::mutex mutex;
  static std::set<std::uint32_t> created;
  const std::lock_guard<std::mutex> lock(mutex);
  if (created.count(id) != 0) return;
  const dds_entity_t domain = dds_create_domain(id, dds_domain_config().c_str());
  // Already there: something else in this process created it (a participant without us); use it as it is.
  if (domain < 0 && domain != DDS_RETCODE_PRECONDITION_NOT_MET) {
    dds_check(domain, "cannot create DDS domain " + std::to_string(id) + " (check CYCLONEDDS_URI)");
  }
  created.insert(id);
}

}  // namespace

DdsParticipant::DdsParticipant(const DdsLinkOptions& options) : options_(options) {
  if (options.domain_id > kMaxDdsDomainId) {
    throw std::invalid_argument("DDS domain id must be between 0 and " + std::to_string(kMaxDdsDomainId) + ", not " +
                                std::to_string(options.domain_id));
  }
  if (options.partition.empty()) throw std::invalid_argument("the DDS partition name must not be empty");
  ensure_domain(options.domain_id);
  participant_ = dds_check(dds_create_participant(options.domain_id, nullptr, nullptr),
                           "cannot join " + describe(options));
}

DdsParticipant::~DdsParticipant() { dds_delete(participant_); }

}  // namespace impetus
