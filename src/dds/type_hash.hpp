// ROS 2 type hashes (REP-2016, "RIHS01"): the SHA-256 of a type's description -- its fields and those
// of every type it references -- written as canonical JSON, the way rosidl computes it at build time
// (rosidl_generator_type_description). ROS 2 Jazzy's rmw puts the hash of an endpoint's type into
// the endpoint's USER_DATA as "typehash=RIHS01_<64 hex>;"; `ros2 topic info -v` shows it and the
// graph cache warns once per endpoint that has none. The descriptions of the types quadcosim puts on
// the wire are data in type_descriptions.cpp.
#pragma once

#include <dds/dds.h>

#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::dds {

/// One interface as its .msg file declares it: "pkg/msg/Name" (or "pkg/srv/Name_Request" ...) and its
/// fields, one per line, in .msg syntax with fully qualified nested types ("float64[9] covariance",
/// "string<=256 name", "builtin_interfaces/msg/Time stamp", "rcl_interfaces/msg/IntegerRange[<=1] r").
/// Constants and default values are left out: neither is part of the hash.
struct MessageDescription {
  std::string name;
  std::string fields;
};

/// One service as its .srv file declares it: "pkg/srv/Name" and the fields of its request and
/// response. The request, response and event messages and the service type itself are derived from
/// it as rosidl derives them.
struct ServiceDescription {
  const char* name;
  const char* request;
  const char* response;
};

/// The descriptions of every type quadcosim publishes, subscribes or serves, and of the types they
/// reference (type_descriptions.cpp).
const std::vector<MessageDescription>& message_descriptions();
const std::vector<ServiceDescription>& service_descriptions();

/// The canonical JSON that REP-2016 hashes for `ros_type` ("geometry_msgs/msg/PoseStamped",
/// "rcl_interfaces/srv/SetParameters_Request", "rcl_interfaces/srv/SetParameters"): the type's
/// description and those of all types it references, sorted by name, default values left out.
/// Throws std::invalid_argument naming the type when it (or a type it references) is not described.
std::string type_description_json(std::string_view ros_type);

/// "RIHS01_" and the lowercase hex SHA-256 of type_description_json(ros_type). Throws as it does.
std::string type_hash(std::string_view ros_type);

/// The USER_DATA part that Jazzy's rmw_cyclonedds appends for an endpoint of the DDS type `dds_type`
/// ("geometry_msgs::msg::dds_::PoseStamped_"): "typehash=RIHS01_<hex>;". Throws std::invalid_argument
/// naming the type when it is not described.
std::string type_hash_user_data(std::string_view dds_type);

/// Sets the USER_DATA of an endpoint's `qos` as Jazzy's rmw_cyclonedds does: `keys` (a service's
/// "serviceid=<id>;" or a client's "clientid=<id>;", empty for a topic) followed by
/// type_hash_user_data(dds_type). Throws as type_hash_user_data does.
void set_endpoint_user_data(dds_qos_t* qos, std::string_view dds_type, const std::string& keys = "");

}  // namespace quadcosim::dds
