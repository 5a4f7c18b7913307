// The ROS 2 interface descriptions behind quadcosim's type hashes (dds/type_hash.hpp): every type
// quadcosim puts on the wire and every type those reference. The message types quadcosim writes come
// from their fields() (sim/message_schema.hpp); the discovery, parameter and service types are written
// here, field by field as the .msg / .srv files of ROS 2 Jazzy (rmw_dds_common, rcl_interfaces,
// service_msgs) declare them, with nested types fully qualified; `char` is uint8 and `byte` is octet,
// as rosidl maps them. A field changed changes the hash that ROS 2 tools see: keep it equal to upstream.
#include "dds/type_hash.hpp"
#include "sim/message_schema.hpp"

namespace quadcosim::dds {

namespace {

// The types quadcosim's nodes use for discovery and parameters, which have no message struct of their
// own (their layout is src/dds/idl's): written as the .msg / .srv files of ROS 2 Jazzy declare them.
const std::vector<MessageDescription>& infrastructure_messages() {
  static const std::vector<MessageDescription> table = {
      // ros_discovery_info (Jazzy: 16-byte GIDs).
      {"rmw_dds_common/msg/Gid", "char[16] data"},
      {"rmw_dds_common/msg/NodeEntitiesInfo",
       "string<=256 node_namespace\n"
       "string<=256 node_name\n"
       "rmw_dds_common/msg/Gid[] reader_gid_seq\n"
       "rmw_dds_common/msg/Gid[] writer_gid_seq"},
      {"rmw_dds_common/msg/ParticipantEntitiesInfo",
       "rmw_dds_common/msg/Gid gid\n"
       "rmw_dds_common/msg/NodeEntitiesInfo[] node_entities_info_seq"},
      // Parameters.
      {"rcl_interfaces/msg/ParameterValue",
       "uint8 type\n"
       "bool bool_value\n"
       "int64 integer_value\n"
       "float64 double_value\n"
       "string string_value\n"
       "byte[] byte_array_value\n"
       "bool[] bool_array_value\n"
       "int64[] integer_array_value\n"
       "float64[] double_array_value\n"
       "string[] string_array_value"},
      {"rcl_interfaces/msg/Parameter",
       "string name\n"
       "rcl_interfaces/msg/ParameterValue value"},
      {"rcl_interfaces/msg/SetParametersResult",
       "bool successful\n"
       "string reason"},
      {"rcl_interfaces/msg/FloatingPointRange",
       "float64 from_value\n"
       "float64 to_value\n"
       "float64 step"},
      {"rcl_interfaces/msg/IntegerRange",
       "int64 from_value\n"
       "int64 to_value\n"
       "uint64 step"},
      {"rcl_interfaces/msg/ParameterDescriptor",
       "string name\n"
       "uint8 type\n"
       "string description\n"
       "string additional_constraints\n"
       "bool read_only\n"
       "bool dynamic_typing\n"
       "rcl_interfaces/msg/FloatingPointRange[<=1] floating_point_range\n"
       "rcl_interfaces/msg/IntegerRange[<=1] integer_range"},
      {"rcl_interfaces/msg/ListParametersResult",
       "string[] names\n"
       "string[] prefixes"},
      {"rcl_interfaces/msg/ParameterEvent",
       "builtin_interfaces/msg/Time stamp\n"
       "string node\n"
       "rcl_interfaces/msg/Parameter[] new_parameters\n"
       "rcl_interfaces/msg/Parameter[] changed_parameters\n"
       "rcl_interfaces/msg/Parameter[] deleted_parameters"},
      // What every service's event message carries (service_msgs/msg/ServiceEventInfo).
      {"service_msgs/msg/ServiceEventInfo",
       "uint8 event_type\n"
       "builtin_interfaces/msg/Time stamp\n"
       "char[16] client_gid\n"
       "int64 sequence_number"},
  };
  return table;
}

}  // namespace

const std::vector<MessageDescription>& message_descriptions() {
  static const std::vector<MessageDescription> table = [] {
    // Every message type quadcosim writes, from its one statement (sim/message_schema.hpp); constants
    // and default values are not part of the hash.
    std::vector<MessageDescription> t;
    for (const auto& [name, schema] : msg::message_schemas()) {
      std::string fields;
      for (const msg::SchemaField& f : schema.fields) fields += (fields.empty() ? "" : "\n") + f.type + " " + f.name;
      t.push_back({name, std::move(fields)});
    }
    t.insert(t.end(), infrastructure_messages().begin(), infrastructure_messages().end());
    return t;
  }();
  return table;
}

const std::vector<ServiceDescription>& service_descriptions() {
  static const std::vector<ServiceDescription> table = {
      {"rcl_interfaces/srv/GetParameters", "string[] names", "rcl_interfaces/msg/ParameterValue[] values"},
      {"rcl_interfaces/srv/GetParameterTypes", "string[] names", "uint8[] types"},
      {"rcl_interfaces/srv/SetParameters", "rcl_interfaces/msg/Parameter[] parameters",
       "rcl_interfaces/msg/SetParametersResult[] results"},
      {"rcl_interfaces/srv/SetParametersAtomically", "rcl_interfaces/msg/Parameter[] parameters",
       "rcl_interfaces/msg/SetParametersResult result"},
      {"rcl_interfaces/srv/ListParameters",
       "string[] prefixes\n"
       "uint64 depth",
       "rcl_interfaces/msg/ListParametersResult result"},
      {"rcl_interfaces/srv/DescribeParameters", "string[] names",
       "rcl_interfaces/msg/ParameterDescriptor[] descriptors"},
  };
  return table;
}

}  // namespace quadcosim::dds
