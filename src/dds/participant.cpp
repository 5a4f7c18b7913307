#include "dds/participant.hpp"

#include "security/keystore.hpp"

#include <cerrno>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace quadcosim::dds {

dds_return_t check(dds_return_t rc, const char* what) {
  if (rc < 0) {
    throw DdsError(std::string(what) + " failed: " + dds_strretcode(rc) + " (" + std::to_string(rc) + ")");
  }
  return rc;
}

void write_now(dds_entity_t writer, const void* sample, const char* what) {
  check(dds_write(writer, sample), what);
  dds_write_flush(writer);
}

namespace {
std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}
}  // namespace

RosEnvironment read_ros_environment(const std::string& enclave) {
  RosEnvironment e;
  if (const std::string why = security::enclave_name_error(enclave); !why.empty()) {
    throw DdsError("enclave '" + enclave + "': " + why);
  }
  e.enclave = enclave;
  e.security = read_security_environment();
  const std::string id = env("ROS_DOMAIN_ID");
  if (!id.empty()) {
    errno = 0;
    char* end = nullptr;
    const unsigned long v = std::strtoul(id.c_str(), &end, 0);
    // 232 is the largest id whose RTPS ports stay below 65535 with the default port mapping.
    if (errno != 0 || end == id.c_str() || *end != '\0' || v > 232) {
      throw DdsError("ROS_DOMAIN_ID='" + id + "': expected a whole number in [0, 232]");
    }
    e.domain_id = static_cast<std::uint32_t>(v);
  }
  const std::string range = env("ROS_AUTOMATIC_DISCOVERY_RANGE");
  if (range.empty() || range == "SUBNET") {
    e.range = DiscoveryRange::kSubnet;
  } else if (range == "LOCALHOST") {
    e.range = DiscoveryRange::kLocalhost;
  } else if (range == "OFF") {
    e.range = DiscoveryRange::kOff;
  } else if (range == "SYSTEM_DEFAULT") {
    e.range = DiscoveryRange::kSystemDefault;
  } else {
    throw DdsError("ROS_AUTOMATIC_DISCOVERY_RANGE='" + range + "': expected SUBNET, LOCALHOST, OFF or SYSTEM_DEFAULT");
  }
  if (env("ROS_LOCALHOST_ONLY") == "1") e.range = DiscoveryRange::kLocalhost;
  e.static_peers = env("ROS_STATIC_PEERS");
  e.cyclonedds_uri = env("CYCLONEDDS_URI");
  return e;
}

std::string cyclone_config(const RosEnvironment& e) {
  std::ostringstream x;
  x << "<CycloneDDS><Domain id=\"any\">";
  if (e.range == DiscoveryRange::kLocalhost || e.range == DiscoveryRange::kOff) {
    x << "<General><AllowMulticast>false</AllowMulticast></General>";
  }
  x << "<Discovery>";
  if (e.range != DiscoveryRange::kSystemDefault) {
    x << "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>";
  }
  std::string peers;
  if (e.range == DiscoveryRange::kLocalhost) peers += "<Peer address=\"localhost\"/>";
  std::stringstream sp(e.static_peers);
  for (std::string p; std::getline(sp, p, ';');) {
    if (!p.empty()) peers += "<Peer address=\"" + p + "\"/>";
  }
  if (!peers.empty()) x << "<Peers>" << peers << "</Peers>";
  x << "</Discovery></Domain></CycloneDDS>";
  std::string config = x.str();
  if (!e.cyclonedds_uri.empty()) config += "," + e.cyclonedds_uri;
  return config;
}

Participant::Participant(const RosEnvironment& env) : domain_id_(env.domain_id) {
  const SecurityPlan security = plan_security(env.security, env.enclave);  // throws under Enforce
  if (!security.note.empty()) std::cerr << security.note << '\n';
  const std::string config = cyclone_config(env);
  const dds_entity_t domain = dds_create_domain(env.domain_id, config.c_str());
  // A domain with this id may already exist in this process (e.g. two nodes in one test): then the
  // participant joins it with the configuration it already has.
  if (domain < 0 && domain != DDS_RETCODE_PRECONDITION_NOT_MET) check(domain, "dds_create_domain");
  domain_ = Entity(domain);  // deleted again if what follows throws
  const Qos qos(dds_create_qos());
  // As rmw: the enclave given to the node (not the override, which only selects the files).
  const std::string user_data = "enclave=" + env.enclave + ";";
  dds_qset_userdata(qos.get(), user_data.data(), user_data.size());
  if (security.secured) set_security_qos(qos.get(), security.root);
  const dds_entity_t participant = dds_create_participant(env.domain_id, qos.get(), nullptr);
  if (participant < 0 && security.secured) {
    throw DdsError("dds_create_participant with security (enclave " + security.enclave_used + ", " +
                   security.root.string() + ") failed: " + dds_strretcode(participant) +
                   "; Cyclone's reason is in its log above (a domain id the governance or permissions do "
                   "not cover, or a plugin that cannot be loaded, are common causes)");
  }
  participant_ = Entity(check(participant, "dds_create_participant"));
  secured_ = security.secured;
}

dds_qos_t* ros_qos(int depth, bool reliable, bool transient_local) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_INFINITY);
  dds_qset_durability(q, transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_INFINITY);
  dds_qset_writer_data_lifecycle(q, false);
  const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q, 1, xcdr1);
  return q;
}

}  // namespace quadcosim::dds
