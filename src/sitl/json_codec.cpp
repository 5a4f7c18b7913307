#include "sitl/json_codec.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include <nlohmann/json.hpp>

namespace quadcosim::sitl {

namespace {

std::uint16_t u16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}

std::uint32_t u32(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
         (static_cast<std::uint32_t>(b[at + 2]) << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}

void put16(std::vector<std::uint8_t>& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v & 0xff));
  b.push_back(static_cast<std::uint8_t>(v >> 8));
}

// A number as nlohmann::json writes a double: "null" when not finite, else its to_chars.
void put_number(std::string& out, double x) {
  if (!std::isfinite(x)) {
    out += "null";
    return;
  }
  std::array<char, 64> buf{};
  const char* end = nlohmann::detail::to_chars(buf.data(), buf.data() + buf.size(), x);
  out.append(buf.data(), static_cast<std::size_t>(end - buf.data()));
}

void put_vec(std::string& out, const Eigen::Vector3d& v) {
  out.push_back('[');
  put_number(out, v.x());
  out.push_back(',');
  put_number(out, v.y());
  out.push_back(',');
  put_number(out, v.z());
  out.push_back(']');
}

Eigen::Vector3d read_vec(const nlohmann::json& j, const char* name) {
  if (!j.is_array() || j.size() != 3) throw DecodeError(fmt::format("JSON state: {} is not 3 numbers", name));
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    if (!j[i].is_number()) throw DecodeError(fmt::format("JSON state: {}[{}] is not a number", name, i));
    v[i] = j[i].get<double>();
  }
  return v;
}

}  // namespace

ServoPacket decode_servo_packet(std::span<const std::uint8_t> bytes) {
  ServoPacket p;
  decode_servo_packet(bytes, p);
  return p;
}

void decode_servo_packet(std::span<const std::uint8_t> bytes, ServoPacket& p) {
  if (bytes.size() < 2) {
    throw DecodeError(fmt::format("servo packet: {} bytes, expected {} (16 channels) or {} (32 channels)", bytes.size(),
                                  kServoPacket16Bytes, kServoPacket32Bytes));
  }
  const std::uint16_t magic = u16(bytes, 0);
  std::size_t channels = 0;
  if (magic == kMagic16) {
    channels = 16;
  } else if (magic == kMagic32) {
    channels = 32;
  } else {
    throw DecodeError(fmt::format("servo packet: magic {}, expected {} (16 channels) or {} (32 channels)", magic,
                                  kMagic16, kMagic32));
  }
  const std::size_t want = 8 + 2 * channels;
  if (bytes.size() != want) {
    throw DecodeError(fmt::format("servo packet: {} bytes with magic {} ({} channels), expected {}", bytes.size(),
                                  magic, channels, want));
  }
  p.frame_rate_hz = u16(bytes, 2);
  p.frame_count = u32(bytes, 4);
  p.pwm_us.resize(channels);
  for (std::size_t i = 0; i < channels; ++i) p.pwm_us[i] = u16(bytes, 8 + 2 * i);
}

std::vector<std::uint8_t> encode_servo_packet(const ServoPacket& packet) {
  if (packet.pwm_us.size() != 16 && packet.pwm_us.size() != 32) {
    throw std::invalid_argument(fmt::format("servo packet: {} channels, expected 16 or 32", packet.pwm_us.size()));
  }
  std::vector<std::uint8_t> b;
  b.reserve(8 + 2 * packet.pwm_us.size());
  put16(b, packet.pwm_us.size() == 16 ? kMagic16 : kMagic32);
  put16(b, packet.frame_rate_hz);
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>((packet.frame_count >> (8 * i)) & 0xff));
  for (std::uint16_t v : packet.pwm_us) put16(b, v);
  return b;
}

void encode_fdm_json(const FdmState& s, std::string& line) {
  // The text nlohmann::json's dump() gives for this object (keys sorted, numbers by its to_chars:
  // shortest round-trip, "1.0" for integral values, "null" for NaN and infinities), written straight
  // into the caller's buffer: no allocation once the buffer has grown.
  line.clear();
  line += "\n{\"imu\":{\"accel_body\":";
  put_vec(line, s.accel_FRD);
  line += ",\"gyro\":";
  put_vec(line, s.gyro_FRD);
  line += "},\"no_time_sync\":1,\"position\":";
  put_vec(line, s.p_NED);
  line += ",\"quaternion\":[";
  put_number(line, s.q_NED_FRD.w());
  for (const double c : {s.q_NED_FRD.x(), s.q_NED_FRD.y(), s.q_NED_FRD.z()}) {
    line.push_back(',');
    put_number(line, c);
  }
  line += "],\"timestamp\":";
  put_number(line, s.timestamp_s);
  line += ",\"velocity\":";
  put_vec(line, s.v_NED);
  line += "}\n";
}

std::string encode_fdm_json(const FdmState& s) {
  std::string line;
  encode_fdm_json(s, line);
  return line;
}

FdmState decode_fdm_json(std::string_view text) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw DecodeError(std::string("JSON state: not JSON: ") + e.what());
  }
  if (!j.is_object()) throw DecodeError("JSON state: not an object");
  for (const char* key : {"timestamp", "imu", "position", "velocity", "quaternion"}) {
    if (!j.contains(key)) throw DecodeError(fmt::format("JSON state: missing {}", key));
  }
  const nlohmann::json& imu = j["imu"];
  if (!imu.is_object() || !imu.contains("gyro") || !imu.contains("accel_body")) {
    throw DecodeError("JSON state: imu needs gyro and accel_body");
  }
  if (!j["timestamp"].is_number()) throw DecodeError("JSON state: timestamp is not a number");
  FdmState s;
  s.timestamp_s = j["timestamp"].get<double>();
  s.gyro_FRD = read_vec(imu["gyro"], "imu.gyro");
  s.accel_FRD = read_vec(imu["accel_body"], "imu.accel_body");
  s.p_NED = read_vec(j["position"], "position");
  s.v_NED = read_vec(j["velocity"], "velocity");
  const nlohmann::json& q = j["quaternion"];
  if (!q.is_array() || q.size() != 4) throw DecodeError("JSON state: quaternion is not 4 numbers");
  for (int i = 0; i < 4; ++i) {
    if (!q[i].is_number()) throw DecodeError(fmt::format("JSON state: quaternion[{}] is not a number", i));
  }
  s.q_NED_FRD = Eigen::Quaterniond(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(), q[3].get<double>());
  return s;
}

}  // namespace quadcosim::sitl
