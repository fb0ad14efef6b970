// SPDX-License-Identifier: Apache-2.0
#pragma once
// A DDS participant in the domain a world link meets in (DdsLinkOptions, common/link/link_options.h). Types from
// Cyclone DDS stay in the sources: nothing here needs its headers.

#include "common/link/link_options.h"

#include <cstdint>
#include <string>

namespace impetus {

// "domain D partition 'P'", for messages.
std::string describe(const DdsLinkOptions& options);

// A participant in `options.domain_id`, deleted with everything it created. With `options.security_dir` it joins
// secured (DDS Security's built-in plugins, shipped with Cyclone DDS): the folder must hold identity_ca.pem,
// permissions_ca.pem, governance.p7s (the shared trust and rules) and cert.pem, key.pem, permissions.p7s (this
// participant's identity and grants), as scripts/dds_security.sh makes them; a missing one is named. The domain is created on first use in the
// process with the configuration dds_domain_config() gives; later participants share it. Throws std::runtime_error
// naming the domain if DDS refuses (a bad configuration in CYCLONEDDS_URI, no usable network interface).
class DdsParticipant {
 public:
  explicit DdsParticipant(const DdsLinkOptions& options);
  ~DdsParticipant();
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;

  std::int32_t handle() const { return participant_; }  // a dds_entity_t
  const DdsLinkOptions& options() const { return options_; }

 private:
  DdsLinkOptions options_;
  std::int32_t participant_ = 0;
};

// The configuration a domain is created with: the user's own (the CYCLONEDDS_URI environment variable, Cyclone's
// usual place: files or XML, e.g. the network interface or, for tests, Internal/Test/XmitLossiness), then ours: a
// participant lease of kDdsLease_s, so a peer killed without a goodbye is noticed in seconds rather than Cyclone's
// default 10 s.
std::string dds_domain_config();
inline constexpr double kDdsLease_s = 2.0;

// Throws std::runtime_error("WHAT: <DDS's reason>") when `status` (a dds_return_t or entity handle) is negative;
// returns it otherwise.
std::int32_t dds_check(std::int32_t status, const std::string& what);

}  // namespace impetus
