// The QoS each topic is offered and asked with: one table, for the DDS endpoints whose host states no
// QoS of its own where it advertises or subscribes (sim::QosChoice, sim/transport.hpp;
// dds/dds_transport.hpp) and the `offered_qos_profiles` recordings state for each channel
// (io/mcap_recorder.hpp).
#pragma once

#include <string>

namespace quadcosim::sim {

struct TopicQos {
  int depth = 10;                ///< KEEP_LAST depth
  bool reliable = true;          ///< RELIABLE (ROS default) or BEST_EFFORT (ROS sensor data)
  bool transient_local = false;  ///< TRANSIENT_LOCAL (late joiners get the last `depth`) or VOLATILE
  static TopicQos ros_default() { return {10, true, false}; }
  static TopicQos sensor_data() { return {5, false, false}; }
  /// What ROS 2 uses for `ros_topic` unless told otherwise: tf2's for /tf (reliable, volatile, depth
  /// 100: tf2_ros::DynamicBroadcasterQoS and DynamicListenerQoS) and /tf_static (reliable, transient
  /// local, depth 1: StaticBroadcasterQoS), robot_state_publisher's for any `.../robot_description`
  /// (reliable, transient local, depth 1), the ROS default for every other topic.
  static TopicQos for_topic(const std::string& ros_topic) {
    static const std::string kDescription = "/robot_description";
    if (ros_topic == "/tf") return {100, true, false};
    if (ros_topic == "/tf_static") return {1, true, true};
    if (ros_topic.size() >= kDescription.size() &&
        ros_topic.compare(ros_topic.size() - kDescription.size(), kDescription.size(), kDescription) == 0) {
      return {1, true, true};
    }
    return ros_default();
  }
};

}  // namespace quadcosim::sim
