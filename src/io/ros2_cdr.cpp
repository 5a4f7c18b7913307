#include "io/ros2_cdr.hpp"

#include <array>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <tuple>
#include <type_traits>

#include "sim/message_schema.hpp"

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
std::vector<std::uint8_t> to_cdr(const msg::RotorSpeeds& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::RotorThrusts& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::ThrustRates& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::ThrustAttitude& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::ThrustTorque& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::VelocityYaw& m) { return cdr_of(m); }
std::vector<std::uint8_t> to_cdr(const msg::AccelerationYaw& m) { return cdr_of(m); }

const std::string& ros2msg_definition(std::string_view ros_type) { return msg::ros2msg_definition(ros_type); }

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
