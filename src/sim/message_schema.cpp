#include "sim/message_schema.hpp"

#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "sim/level_messages.hpp"
#include "sim/messages.hpp"
#include "sim/scene_messages.hpp"

namespace quadcosim::msg {
namespace {

using Schemas = std::map<std::string, MessageSchema, std::less<>>;

// Collects one message type's schema from its constants() and fields() lists, and (into `schemas`)
// that of every type it uses.
struct SchemaVisitor {
  Schemas& schemas;
  MessageSchema out;

  template <class M>
  static MessageSchema of(std::string name, Schemas& schemas, const M& m) {
    SchemaVisitor v{schemas, {}};
    v.out.name = std::move(name);
    if constexpr (requires { M::constants(v); }) M::constants(v);
    M::fields(m, v);
    return std::move(v.out);
  }

  template <class T>
  void field(std::string_view name, const T& value, FieldNote note = {}) {
    out.fields.push_back({type_text(value, note.ros_type), std::string(name), std::string(note.default_value)});
  }
  template <class T>
  void constant(std::string_view name, T value) {
    out.constants.push_back(type_text(value, {}) + " " + std::string(name) + "=" + std::to_string(value));
  }
  template <class F>
  void group(std::string_view name, std::string_view ros_type, F&& visit) {
    const std::string type(ros_type);
    out.fields.push_back({type, std::string(name), ""});
    out.uses.push_back(type);
    if (schemas.count(type) == 0) {
      SchemaVisitor sub{schemas, {}};
      sub.out.name = type;
      visit(sub);
      schemas[type] = std::move(sub.out);
    }
  }

  template <class T>
  std::string type_text(const T& v, std::string_view ros_type) {
    if constexpr (std::is_same_v<T, bool>) {
      return "bool";
    } else if constexpr (std::is_same_v<T, std::uint8_t>) {
      return "uint8";
    } else if constexpr (std::is_same_v<T, std::int8_t>) {
      return "int8";
    } else if constexpr (std::is_same_v<T, std::uint16_t>) {
      return "uint16";
    } else if constexpr (std::is_same_v<T, std::string>) {
      return "string";
    } else if constexpr (std::is_same_v<T, double>) {
      return "float64";
    } else if constexpr (std::is_same_v<T, std::int32_t>) {
      return "int32";
    } else if constexpr (std::is_same_v<T, std::uint32_t>) {
      return "uint32";
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {
      return "uint64";
    } else if constexpr (IsArray<T>::value) {
      return type_text(typename T::value_type{}, ros_type) + "[" + std::to_string(std::tuple_size_v<T>) + "]";
    } else if constexpr (IsVector<T>::value) {
      return type_text(typename T::value_type{}, ros_type) + "[]";
    } else {
      const std::string type(ros_type.empty() ? T::kRosType : ros_type);
      out.uses.push_back(type);
      if (schemas.count(type) == 0) schemas[type] = of(type, schemas, v);
      return type;
    }
  }
};

template <class M>
void add(Schemas& schemas) {
  schemas[std::string(M::kRosType)] = SchemaVisitor::of(std::string(M::kRosType), schemas, M{});
}

// "pkg/msg/Type" -> "pkg/Type", as .msg files and MCAP's "MSG:" lines name types.
std::string short_name(std::string_view type) {
  const auto slash = type.find('/');
  return std::string(type.substr(0, slash)) + std::string(type.substr(type.find('/', slash + 1)));
}

// A field's type as a .msg file of `package` writes it: bare within the package, "pkg/Type" across.
std::string as_written(const std::string& type, std::string_view package) {
  const auto first = type.find('/');
  if (first == std::string::npos) return type;  // a primitive
  const std::string s = short_name(type);
  return type.compare(0, first, package) == 0 ? s.substr(s.find('/') + 1) : s;
}

std::string msg_text(const MessageSchema& m) {
  const std::string_view package = std::string_view(m.name).substr(0, m.name.find('/'));
  std::string text;
  for (const std::string& c : m.constants) text += c + "\n";
  for (const SchemaField& f : m.fields) {
    text += as_written(f.type, package) + " " + f.name;
    if (!f.default_value.empty()) text += " " + f.default_value;
    text += "\n";
  }
  return text;
}

void append_uses(const MessageSchema& m, std::set<std::string>& seen, std::string& out) {
  for (const std::string& dep : m.uses) {
    if (!seen.insert(dep).second) continue;
    const MessageSchema& d = message_schemas().at(dep);
    out += std::string(80, '=') + "\nMSG: " + short_name(dep) + "\n" + msg_text(d);
    append_uses(d, seen, out);
  }
}

}  // namespace

const std::map<std::string, MessageSchema, std::less<>>& message_schemas() {
  static const Schemas schemas = [] {
    Schemas s;
    add<PoseStamped>(s);
    add<TwistStamped>(s);
    add<Imu>(s);
    add<MagneticField>(s);
    add<FluidPressure>(s);
    add<NavSatFix>(s);
    add<Float64MultiArray>(s);
    add<Clock>(s);
    add<ControllerStatus>(s);
    add<PlantStatus>(s);
    for_each_level_message([&]<class T>() { add<T>(s); });
    add<TFMessage>(s);
    add<String>(s);
    add<SceneUpdate>(s);
    return s;
  }();
  return schemas;
}

const std::string& ros2msg_definition(std::string_view ros_type) {
  static const std::map<std::string, std::string, std::less<>> definitions = [] {
    std::map<std::string, std::string, std::less<>> d;
    for (const auto& [name, m] : message_schemas()) {
      std::string text = msg_text(m);
      std::set<std::string> seen{name};
      append_uses(m, seen, text);
      d[name] = std::move(text);
    }
    return d;
  }();
  const auto it = definitions.find(ros_type);
  if (it == definitions.end()) {
    throw std::invalid_argument("ros2msg_definition: unknown ROS 2 message type '" + std::string(ros_type) + "'");
  }
  return it->second;
}

}  // namespace quadcosim::msg
