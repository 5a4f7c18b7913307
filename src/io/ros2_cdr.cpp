#include "io/ros2_cdr.hpp"

#include <array>
#include <bit>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>
#include <type_traits>

namespace quadcosim::io {

namespace {

// Little-endian CDR with the CDR_LE encapsulation header; alignment counts from the header's end.
class CdrWriter {
 public:
  CdrWriter() { bytes_ = {0x00, 0x01, 0x00, 0x00}; }

  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void i8(std::int8_t v) { bytes_.push_back(static_cast<std::uint8_t>(v)); }
  void u16(std::uint16_t v) { primitive(v); }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void u32(std::uint32_t v) { primitive(v); }
  void u64(std::uint64_t v) { primitive(v); }
  void i32(std::int32_t v) { primitive(v); }
  void f64(double v) { primitive(v); }
  void str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
  }

  std::vector<std::uint8_t> take() { return std::move(bytes_); }

 private:
  static constexpr std::size_t kHeader = 4;

  template <class T>
  void primitive(T v) {
    static_assert(std::endian::native == std::endian::little, "CDR_LE writer assumes a little-endian host");
    while ((bytes_.size() - kHeader) % sizeof(T) != 0) bytes_.push_back(0);
    const auto at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &v, sizeof(T));
  }

  std::vector<std::uint8_t> bytes_;
};

using msg::IsArray;
using msg::IsVector;

// Writes the fields of a message in the order its fields() lists them (sim/messages.hpp).
struct CdrFields {
  CdrWriter& w;

  template <class T>
  void field(std::string_view /*name*/, const T& v, msg::FieldNote = {}) {
    put(v);
  }
  template <class F>
  void group(std::string_view /*name*/, std::string_view /*ros_type*/, F&& visit) {
    visit(*this);
  }

  template <class T>
  void put(const T& v) {
    if constexpr (std::is_same_v<T, bool>) {
      w.boolean(v);
    } else if constexpr (std::is_same_v<T, std::uint8_t>) {
      w.u8(v);
    } else if constexpr (std::is_same_v<T, std::int8_t>) {
      w.i8(v);
    } else if constexpr (std::is_same_v<T, std::uint16_t>) {
      w.u16(v);
    } else if constexpr (std::is_same_v<T, std::string>) {
      w.str(v);
    } else if constexpr (std::is_same_v<T, double>) {
      w.f64(v);
    } else if constexpr (std::is_same_v<T, std::int32_t>) {
      w.i32(v);
    } else if constexpr (std::is_same_v<T, std::uint32_t>) {
      w.u32(v);
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {
      w.u64(v);
    } else if constexpr (IsArray<T>::value) {
      for (const auto& e : v) put(e);  // fixed array: the elements only
    } else if constexpr (IsVector<T>::value) {
      w.u32(static_cast<std::uint32_t>(v.size()));  // sequence: count, then the elements
      for (const auto& e : v) put(e);
    } else {
      T::fields(v, *this);  // a nested message
    }
  }
};

template <class M>
std::vector<std::uint8_t> cdr_of(const M& m) {
  CdrWriter w;
  CdrFields f{w};
  M::fields(m, f);
  return w.take();
}

// "pkg/msg/Type" -> "pkg/Type", as .msg files and MCAP's "MSG:" lines name types.
std::string short_name(std::string_view ros_type) {
  const auto slash = ros_type.find('/');
  return std::string(ros_type.substr(0, slash)) + std::string(ros_type.substr(ros_type.find('/', slash + 1)));
}
std::string package_of(std::string_view name) { return std::string(name.substr(0, name.find('/'))); }

// One .msg definition: its field lines and the types it uses, in field order.
struct MsgType {
  std::string text;
  std::vector<std::string> deps;  ///< "pkg/Type" of each non-primitive field type, in order
};
using MsgTypes = std::map<std::string, MsgType, std::less<>>;

// Builds a message's .msg text from its fields() list, and (into `types`) that of every type it uses.
struct MsgFields {
  std::string name;  ///< "pkg/Type" being written
  MsgTypes& types;
  MsgType out;

  /// The .msg text of message `m`'s type, named `type_name`: its constants (when it declares any),
  /// then its fields.
  template <class M>
  static MsgType of(const std::string& type_name, MsgTypes& types, const M& m) {
    MsgFields f{type_name, types, {}};
    if constexpr (requires { M::constants(f); }) M::constants(f);
    M::fields(m, f);
    return f.out;
  }

