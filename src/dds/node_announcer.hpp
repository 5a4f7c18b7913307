// Makes a participant's node visible to `ros2 node list` / `ros2 node info`: publishes
// rmw_dds_common/ParticipantEntitiesInfo on ros_discovery_info (RELIABLE, TRANSIENT_LOCAL,
// KEEP_LAST 1), listing the node with the GIDs (DDS GUIDs) of the participant's readers and writers.
#pragma once

#include <dds/dds.h>

#include <string>

namespace quadcosim::dds {

class NodeAnnouncer {
 public:
  /// `name` like "quadrotor_plant", `ns` like "/".
  NodeAnnouncer(dds_entity_t participant, std::string name, std::string ns = "/");
  /// Publishes the current list of endpoints; call again after creating endpoints.
  void announce();
  /// Readers and writers announced by the last announce().
  std::size_t readers() const { return readers_; }
  std::size_t writers() const { return writers_; }

 private:
  dds_entity_t participant_;
  dds_entity_t writer_ = 0;
  std::string name_, ns_;
  std::size_t readers_ = 0, writers_ = 0;
};

}  // namespace quadcosim::dds
