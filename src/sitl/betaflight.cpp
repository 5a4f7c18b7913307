#include "sitl/betaflight.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "sitl/frames.hpp"
#include "sitl/json_codec.hpp"

namespace quadcosim::sitl::betaflight {

namespace {

template <class T>
void put(std::uint8_t* at, T v) {
  std::memcpy(at, &v, sizeof(T));  // x86-64: little-endian, as Betaflight's structs
}
template <class T>
T get(const std::uint8_t* at) {
  T v;
  std::memcpy(&v, at, sizeof(T));
  return v;
}

void need(std::span<const std::uint8_t> bytes, std::size_t size, const char* what) {
  if (bytes.size() != size) {
    throw DecodeError(fmt::format("a {} of {} bytes, expected {}", what, bytes.size(), size));
  }
}

}  // namespace

std::array<std::uint8_t, kFdmPacketBytes> encode_fdm(const FdmPacket& p) {
  std::array<double, 18> d{};
  d[0] = p.timestamp_s;
  for (int i = 0; i < 3; ++i) {
    d[1 + i] = p.gyro_rad_s[i];
    d[4 + i] = p.accel_m_s2[i];
    d[11 + i] = p.velocity_m_s[i];
    d[14 + i] = p.position[i];
  }
  for (int i = 0; i < 4; ++i) d[7 + i] = p.quat_wxyz[i];
  d[17] = p.pressure_Pa;
  std::array<std::uint8_t, kFdmPacketBytes> out{};
  for (std::size_t i = 0; i < d.size(); ++i) put(out.data() + 8 * i, d[i]);
  return out;
}

FdmPacket decode_fdm(std::span<const std::uint8_t> bytes) {
  need(bytes, kFdmPacketBytes, "fdm_packet");
  std::array<double, 18> d{};
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = get<double>(bytes.data() + 8 * i);
  FdmPacket p;
  p.timestamp_s = d[0];
  p.gyro_rad_s = {d[1], d[2], d[3]};
  p.accel_m_s2 = {d[4], d[5], d[6]};
  p.quat_wxyz = {d[7], d[8], d[9], d[10]};
  p.velocity_m_s = {d[11], d[12], d[13]};
  p.position = {d[14], d[15], d[16]};
  p.pressure_Pa = d[17];
  return p;
}

std::array<std::uint8_t, kRcPacketBytes> encode_rc(double timestamp_s,
                                                   const std::array<std::uint16_t, kRcChannels>& ch) {
  std::array<std::uint8_t, kRcPacketBytes> out{};
  put(out.data(), timestamp_s);
  for (int i = 0; i < kRcChannels; ++i) put(out.data() + 8 + 2 * i, ch[static_cast<std::size_t>(i)]);
  return out;
}

std::array<std::uint16_t, kRcChannels> decode_rc(std::span<const std::uint8_t> bytes, double* timestamp_s) {
  need(bytes, kRcPacketBytes, "rc_packet");
  if (timestamp_s) *timestamp_s = get<double>(bytes.data());
  std::array<std::uint16_t, kRcChannels> ch{};
  for (int i = 0; i < kRcChannels; ++i) ch[static_cast<std::size_t>(i)] = get<std::uint16_t>(bytes.data() + 8 + 2 * i);
  return ch;
}

std::array<std::uint8_t, kServoPacketBytes> encode_motors(const std::array<float, 4>& motor_speed) {
  std::array<std::uint8_t, kServoPacketBytes> out{};
  for (int i = 0; i < 4; ++i) put(out.data() + 4 * i, motor_speed[static_cast<std::size_t>(i)]);
  return out;
}

std::array<float, 4> decode_motors(std::span<const std::uint8_t> bytes) {
  need(bytes, kServoPacketBytes, "servo_packet (Betaflight's motor output, 4 floats)");
  std::array<float, 4> m{};
  for (int i = 0; i < 4; ++i) m[static_cast<std::size_t>(i)] = get<float>(bytes.data() + 4 * i);
  return m;
}

double pressure_Pa(double altitude_m) { return 101325.0 * std::pow(1.0 - 2.25577e-5 * altitude_m, 5.25588); }

FdmPacket gazebo_fdm(double timestamp_s, const Eigen::Vector3d& w_B, const Eigen::Vector3d& f_B,
                     const Eigen::Quaterniond& q_WB, const Eigen::Vector3d& v_W, const Eigen::Vector3d& lon_lat_alt,
                     const Eigen::Vector2d& first_lon_lat_deg) {
  FdmPacket p;
  p.timestamp_s = timestamp_s;
  p.gyro_rad_s = flu_to_frd(w_B);
  p.accel_m_s2 = flu_to_frd(f_B);
  // Rx(pi) q Rx(pi)^-1 as a rotation: R' = diag(1,-1,-1) R diag(1,-1,-1).
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  Eigen::Quaterniond q(Eigen::Matrix3d(flip * q_WB.normalized().toRotationMatrix() * flip));
  q.normalize();
  const Eigen::Quaterniond qn = q_WB.normalized();
  // One sign for one attitude: the same sign as q_WB's w (the conjugation keeps w).
  if ((q.w() < 0) != (qn.w() < 0)) q.coeffs() = -q.coeffs();
  p.quat_wxyz = {q.w(), q.x(), q.y(), q.z()};
  p.velocity_m_s = v_W;
  p.position = {2.0 * first_lon_lat_deg.x() - lon_lat_alt.x(), 2.0 * first_lon_lat_deg.y() - lon_lat_alt.y(),
                lon_lat_alt.z()};
  p.pressure_Pa = pressure_Pa(lon_lat_alt.z());
  return p;
}

std::array<std::uint16_t, kRcChannels> rc_channels(const RcSticks& s) {
  auto us = [](double v) {
    return static_cast<std::uint16_t>(std::lround(std::clamp(std::isfinite(v) ? v : 1500.0, 1000.0, 2000.0)));
  };
  std::array<std::uint16_t, kRcChannels> ch{};
  ch.fill(1000);
  ch[0] = us(s.roll_us);
  ch[1] = us(s.pitch_us);
  ch[2] = us(s.throttle_us);
  ch[3] = us(s.yaw_us);
  ch[4] = s.arm ? 2000 : 1000;
  return ch;
}

MotorMap motor_map_for(const model::VehicleParams& vehicle) {
  if (vehicle.rotor_count != 4 || vehicle.layout != model::RotorLayout::kX) {
    throw std::invalid_argument(
        fmt::format("vehicle layout {} with {} rotors: the Betaflight bridge flies its QUADX mixer only (layout x, "
                    "4 rotors)",
                    model::to_string(vehicle.layout), vehicle.rotor_count));
  }
  if (vehicle.spin[0] != 1 || vehicle.spin[1] != -1 || vehicle.spin[2] != 1 || vehicle.spin[3] != -1) {
    throw std::invalid_argument(
        fmt::format("vehicle spin signs [{}, {}, {}, {}]: Betaflight's QUADX with props in needs [1, -1, 1, -1] "
                    "(front-left and rear-right clockwise seen from above)",
                    vehicle.spin[0], vehicle.spin[1], vehicle.spin[2], vehicle.spin[3]));
  }
  MotorMap m;
  m.channel_of_rotor = {3, 1, 0, 2};
  m.omega_max_rad_s = vehicle.motor.omega_max_rad_s;
  m.frame_type = 1;
  return m;
}

Eigen::Vector4d omega_from_motors(const MotorMap& map, const std::array<float, 4>& motor_speed) {
  Eigen::Vector4d w;
  for (int i = 0; i < 4; ++i) {
    const float u = motor_speed[static_cast<std::size_t>(map.channel_of_rotor[i])];
    w[i] = std::isfinite(u) ? std::clamp(static_cast<double>(u), 0.0, 1.0) * map.omega_max_rad_s : 0.0;
  }
  return w;
}

std::vector<std::string> base_cli() {
  return {"mixer QUADX", "set motor_pwm_protocol = PWM",
          "set pwr_on_arm_grace = 0",  // arming is refused for 5 s after power-on otherwise
          // It takes off "controlled" only after stick deflections above 15 %, which this pilot never gives;
          // until then a large PID sum with a turn rate disarms it (seen after a stick step).
          "set runaway_takeoff_prevention = OFF",
          "aux 0 0 0 1700 2100 0 0",  // ARM (box 0) on AUX1 high
          "aux 1 1 0 900 2100 0 0"};  // ANGLE (box 1) on AUX1 over its whole range: always
}

}  // namespace quadcosim::sitl::betaflight
