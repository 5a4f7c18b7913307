// The DDS wire layout (src/dds/idl/*.idl, what idlc compiles into the C types Cyclone serialises)
// against the one statement of each message's fields (sim/message_schema.hpp, from fields()): every
// message type quadcosim writes or takes that the IDL declares has the same fields, in the same order, with the
// same types, as rmw maps .msg types to IDL (float64 -> double, bool -> boolean, T[] -> sequence<T>,
// T[N] -> a field with [N], pkg/msg/Type -> pkg::msg::dds_::Type_).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "sim/message_schema.hpp"

namespace quadcosim::dds {
namespace {

const std::map<std::string, std::string> kIdlPrimitive = {
    {"double", "float64"}, {"float", "float32"}, {"boolean", "bool"},  {"octet", "byte"},    {"char", "char"},
    {"int8", "int8"},      {"uint8", "uint8"},   {"int16", "int16"},   {"uint16", "uint16"}, {"int32", "int32"},
    {"uint32", "uint32"},  {"int64", "int64"},   {"uint64", "uint64"}, {"string", "string"}};

// An IDL type as a .msg type: primitives renamed, "pkg::msg::dds_::Type_" (or a bare "Type_" of the
// same module) as "pkg/msg/Type".
std::string msg_type(const std::string& idl, const std::string& package) {
  if (auto it = kIdlPrimitive.find(idl); it != kIdlPrimitive.end()) return it->second;
  std::smatch m;
  if (std::regex_match(idl, m, std::regex(R"((\w+)::msg::dds_::(\w+)_)"))) return m[1].str() + "/msg/" + m[2].str();
  if (std::regex_match(idl, m, std::regex(R"((\w+)_)"))) return package + "/msg/" + m[1].str();
  return "?" + idl;
}

// Every struct of the IDL files: "pkg/msg/Type" -> its fields as "TYPE NAME" in .msg terms.
std::map<std::string, std::vector<std::string>> idl_structs() {
  std::map<std::string, std::vector<std::string>> out;
  for (const char* file : {"builtin_interfaces", "std_msgs", "geometry_msgs", "sensor_msgs", "rosgraph_msgs",
                           "tf2_msgs", "quadcosim_msgs"}) {
    std::ifstream in(std::string(QUADCOSIM_SOURCE_DIR) + "/src/dds/idl/" + file + ".idl");
    EXPECT_TRUE(in) << file << ".idl";
    std::stringstream text;
    for (std::string line; std::getline(in, line);) {
      const auto comment = line.find("//");
      text << (comment == std::string::npos ? line : line.substr(0, comment)) << '\n';
    }
    const std::string s = text.str();
    std::smatch module;
    if (!std::regex_search(s, module, std::regex(R"(module (\w+) \{ module msg)"))) continue;
    const std::string package = module[1];
    const std::regex struct_re(R"(struct (\w+)_ \{([^}]*)\})");
    for (auto it = std::sregex_iterator(s.begin(), s.end(), struct_re); it != std::sregex_iterator(); ++it) {
      std::vector<std::string>& fields = out[package + "/msg/" + (*it)[1].str()];
      const std::string body = (*it)[2];
      const std::regex field_re(R"((sequence<\s*([\w:]+)\s*>|[\w:]+)\s+(\w+)(\[(\d+)\])?\s*;)");
      for (auto f = std::sregex_iterator(body.begin(), body.end(), field_re); f != std::sregex_iterator(); ++f) {
        const bool sequence = (*f)[2].matched;
        std::string type = msg_type(sequence ? (*f)[2].str() : (*f)[1].str(), package);
        if (sequence) type += "[]";
        if ((*f)[4].matched) type.append("[").append((*f)[5].str()).append("]");
        fields.push_back(type + " " + (*f)[3].str());
      }
    }
  }
  return out;
}

TEST(IdlSchemaTest, TheWireLayoutIsTheMessagesFields) {
  const auto idl = idl_structs();
  // What quadcosim's nodes publish on DDS (docs/ros2.md), and every type those contain.
  std::vector<std::string> todo = {
      "geometry_msgs/msg/PoseStamped",     "geometry_msgs/msg/TwistStamped",  "sensor_msgs/msg/Imu",
      "sensor_msgs/msg/MagneticField",     "sensor_msgs/msg/FluidPressure",   "sensor_msgs/msg/NavSatFix",
      "std_msgs/msg/Float64MultiArray",    "rosgraph_msgs/msg/Clock",         "quadcosim_msgs/msg/ControllerStatus",
      "quadcosim_msgs/msg/PlantStatus",    "tf2_msgs/msg/TFMessage",          "std_msgs/msg/String",
      "quadcosim_msgs/msg/RotorSpeeds",    "quadcosim_msgs/msg/RotorThrusts", "quadcosim_msgs/msg/ThrustRates",
      "quadcosim_msgs/msg/ThrustAttitude", "quadcosim_msgs/msg/ThrustTorque", "quadcosim_msgs/msg/VelocityYaw",
      "quadcosim_msgs/msg/AccelerationYaw"};
  std::set<std::string> done;
  while (!todo.empty()) {
    const std::string name = todo.back();
    todo.pop_back();
    if (!done.insert(name).second) continue;
    const auto schema = msg::message_schemas().find(name);
    ASSERT_NE(schema, msg::message_schemas().end()) << name << " has no fields() in sim/messages.hpp";
    const auto it = idl.find(name);
    ASSERT_NE(it, idl.end()) << name << " is written on DDS but src/dds/idl declares no struct for it";
    std::vector<std::string> fields;
    for (const msg::SchemaField& f : schema->second.fields) fields.push_back(f.type + " " + f.name);
    EXPECT_EQ(it->second, fields) << name;
    todo.insert(todo.end(), schema->second.uses.begin(), schema->second.uses.end());
  }
  // Header, Time, Pose, Point, Quaternion, Twist, Vector3, NavSatStatus, MultiArrayLayout,
  // MultiArrayDimension, TransformStamped, Transform.
  EXPECT_EQ(done.size(), 31u) << "the nineteen types and the twelve they contain";
}

// A .msg file's fields as "TYPE NAME" in the terms above: comments, constants and defaults dropped,
// "pkg/Type" as "pkg/msg/Type", a bare type as the package's own (Header: std_msgs's, as rosidl has it).
std::vector<std::string> msg_file_fields(const std::string& path, const std::string& package) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  std::vector<std::string> out;
  const std::set<std::string> primitives = {"bool",   "byte",  "char",   "float32", "float64",
                                            "int8",   "uint8", "int16",  "uint16",  "int32",
                                            "uint32", "int64", "uint64", "string",  "wstring"};
  for (std::string line; std::getline(in, line);) {
    if (const auto c = line.find('#'); c != std::string::npos) line.erase(c);
    std::istringstream words(line);
    std::string type, name;
    if (!(words >> type >> name) || name.find('=') != std::string::npos) continue;  // blank or a constant
    std::smatch m;
    std::regex_match(type, m, std::regex(R"(([\w/]+)(\[\d*\])?)"));
    std::string base = m[1];
    if (primitives.count(base) == 0) {
      if (base == "Header") base = "std_msgs/Header";
      if (base.find('/') == std::string::npos) base = package + "/" + base;
      base.insert(base.find('/'), "/msg");
    }
    out.push_back(base + m[2].str() + " " + name);
  }
  return out;
}

// The ROS 2 package a ROS 2 user builds (ros2/quadcosim_msgs): one .msg file per quadcosim_msgs struct
// of the IDL, each stating the same fields in the same order with the same types, and every one in
// its CMakeLists.txt's rosidl_generate_interfaces.
TEST(IdlSchemaTest, TheRosPackagesMsgFilesAreTheIdl) {
  const std::string dir = std::string(QUADCOSIM_SOURCE_DIR) + "/ros2/quadcosim_msgs";
  std::ifstream cmake_in(dir + "/CMakeLists.txt");
  ASSERT_TRUE(cmake_in) << dir << "/CMakeLists.txt";
  const std::string cmake((std::istreambuf_iterator<char>(cmake_in)), std::istreambuf_iterator<char>());
  int types = 0;
  for (const auto& [name, idl_fields] : idl_structs()) {
    if (name.rfind("quadcosim_msgs/msg/", 0) != 0) continue;
    ++types;
    const std::string type = name.substr(name.rfind('/') + 1);
    EXPECT_EQ(msg_file_fields(dir + "/msg/" + type + ".msg", "quadcosim_msgs"), idl_fields) << type << ".msg";
    EXPECT_NE(cmake.find("\"msg/" + type + ".msg\""), std::string::npos) << type << ".msg not in CMakeLists.txt";
    // The same fields as the C++ message's fields() (sim/message_schema.hpp).
    const auto schema = msg::message_schemas().find(name);
    ASSERT_NE(schema, msg::message_schemas().end()) << name;
    std::vector<std::string> fields;
    for (const msg::SchemaField& f : schema->second.fields) fields.push_back(f.type + " " + f.name);
    EXPECT_EQ(fields, idl_fields) << name;
  }
  EXPECT_EQ(types, 9) << "ControllerStatus, PlantStatus and the seven typed commands";
}

}  // namespace
}  // namespace quadcosim::dds
