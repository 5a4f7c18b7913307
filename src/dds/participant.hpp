// A DDS domain participant that looks like a ROS 2 node's to other ROS 2 participants: domain id from
// ROS_DOMAIN_ID, discovery range from ROS_AUTOMATIC_DISCOVERY_RANGE / ROS_LOCALHOST_ONLY /
// ROS_STATIC_PEERS (as rmw_cyclonedds maps them onto Cyclone's configuration), USER_DATA
// "enclave=<enclave>;", and DDS Security from ROS_SECURITY_* (dds/security.hpp).
#pragma once

#include <dds/dds.h>

#include <cstdint>
#include <stdexcept>
#include <string>

#include "dds/entity.hpp"
#include "dds/security.hpp"

namespace quadcosim::dds {

/// A failure of the DDS layer; what() names the call and Cyclone's return code.
class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws DdsError when `rc` is a Cyclone error code; returns it otherwise.
dds_return_t check(dds_return_t rc, const char* what);

/// dds_write, then the writer's datagram sent now. A DdsTransport's domain packs writes until a
/// flush (DdsTransport::hold_sends), so every write of quadcosim's own is either flushed at once or
/// held by a transport and flushed at its release. Throws DdsError naming `what` on an error.
void write_now(dds_entity_t writer, const void* sample, const char* what);

enum class DiscoveryRange { kSubnet, kLocalhost, kOff, kSystemDefault };

/// The ROS 2 environment, parsed (docs/ros2.md, Domain and discovery).
struct RosEnvironment {
  std::uint32_t domain_id = 0;
  DiscoveryRange range = DiscoveryRange::kSubnet;
  std::string static_peers;  ///< ';'-separated addresses
  std::string cyclonedds_uri;
  std::string enclave = "/";     ///< the node's enclave (rcl --enclave): USER_DATA and security files
  SecurityEnvironment security;  ///< ROS_SECURITY_*
};

/// Reads ROS_DOMAIN_ID (base 0 like strtoul; unset or empty: 0), ROS_AUTOMATIC_DISCOVERY_RANGE,
/// ROS_LOCALHOST_ONLY=1 (forces LOCALHOST), ROS_STATIC_PEERS, CYCLONEDDS_URI and the ROS_SECURITY_*
/// variables; `enclave` is the node's enclave name ("/" unless --enclave says otherwise). Throws
/// DdsError naming the variable and value when one is malformed (e.g. a domain id above 232), or the
/// enclave when it is not a valid enclave name.
RosEnvironment read_ros_environment(const std::string& enclave = "/");

/// The Cyclone configuration XML for the environment, as rmw_cyclonedds builds it.
std::string cyclone_config(const RosEnvironment& env);

/// RAII participant. Not copyable; deleting it deletes every entity it created.
class Participant {
 public:
  /// Creates the domain (with the configuration for `env`) and the participant; with security on,
  /// the participant carries the enclave's dds.sec.* properties (Enforce: throws DdsError naming
  /// what is missing or unusable; Permissive: a warning on stderr and no security). A one-line note
  /// on stderr says what was decided whenever security is on.
  explicit Participant(const RosEnvironment& env);
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  dds_entity_t handle() const { return participant_.get(); }
  std::uint32_t domain_id() const { return domain_id_; }
  /// True when the participant runs with DDS Security (authenticated, access-controlled).
  bool secured() const { return secured_; }

 private:
  Entity domain_;       ///< when this participant created its domain
  Entity participant_;  ///< deleted before the domain (declared after it)
  std::uint32_t domain_id_ = 0;
  bool secured_ = false;
};

/// The QoS rmw uses for `depth` KEEP_LAST, RELIABLE (or BEST_EFFORT), VOLATILE (or TRANSIENT_LOCAL:
/// a writer keeps its last `depth` samples for readers that join later, as robot_state_publisher's
/// robot_description and tf2's /tf_static), XCDR1 only. Caller owns the result (hold it in a dds::Qos).
dds_qos_t* ros_qos(int depth, bool reliable, bool transient_local = false);

}  // namespace quadcosim::dds
