// An SROS2-compatible DDS Security keystore, made and checked with OpenSSL's libcrypto.
//
// Layout (the one `ros2 security create_keystore` / `create_enclave` writes, so either tool's
// keystore serves both):
//
//   DIR/public/ca.cert.pem                  self-signed CA, CN "sros2CA", EC prime256v1, 10 years,
//                                           basicConstraints critical CA:TRUE, pathlen:1
//   DIR/public/{identity,permissions}_ca.cert.pem -> ca.cert.pem   (one key serves both CAs)
//   DIR/private/ca.key.pem (+ identity_ca.key.pem, permissions_ca.key.pem -> ca.key.pem), PKCS#8
//   DIR/enclaves/governance.xml, governance.p7s   (S/MIME, detached, text, signed by the permissions CA)
//   DIR/enclaves/<enclave path>/                  e.g. enclaves/quadcosim/plant for "/quadcosim/plant":
//       cert.pem, key.pem                 identity: EC prime256v1, CN = the enclave name, signed by the
//                                          identity CA, valid from one day ago for 10 years
//       identity_ca.cert.pem, permissions_ca.cert.pem, governance.p7s   relative symlinks
//       permissions.xml, permissions.p7s  the grant for CN=<enclave>, signed by the permissions CA
//
// Bad input (an invalid enclave name, a keystore that is not one, an unreadable or unwritable file)
// throws KeystoreError naming the path or value and what was expected.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace quadcosim::security {

class KeystoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// "" when `name` is a valid enclave name (rcl's rule, the one for absolute namespaces: "/" or
/// "/tok/tok", tokens of [A-Za-z0-9_] not starting with a digit, no "//", no trailing "/",
/// at most 255 characters); otherwise why not.
std::string enclave_name_error(const std::string& name);

/// The directory rcl uses for `enclave` in `keystore`: keystore/enclaves for "/", otherwise
/// keystore/enclaves/<name without its leading '/'>.
std::filesystem::path enclave_dir(const std::filesystem::path& keystore, const std::string& enclave);

/// What an enclave may do. The default is SROS2's default policy: publish and subscribe every topic
/// (rt/*), call and serve every service (rq/*Request, rr/*Reply) and action, and ros_discovery_info.
/// docs/security.md lists the DDS topics each policy grants and denies.
struct EnclavePolicy {
  /// ROS topic names (fully qualified, e.g. "/drone/motor_commands"; DDS wildcards * ? allowed) the
  /// enclave may NOT publish; when any is given, it may not set any node's parameters either
  /// (parameter_change_requests()). It may still subscribe them.
  std::vector<std::string> deny_publish;
  /// The DDS domain the grant holds for (sros2 takes ROS_DOMAIN_ID at creation time).
  std::uint32_t domain_id = 0;
  /// Subscribe only: every topic (rt/*) may be read, nothing written (no topic, no service request
  /// or reply), except ros_discovery_info, which carries the node's name. Excludes deny_publish.
  bool read_only = false;
};

/// The DDS request topics that change a node's parameters (set_parameters, set_parameters_atomically
/// of every node), denied with any deny_publish.
const std::vector<std::string>& parameter_change_requests();

/// The governance document sros2 writes: no unauthenticated participants, join access control,
/// discovery and liveliness ENCRYPT, RTPS SIGN, every topic with read/write access control and
/// metadata/data ENCRYPT, for `domain_id`.
std::string governance_xml(std::uint32_t domain_id);

/// The permissions document for `enclave` under `policy`, with the grant valid over
/// [not_before, not_after] (ISO 8601 UTC without zone, "2026-01-31T12:00:00", as sros2 writes them).
std::string permissions_xml(const std::string& enclave, const EnclavePolicy& policy, const std::string& not_before,
                            const std::string& not_after);

/// True when `dir` holds the files sros2 calls a valid keystore (both CA certs and keys,
/// enclaves/governance.p7s).
bool is_keystore(const std::filesystem::path& dir);

/// Creates a keystore in `dir` (created when missing) for `domain_id`: CA, governance. Throws when
/// `dir` already is a keystore (nothing is overwritten). private/ is made 0700 (also when it existed)
/// and its key is created 0600 (O_CREAT|O_EXCL, umask 077): never readable by others, not for an
/// instant; an existing private/ca.key.pem is an error, never overwritten.
void create_keystore(const std::filesystem::path& dir, std::uint32_t domain_id);

/// Creates (or updates) enclave `name` in keystore `dir`: identity key and certificate when they do
/// not exist yet (kept otherwise, as sros2 does), CA and governance links, permissions.xml and
/// permissions.p7s always rewritten from `policy`. Returns the enclave's directory, made 0700 (also
/// when it existed), with key.pem created 0600 as create_keystore creates the CA key.
std::filesystem::path create_enclave(const std::filesystem::path& dir, const std::string& name,
                                     const EnclavePolicy& policy);

/// Every reason the enclave directory `dir` cannot be used for DDS Security, each naming the file:
/// a missing file, a PEM that does not parse, an identity certificate that does not verify against
/// identity_ca.cert.pem or is outside its validity, a key that does not belong to the certificate,
/// a governance or permissions document whose S/MIME signature does not verify against
/// permissions_ca.cert.pem, a permissions document without a grant for the certificate's subject,
/// a governance.xml or permissions.xml (beside the .p7s, or beside the file it links to) whose text
/// is not the text signed. Empty when the enclave is usable.
std::vector<std::string> check_enclave(const std::filesystem::path& dir);

/// Every private key or folder of keys that group or others may use, each naming the path, its mode
/// and the mode wanted: `enclave` (any group/other read or write bit) and its key.pem (any group/other
/// bit), `keystore`/private and the CA keys in it (links followed). Paths that do not exist are
/// skipped (a vehicle's machine may hold one enclave and no private/). Empty when all are private.
std::vector<std::string> key_mode_problems(const std::filesystem::path& keystore, const std::filesystem::path& enclave);

/// The file names an enclave directory needs (rmw_dds_common's list), in the order checked.
const std::vector<std::string>& enclave_files();

}  // namespace quadcosim::security
