#include "io/ros2_cdr.hpp"

#include <array>
#include <bit>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>

namespace quadcosim::io {

namespace {

// Little-endian CDR with the CDR_LE encapsulation header; alignment counts from the header's end.
class CdrWriter {
 public:
  CdrWriter() { bytes_ = {0x00, 0x01, 0x00, 0x00}; }

  void u8(std::uint8_t v) { bytes_.push_back(v); }
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
  template <std::size_t N>
  void f64s(const std::array<double, N>& a) {
    for (double v : a) f64(v);
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

void put(CdrWriter& w, const msg::Time& t) {
  w.i32(t.sec);
  w.u32(t.nanosec);
}
void put(CdrWriter& w, const msg::Header& h) {
  put(w, h.stamp);
  w.str(h.frame_id);
}
void put(CdrWriter& w, const msg::Vector3& v) {
  w.f64(v.x);
  w.f64(v.y);
  w.f64(v.z);
}
void put(CdrWriter& w, const msg::Quaternion& q) {
  w.f64(q.x);
  w.f64(q.y);
  w.f64(q.z);
  w.f64(q.w);
}

// The .msg definitions (fields only, as in the ROS 2 packages; Jazzy and Humble agree), keyed
// "pkg/Type". Field types without a package refer to the same package.
const std::map<std::string, std::string, std::less<>>& msg_files() {
  static const std::map<std::string, std::string, std::less<>> files = {
      {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
      {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
      {"std_msgs/MultiArrayDimension", "string label\nuint32 size\nuint32 stride\n"},
      {"std_msgs/MultiArrayLayout", "MultiArrayDimension[] dim\nuint32 data_offset\n"},
      {"std_msgs/Float64MultiArray", "MultiArrayLayout layout\nfloat64[] data\n"},
      {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
      {"geometry_msgs/Pose", "Point position\nQuaternion orientation\n"},
      {"geometry_msgs/PoseStamped", "std_msgs/Header header\nPose pose\n"},
      {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"},
      {"geometry_msgs/TwistStamped", "std_msgs/Header header\nTwist twist\n"},
      {"sensor_msgs/Imu",
       "std_msgs/Header header\n"
       "geometry_msgs/Quaternion orientation\n"
       "float64[9] orientation_covariance\n"
       "geometry_msgs/Vector3 angular_velocity\n"
       "float64[9] angular_velocity_covariance\n"
       "geometry_msgs/Vector3 linear_acceleration\n"
       "float64[9] linear_acceleration_covariance\n"},
      {"rosgraph_msgs/Clock", "builtin_interfaces/Time clock\n"},
      {"quadcosim_msgs/ControllerStatus",
       "std_msgs/Header header\n"
       "string mode\n"
       "float64[6] setpoint\n"
       "float64[4] u\n"
       "float64[4] error\n"
       "bool[4] rotor_saturated\n"
       "bool tilt_saturated\n"
       "bool safety\n"
       "uint64 rejected_non_finite\n"
       "uint64 rejected_bad_quaternion\n"
       "uint64 rejected_bad_stamp\n"
       "uint64 rejected_stamp_backwards\n"},
      {"quadcosim_msgs/PlantStatus",
       "std_msgs/Header header\n"
       "uint64 commands_accepted\n"
       "uint64 commands_clamped\n"
       "uint64 commands_rejected_length\n"
       "uint64 commands_rejected_non_finite\n"
       "string last_problem\n"},
  };
  return files;
}

bool is_primitive(std::string_view type) {
  static const std::set<std::string_view> primitives = {"bool",   "byte",  "char",   "float32", "float64",
                                                        "int8",   "uint8", "int16",  "uint16",  "int32",
                                                        "uint32", "int64", "uint64", "string",  "wstring"};
  return primitives.count(type) > 0;
}

// The "pkg/Type" keys of the non-primitive field types of `key`'s definition, in field order.
std::vector<std::string> dependencies(const std::string& key) {
  const std::string pkg = key.substr(0, key.find('/'));
  std::vector<std::string> deps;
  const std::string& text = msg_files().at(key);
  std::size_t line = 0;
  while (line < text.size()) {
    const std::size_t end = text.find('\n', line);
    std::string type = text.substr(line, text.find(' ', line) - line);
    line = end + 1;
    type = type.substr(0, type.find_first_of("[<"));  // T[], T[N], T[<=N], string<=N
    if (is_primitive(type)) continue;
    deps.push_back(type.find('/') == std::string::npos ? pkg + "/" + type : type);
  }
  return deps;
}

void append_dependencies(const std::string& key, std::set<std::string>& seen, std::string& out) {
  for (const std::string& dep : dependencies(key)) {
    if (!seen.insert(dep).second) continue;
    out += std::string(80, '=') + "\nMSG: " + dep + "\n" + msg_files().at(dep);
    append_dependencies(dep, seen, out);
  }
}

std::string full_definition(const std::string& key) {
  std::string out = msg_files().at(key);
  std::set<std::string> seen{key};
  append_dependencies(key, seen, out);
  return out;
}

}  // namespace

std::vector<std::uint8_t> to_cdr(const msg::PoseStamped& m) {
  CdrWriter w;
  put(w, m.header);
  put(w, m.position);
  put(w, m.orientation);
  return w.take();
}

std::vector<std::uint8_t> to_cdr(const msg::TwistStamped& m) {
  CdrWriter w;
  put(w, m.header);
  put(w, m.linear);
  put(w, m.angular);
  return w.take();
}

std::vector<std::uint8_t> to_cdr(const msg::Imu& m) {
  CdrWriter w;
  put(w, m.header);
  put(w, m.orientation);
  w.f64s(m.orientation_covariance);
  put(w, m.angular_velocity);
  w.f64s(m.angular_velocity_covariance);
  put(w, m.linear_acceleration);
  w.f64s(m.linear_acceleration_covariance);
  return w.take();
}

std::vector<std::uint8_t> to_cdr(const msg::Float64MultiArray& m) {
  CdrWriter w;
  w.u32(static_cast<std::uint32_t>(m.dim.size()));  // layout.dim
  for (const auto& d : m.dim) {
    w.str(d.label);
    w.u32(d.size);
    w.u32(d.stride);
  }
  w.u32(m.data_offset);  // layout.data_offset
  w.u32(static_cast<std::uint32_t>(m.data.size()));
  for (double v : m.data) w.f64(v);
  return w.take();
}

std::vector<std::uint8_t> to_cdr(const msg::Clock& m) {
  CdrWriter w;
  put(w, m.clock);
  return w.take();
}

std::vector<std::uint8_t> to_cdr(const msg::ControllerStatus& m) {
  CdrWriter w;
  put(w, m.header);
  w.str(m.mode);
  w.f64s(m.setpoint);
  w.f64s(m.u);
  w.f64s(m.error);
  for (bool b : m.rotor_saturated) w.boolean(b);
  w.boolean(m.tilt_saturated);
  w.boolean(m.safety);
  w.u64(m.rejected_non_finite);
  w.u64(m.rejected_bad_quaternion);
  w.u64(m.rejected_bad_stamp);
  w.u64(m.rejected_stamp_backwards);
  return w.take();
}

std::vector<std::uint8_t> to_cdr(const msg::PlantStatus& m) {
  CdrWriter w;
  put(w, m.header);
  w.u64(m.commands_accepted);
  w.u64(m.commands_clamped);
  w.u64(m.commands_rejected_length);
  w.u64(m.commands_rejected_non_finite);
  w.str(m.last_problem);
  return w.take();
}

const std::string& ros2msg_definition(std::string_view ros_type) {
  // "pkg/msg/Type" -> the full text, built once from the .msg table (immutable afterwards).
  static const std::map<std::string, std::string, std::less<>> definitions = [] {
    std::map<std::string, std::string, std::less<>> d;
    for (const auto& [key, text] : msg_files()) {
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

std::string ros2_offered_qos_profiles(std::uint32_t depth, bool reliable) {
  // RMW_DURATION_INFINITE as rosbag2 writes it.
  const std::string infinite = "\n    sec: 9223372036\n    nsec: 854775807";
  return "- history: keep_last\n  depth: " + std::to_string(depth) +
         "\n  reliability: " + (reliable ? "reliable" : "best_effort") +
         "\n  durability: volatile\n  deadline:" + infinite + "\n  lifespan:" + infinite +
         "\n  liveliness: automatic\n  liveliness_lease_duration:" + infinite +
         "\n  avoid_ros_namespace_conventions: false";
}

}  // namespace quadcosim::io
