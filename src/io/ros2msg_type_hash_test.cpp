// The type descriptions behind the ROS 2 type hashes (dds/type_descriptions.cpp, written by hand)
// against the .msg schema text that recordings carry (io/ros2_cdr.cpp, generated from each message's
// fields()): the same fields, in the same order, with the same types, for every recorded type and
// every type it references. For quadcosim_msgs this is the only second source there is.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "dds/type_hash.hpp"
#include "io/ros2_cdr.hpp"
#include "sim/messages.hpp"

namespace quadcosim::io {
namespace {

const std::set<std::string> kPrimitives = {"bool",  "byte",   "char",  "int8",   "uint8",   "int16",   "uint16",
                                           "int32", "uint32", "int64", "uint64", "float32", "float64", "string"};

// "pkg/Type" (or bare "Type" within `package`) -> "pkg/msg/Type"; primitives stay as they are.
std::string qualified(const std::string& type, const std::string& package) {
  const auto bracket = type.find('[');
  const std::string base = type.substr(0, bracket);
  const std::string suffix = bracket == std::string::npos ? "" : type.substr(bracket);
  if (kPrimitives.count(base) || base.rfind("string<=", 0) == 0) return type;
  const auto slash = base.find('/');
  if (slash == std::string::npos) return package + "/msg/" + base + suffix;
  return base.substr(0, slash) + "/msg" + base.substr(slash) + suffix;
}

// A ros2msg definition split into its sections, "pkg/msg/Type" -> "TYPE NAME" lines with nested types
// fully qualified and default values dropped (neither is part of the type hash).
std::map<std::string, std::vector<std::string>> sections(const std::string& top, const std::string& text) {
  std::map<std::string, std::vector<std::string>> out;
  std::string current = top;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line.find_first_not_of('=') == std::string::npos) continue;
    if (line.find('=') != std::string::npos) continue;  // a constant ("int8 STATUS_FIX=0"): not hashed
    if (line.rfind("MSG: ", 0) == 0) {
      const std::string name = line.substr(5);
      current = name.substr(0, name.find('/')) + "/msg" + name.substr(name.find('/'));
      out[current];
      continue;
    }
    std::istringstream words(line);
    std::string type, field;
    words >> type >> field;
    out[current].push_back(qualified(type, current.substr(0, current.find('/'))) + " " + field);
  }
  return out;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

TEST(Ros2msgTypeHashTest, TypeDescriptionsMatchTheRecordedSchemas) {
  std::map<std::string, std::string> table;
  for (const dds::MessageDescription& d : dds::message_descriptions()) table[d.name] = d.fields;
  int compared = 0;
  for (const std::string_view type :
       {msg::PoseStamped::kRosType, msg::TwistStamped::kRosType, msg::Imu::kRosType, msg::Float64MultiArray::kRosType,
        msg::Clock::kRosType, msg::ControllerStatus::kRosType, msg::PlantStatus::kRosType, msg::MagneticField::kRosType,
        msg::FluidPressure::kRosType, msg::NavSatFix::kRosType}) {
    for (const auto& [name, fields] : sections(std::string(type), ros2msg_definition(type))) {
      ASSERT_EQ(table.count(name), 1u) << name << " (in the schema of " << type << ") has no type description";
      EXPECT_EQ(lines(table[name]), fields) << name;
      ++compared;
    }
  }
  EXPECT_GE(compared, 30);  // the ten types and the ones they reference, each schema's sections
}

}  // namespace
}  // namespace quadcosim::io
