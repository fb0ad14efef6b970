// SPDX-License-Identifier: Apache-2.0
#include "common/link/dds/dds_participant.h"

#include <dds/dds.h>
#include <dlfcn.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <stdexcept>

namespace impetus {

std::string describe(const DdsLinkOptions& options) {
  return "DDS domain " + std::to_string(options.domain_id) + " partition '" + options.partition + "'" +
         (options.security_dir.empty() ? "" : " (secured)");
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

// Where Cyclone's security plugins are: beside libddsc, or (Debian) in its libddsc0debian/ folder. Empty if neither.
std::filesystem::path security_plugin_dir() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&dds_create_participant), &info) == 0 || info.dli_fname == nullptr) return {};
  const std::filesystem::path library_dir = std::filesystem::path(info.dli_fname).parent_path();
  for (const std::filesystem::path& dir : {library_dir / "libddsc0debian", library_dir}) {
    std::error_code error;
    if (std::filesystem::is_regular_file(dir / "libdds_security_auth.so", error)) return dir;
  }
  return {};
}

// The participant QoS of a secured link: the three built-in plugins and this participant's files (DDS Security
// 1.1, §9's property names).
dds_qos_t* security_qos(const DdsLinkOptions& options) {
  namespace fs = std::filesystem;
  const fs::path dir(options.security_dir);
  const std::array<const char*, 6> files{"identity_ca.pem", "permissions_ca.pem", "governance.p7s",
                                         "cert.pem",        "key.pem",            "permissions.p7s"};
  for (const char* file : files) {
    std::error_code error;
    if (!fs::is_regular_file(dir / file, error)) {
      throw std::runtime_error("--dds-security " + options.security_dir + ": no " + file +
                               " (make the folder with scripts/dds_security.sh)");
    }
  }
  const fs::path plugins = security_plugin_dir();
  if (plugins.empty()) {
    throw std::runtime_error("--dds-security: Cyclone DDS's security plugins (libdds_security_auth.so) were not "
                             "found beside libddsc (Debian ships them in libddsc0debian)");
  }
  const auto file = [&](const char* name) { return "file:" + fs::absolute(dir / name).string(); };
  dds_qos_t* qos = dds_create_qos();
  struct Plugin {
    const char* prefix;
    const char* library;
    const char* init;
    const char* finalize;
  };
  for (const Plugin& plugin : {Plugin{"auth", "libdds_security_auth.so", "init_authentication", "finalize_authentication"},
                               Plugin{"crypto", "libdds_security_crypto.so", "init_crypto", "finalize_crypto"},
                               Plugin{"access", "libdds_security_ac.so", "init_access_control",
                                      "finalize_access_control"}}) {
    const std::string base = std::string("dds.sec.") + plugin.prefix + ".library.";
    dds_qset_prop(qos, (base + "path").c_str(), (plugins / plugin.library).c_str());
    dds_qset_prop(qos, (base + "init").c_str(), plugin.init);
    dds_qset_prop(qos, (base + "finalize").c_str(), plugin.finalize);
  }
  dds_qset_prop(qos, "dds.sec.auth.identity_ca", file("identity_ca.pem").c_str());
  dds_qset_prop(qos, "dds.sec.auth.identity_certificate", file("cert.pem").c_str());
  dds_qset_prop(qos, "dds.sec.auth.private_key", file("key.pem").c_str());
  dds_qset_prop(qos, "dds.sec.access.permissions_ca", file("permissions_ca.pem").c_str());
  dds_qset_prop(qos, "dds.sec.access.governance", file("governance.p7s").c_str());
  dds_qset_prop(qos, "dds.sec.access.permissions", file("permissions.p7s").c_str());
  return qos;
}

}  // namespace

DdsParticipant::DdsParticipant(const DdsLinkOptions& options) : options_(options) {
  if (options.domain_id > kMaxDdsDomainId) {
    throw std::invalid_argument("DDS domain id must be between 0 and " + std::to_string(kMaxDdsDomainId) + ", not " +
                                std::to_string(options.domain_id));
  }
  if (options.partition.empty()) throw std::invalid_argument("the DDS partition name must not be empty");
  ensure_domain(options.domain_id);
  dds_qos_t* qos = options.security_dir.empty() ? nullptr : security_qos(options);
  const dds_entity_t participant = dds_create_participant(options.domain_id, qos, nullptr);
  if (qos != nullptr) {
    dds_delete_qos(qos);
    // The security plugins use OpenSSL, which frees its locks in an exit handler, while Cyclone's threads would go
    // on encrypting until Cyclone's own teardown after it: a crash at exit, now and then. Registered after the
    // plugins loaded OpenSSL, this handler runs before OpenSSL's and stops every DDS thread first.
    static const bool registered = std::atexit([] { dds_delete(DDS_CYCLONEDDS_HANDLE); }) == 0;
    (void)registered;
  }
  participant_ = dds_check(participant, "cannot join " + describe(options) +
                                            (options.security_dir.empty()
                                                 ? std::string()
                                                 : " secured with " + options.security_dir +
                                                       " (a certificate or document that does not verify?)"));
}

DdsParticipant::~DdsParticipant() { dds_delete(participant_); }

}  // namespace impetus
