// The ROS 2 interface definition of every message type quadcosim writes or takes (sim/messages.hpp,
// sim/level_messages.hpp,
// sim/scene_messages.hpp), derived from each type's fields() list: the one statement of a message's
// fields. Recordings carry it as `ros2msg` schema text (io/ros2_cdr.hpp, MCAP), and the type
// hashes ROS 2 tools check are computed from it (dds/type_hash.hpp). The DDS wire layout in
// src/dds/idl/ is checked against it (dds/idl_schema_test.cpp).
#pragma once

#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::msg {

/// One field as a .msg file declares it.
struct SchemaField {
  std::string type;  ///< a primitive ("float64", "uint8[9]", "string[]") or "pkg/msg/Type" (+ "[]"/"[N]")
  std::string name;
  std::string default_value;  ///< "" for none
};

/// One message type: "pkg/msg/Type", its constants ("TYPE NAME=VALUE", not part of the type hash), its
/// fields in order, and the message types its fields use ("pkg/msg/Type", in field order, with repeats).
struct MessageSchema {
  std::string name;
  std::vector<std::string> constants;
  std::vector<SchemaField> fields;
  std::vector<std::string> uses;
};

/// Every message type of sim/messages.hpp and sim/scene_messages.hpp and every type they contain,
/// keyed by "pkg/msg/Type". Built once (immutable afterwards).
const std::map<std::string, MessageSchema, std::less<>>& message_schemas();

/// The full `ros2msg` schema text of a ROS 2 message type named "pkg/msg/Type": the type's constants
/// and fields, then every type it depends on, depth first in field order, each once, as a line of 80
/// '=', a line "MSG: pkg/Type" and that type's definition (the ros2msg convention of the MCAP registry
/// and rosbag2; a type of the same package is named bare, others "pkg/Type"). Throws
/// std::invalid_argument naming `ros_type` for a type message_schemas() does not hold.
const std::string& ros2msg_definition(std::string_view ros_type);

}  // namespace quadcosim::msg
