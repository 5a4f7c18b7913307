#include "dds/node_announcer.hpp"

#include <cstring>
#include <vector>

#include "dds/participant.hpp"
#include "dds/type_hash.hpp"
#include "rmw_dds_common.h"

namespace quadcosim::dds {

namespace {

rmw_dds_common_msg_dds__Gid_ gid_of(dds_entity_t e) {
  dds_guid_t guid;
  check(dds_get_guid(e, &guid), "dds_get_guid");
  rmw_dds_common_msg_dds__Gid_ g;
  static_assert(sizeof(g.data) == sizeof(guid.v));
  std::memcpy(g.data, guid.v, sizeof(g.data));
  return g;
}

std::vector<dds_entity_t> children(dds_entity_t e) {
  std::vector<dds_entity_t> out(64);
  for (;;) {
    const dds_return_t n = dds_get_children(e, out.data(), out.size());
    if (n < 0) return {};
    if (static_cast<std::size_t>(n) <= out.size()) {
      out.resize(static_cast<std::size_t>(n));
      return out;
    }
    out.resize(static_cast<std::size_t>(n));
  }
}

}  // namespace

NodeAnnouncer::NodeAnnouncer(dds_entity_t participant, std::string name, std::string ns)
    : participant_(participant), name_(std::move(name)), ns_(std::move(ns)) {
  if (name_.empty() || name_.size() > 256 || ns_.size() > 256) {
    throw DdsError("node name must be 1-256 characters and the namespace at most 256: '" + ns_ + "', '" + name_ + "'");
  }
  const dds_entity_t topic =
      check(dds_create_topic(participant_, &rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc, "ros_discovery_info",
                             nullptr, nullptr),
            "dds_create_topic ros_discovery_info");
  const Qos qos(ros_qos(1, true));
  dds_qset_durability(qos.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
  set_endpoint_user_data(qos.get(), rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc.m_typename);
  writer_ = dds_create_writer(participant_, topic, qos.get(), nullptr);
  check(writer_, "dds_create_writer ros_discovery_info");
}

void NodeAnnouncer::announce() {
  std::vector<rmw_dds_common_msg_dds__Gid_> readers, writers;
  // Readers and writers hang below the participant's (implicit) subscribers and publishers.
  for (dds_entity_t group : children(participant_)) {
    for (dds_entity_t e : children(group)) {
      if (e == writer_) continue;
      dds_publication_matched_status_t pub;
      dds_subscription_matched_status_t sub;
      if (dds_get_publication_matched_status(e, &pub) == DDS_RETCODE_OK) {
        writers.push_back(gid_of(e));
      } else if (dds_get_subscription_matched_status(e, &sub) == DDS_RETCODE_OK) {
        readers.push_back(gid_of(e));
      }
    }
  }
  readers_ = readers.size();
  writers_ = writers.size();
  rmw_dds_common_msg_dds__NodeEntitiesInfo_ node{};
  // Bounded strings (string<256>) are inline arrays; the constructor checked the lengths.
  std::strncpy(node.node_namespace, ns_.c_str(), sizeof(node.node_namespace) - 1);
  std::strncpy(node.node_name, name_.c_str(), sizeof(node.node_name) - 1);
  const auto nr = static_cast<uint32_t>(readers.size()), nw = static_cast<uint32_t>(writers.size());
  node.reader_gid_seq = {nr, nr, readers.data(), false};
  node.writer_gid_seq = {nw, nw, writers.data(), false};
  rmw_dds_common_msg_dds__ParticipantEntitiesInfo_ info{};
  info.gid = gid_of(participant_);
  info.node_entities_info_seq = {1, 1, &node, false};
  write_now(writer_, &info, "dds_write ros_discovery_info");
}

}  // namespace quadcosim::dds
