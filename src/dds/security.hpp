// DDS Security for a participant, switched on as ROS 2 switches it on (rcl security.c,
// rmw_cyclonedds configure_qos_for_security): ROS_SECURITY_ENABLE=true, ROS_SECURITY_STRATEGY
// (Enforce | anything else: Permissive), ROS_SECURITY_KEYSTORE, ROS_SECURITY_ENCLAVE_OVERRIDE; the
// enclave's files become Cyclone's dds.sec.* participant properties, served by the Cyclone security
// plugins (auth, access control, crypto).
#pragma once

#include <dds/dds.h>

#include <filesystem>
#include <string>

namespace quadcosim::dds {

enum class SecurityStrategy { kPermissive, kEnforce };

/// The ROS 2 security environment, as read (no files are looked at here).
struct SecurityEnvironment {
  bool enabled = false;                                       ///< ROS_SECURITY_ENABLE is exactly "true"
  SecurityStrategy strategy = SecurityStrategy::kPermissive;  ///< ROS_SECURITY_STRATEGY == "Enforce"
  std::string keystore;                                       ///< ROS_SECURITY_KEYSTORE ("" when unset)
  std::string enclave_override;                               ///< ROS_SECURITY_ENCLAVE_OVERRIDE ("" when unset)
  std::string warning;  ///< a value rcl would silently read differently than written, or ""
};

/// Reads the four variables. As rcl: only "true" enables, only "Enforce" enforces. A value that is
/// neither of the documented ones (e.g. "enforce", "1") is read the same way but noted in `warning`.
SecurityEnvironment read_security_environment();

/// What a participant in `enclave` does about security.
struct SecurityPlan {
  bool secured = false;
  std::filesystem::path root;  ///< the enclave directory in use (secured only)
  std::string enclave_used;    ///< the enclave whose files are used (the override, if set)
  std::string note;            ///< one line for the log: what was decided and why ("" when disabled)
};

/// Decides for `enclave` (the name the node runs in, e.g. from --enclave; "/" by default). The files
/// come from ROS_SECURITY_KEYSTORE/enclaves/<ROS_SECURITY_ENCLAVE_OVERRIDE or enclave>, as rcl
/// resolves them, and are checked with OpenSSL (security/keystore.hpp check_enclave). Enforce: throws
/// DdsError naming the variable, the directory or each missing/unusable file. Permissive: returns an
/// unsecured plan whose note says why.
SecurityPlan plan_security(const SecurityEnvironment& env, const std::string& enclave);

/// Sets the dds.sec.* properties on a participant QoS for the enclave directory `root`: the six
/// documents as file: URIs and the three plugin libraries (with init/finalize symbols).
void set_security_qos(dds_qos_t* qos, const std::filesystem::path& root);

/// The plugin library to load for `name` ("dds_security_auth", "dds_security_ac",
/// "dds_security_crypto"): the full path in Debian's libddsc0debian directory beside libddsc when the
/// file is there, otherwise the bare name (Cyclone then searches the library path).
std::string security_plugin(const std::string& name);

}  // namespace quadcosim::dds
