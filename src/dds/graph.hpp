// The ROS 2 graph as DDS discovery shows it: every reader and writer on the domain, read from
// Cyclone's built-in topics (DCPSPublication / DCPSSubscription), and the name rules ROS 2 tools
// apply to them (rmw_cyclonedds demangle.cpp): DDS topic "rt/drone/Pose" is ROS topic "/drone/Pose",
// DDS type "geometry_msgs::msg::dds_::PoseStamped_" is "geometry_msgs/msg/PoseStamped", and topics
// without the "rt/" prefix (ros_discovery_info, services, plain DDS) are not ROS topics.
#pragma once

#include <dds/dds.h>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::dds {

/// One discovered reader or writer, with the names as they are on the wire.
struct Endpoint {
  std::string dds_topic;  ///< "rt/drone/Pose"
  std::string dds_type;   ///< "geometry_msgs::msg::dds_::PoseStamped_"
  bool writer = false;    ///< a writer (publisher) or a reader (subscription)
  bool reliable = true;   ///< its reliability QoS
  std::string user_data;  ///< its USER_DATA QoS as sent ("typehash=RIHS01_...;" from ROS 2 Jazzy), "" if none
  std::array<std::uint8_t, 16> participant{};  ///< the GUID of the participant it belongs to
};

/// A ROS topic with everything discovered on it.
struct RosTopic {
  std::string name;                ///< "/drone/Pose"
  std::vector<std::string> types;  ///< ROS type names, sorted, unique
  int publishers = 0;
  int subscribers = 0;
  int best_effort_publishers = 0;
};

/// "rt/drone/Pose" -> "/drone/Pose"; nullopt for a DDS topic that is not a ROS topic (no "rt/").
std::optional<std::string> ros_topic_name(std::string_view dds_topic);

/// "geometry_msgs::msg::dds_::PoseStamped_" -> "geometry_msgs/msg/PoseStamped". A name that is not
/// a mangled ROS type (no "dds_::", or no trailing '_') comes back unchanged, as in rmw_cyclonedds.
std::string demangle_ros_type(std::string_view dds_type);

/// True when a token of the name starts with '_' ("/drone/_debug"): `ros2 topic list` hides those
/// unless --include-hidden-topics.
bool is_hidden_topic(std::string_view ros_topic);

/// Groups endpoints into ROS topics: only "rt/" topics, demangled, sorted by name, one entry per
/// name with the union of the types.
std::vector<RosTopic> ros_topics(const std::vector<Endpoint>& endpoints);

/// The lines of `ros2 topic list` ("/drone/Pose") or `ros2 topic list -t`
/// ("/drone/Pose [geometry_msgs/msg/PoseStamped]"; several types are separated by ", "), each
/// ending in '\n'. Hidden topics are left out unless `include_hidden`.
std::string format_topic_list(const std::vector<RosTopic>& topics, bool with_types, bool include_hidden = false);

/// The ROS nodes with parameter services ("/attitude_controller", "/uav1/attitude_controller") in the
/// participants that write `ros_topic` ("/drone/motor_commands"), sorted: read from the DDS topics of
/// their get_parameters request readers ("rq/attitude_controller/get_parametersRequest"), so the node
/// behind a publisher is found without ros_discovery_info. Several when a process hosts several nodes.
std::vector<std::string> parameter_nodes_writing(const std::vector<Endpoint>& endpoints, std::string_view ros_topic);

/// Collects the endpoints that `participant` discovers (other participants' only, not its own) for
/// up to `wait_ns`, blocking on a waitset. Returns earlier, as soon as `done(endpoints so far)` holds,
/// when `done` is given. Endpoints that disappeared meanwhile are dropped.
std::vector<Endpoint> discover_endpoints(dds_entity_t participant, std::int64_t wait_ns,
                                         const std::function<bool(const std::vector<Endpoint>&)>& done = {});

}  // namespace quadcosim::dds