  template <class T>
  void field(std::string_view field_name, const T& v, msg::FieldNote note = {}) {
    out.text += type_text(v, note.ros_type) + " " + std::string(field_name);
    if (!note.default_value.empty()) out.text += " " + std::string(note.default_value);
    out.text += "\n";
  }
  // "TYPE NAME=VALUE", as a .msg file declares a constant.
  template <class T>
  void constant(std::string_view constant_name, T value) {
    out.text += type_text(value, {}) + " " + std::string(constant_name) + "=" + std::to_string(value) + "\n";
  }
  template <class F>
  void group(std::string_view field_name, std::string_view ros_type, F&& visit) {
    const std::string dep = short_name(ros_type);
    out.text += local(dep) + " " + std::string(field_name) + "\n";
    out.deps.push_back(dep);
    if (types.count(dep) == 0) {
      MsgFields sub{dep, types, {}};
      visit(sub);
      types[dep] = sub.out;
    }
  }

  // A type as a field of `name` names it: bare within the same package, "pkg/Type" across packages.
  std::string local(const std::string& dep) const {
    return package_of(dep) == package_of(name) ? dep.substr(dep.find('/') + 1) : dep;
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
      const std::string dep = short_name(ros_type.empty() ? T::kRosType : ros_type);
      out.deps.push_back(dep);
      if (types.count(dep) == 0) types[dep] = of(dep, types, v);
      return local(dep);
    }
  }
};

template <class M>
void add_type(MsgTypes& types) {
  const std::string name = short_name(M::kRosType);
  types[name] = MsgFields::of(name, types, M{});
}

// Every .msg definition the recorded message types need, keyed "pkg/Type".
const MsgTypes& msg_types() {
  static const MsgTypes types = [] {
    MsgTypes t;
    add_type<msg::PoseStamped>(t);
    add_type<msg::TwistStamped>(t);
    add_type<msg::Imu>(t);
    add_type<msg::MagneticField>(t);
    add_type<msg::FluidPressure>(t);
    add_type<msg::NavSatFix>(t);
    add_type<msg::Float64MultiArray>(t);
    add_type<msg::Clock>(t);
    add_type<msg::ControllerStatus>(t);
    add_type<msg::PlantStatus>(t);
    add_type<msg::TFMessage>(t);
    add_type<msg::String>(t);
    add_type<msg::SceneUpdate>(t);
    return t;
  }();
  return types;
}

void append_dependencies(const std::string& key, std::set<std::string>& seen, std::string& out) {
  for (const std::string& dep : msg_types().at(key).deps) {
    if (!seen.insert(dep).second) continue;
    out += std::string(80, '=') + "\nMSG: " + dep + "\n" + msg_types().at(dep).text;
    append_dependencies(dep, seen, out);
  }
}

std::string full_definition(const std::string& key) {
  std::string out = msg_types().at(key).text;
  std::set<std::string> seen{key};
  append_dependencies(key, seen, out);
  return out;
}

}  // namespace

std::vector<std::uint8_t> to_cdr(const msg::PoseStamped& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::TwistStamped& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::Imu& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::MagneticField& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::FluidPressure& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::NavSatFix& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::Float64MultiArray& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::Clock& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::ControllerStatus& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::PlantStatus& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::TFMessage& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::String& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::SceneUpdate& m) { return cdr_of(m); }

const std::string& ros2msg_definition(std::string_view ros_type) {
  // "pkg/msg/Type" -> the full text, built once from the .msg table (immutable afterwards).
  static const std::map<std::string, std::string, std::less<>> definitions = [] {
    std::map<std::string, std::string, std::less<>> d;
    for (const auto& [key, type] : msg_types()) {
      const auto slash = key.find('/');
      d[key.substr(0, slash) + "/msg" + key.substr(slash)] = full_definition(key);
    }
    return d;
  }();
  const auto it = definitions.find(ros_type);
  if (it == definitions.end()) {
    throw std::invalid_argument("ros2msg_definition: unknown ROS 2 message type '" + std::string(ros_type) + "'");
  }
  return it->second;
}

std::string ros2_offered_qos_profiles(std::uint32_t depth, bool reliable, bool transient_local) {
  // RMW_DURATION_INFINITE as rosbag2 writes it.
  const std::string infinite = "\n    sec: 9223372036\n    nsec: 854775807";
  return "- history: keep_last\n  depth: " + std::to_string(depth) +
         "\n  reliability: " + (reliable ? "reliable" : "best_effort") +
         "\n  durability: " + (transient_local ? "transient_local" : "volatile") + "\n  deadline:" + infinite +
         "\n  lifespan:" + infinite + "\n  liveliness: automatic\n  liveliness_lease_duration:" + infinite +
         "\n  avoid_ros_namespace_conventions: false";
}

}  // namespace quadcosim::io
