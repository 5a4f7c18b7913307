// Betaflight's SITL packets, the Gazebo bridge's frames and the QUADX motor map, against hand-written
// bytes (IEEE 754 patterns), closed-form rotations, the standard atmosphere, and Betaflight's own mixer
// table and attitude reconstruction (sitl.c) written out here.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "model/mixer.hpp"
#include "sitl/betaflight.hpp"
#include "sitl/json_codec.hpp"

namespace quadcosim::sitl::betaflight {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Eigen::Quaterniond axis_angle(double angle_rad, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis));
}

TEST(BetaflightCodec, FdmPacketBytes) {
  FdmPacket p;
  p.timestamp_s = 1.0;
  p.gyro_rad_s = {2.0, 0, 0};
  p.pressure_Pa = -0.5;
  const auto b = encode_fdm(p);
  ASSERT_EQ(b.size(), 144u);
  // 1.0 = 0x3FF0000000000000, 2.0 = 0x4000000000000000, -0.5 = 0xBFE0000000000000, little-endian.
  const std::vector<std::uint8_t> one = {0, 0, 0, 0, 0, 0, 0xF0, 0x3F};
  const std::vector<std::uint8_t> two = {0, 0, 0, 0, 0, 0, 0x00, 0x40};
  const std::vector<std::uint8_t> minus_half = {0, 0, 0, 0, 0, 0, 0xE0, 0xBF};
  EXPECT_EQ(std::vector<std::uint8_t>(b.begin(), b.begin() + 8), one);
  EXPECT_EQ(std::vector<std::uint8_t>(b.begin() + 8, b.begin() + 16), two);
  EXPECT_EQ(std::vector<std::uint8_t>(b.begin() + 136, b.end()), minus_half);
  // The quaternion's w (1 by default) is the 8th double: bytes 56..63.
  EXPECT_EQ(std::vector<std::uint8_t>(b.begin() + 56, b.begin() + 64), one);
  const FdmPacket back = decode_fdm(b);
  EXPECT_EQ(back.timestamp_s, 1.0);
  EXPECT_EQ(back.pressure_Pa, -0.5);
  EXPECT_THROW(decode_fdm(std::span<const std::uint8_t>(b.data(), 143)), DecodeError);
}

TEST(BetaflightCodec, RcPacketBytes) {
  std::array<std::uint16_t, kRcChannels> ch{};
  ch.fill(1000);
  ch[0] = 1500;
  ch[15] = 2000;
  const auto b = encode_rc(0.5, ch);
  ASSERT_EQ(b.size(), 40u);
  const std::vector<std::uint8_t> half = {0, 0, 0, 0, 0, 0, 0xE0, 0x3F};
  EXPECT_EQ(std::vector<std::uint8_t>(b.begin(), b.begin() + 8), half);
  EXPECT_EQ(b[8], 0xDC);  // 1500 = 0x05DC
  EXPECT_EQ(b[9], 0x05);
  EXPECT_EQ(b[10], 0xE8);  // 1000 = 0x03E8
  EXPECT_EQ(b[38], 0xD0);  // 2000 = 0x07D0
  EXPECT_EQ(b[39], 0x07);
  double t = 0;
  EXPECT_EQ(decode_rc(b, &t), ch);
  EXPECT_EQ(t, 0.5);
}

TEST(BetaflightCodec, MotorPacket) {
  // 0.5f = 0x3F000000, 1.0f = 0x3F800000, 0.25f = 0x3E800000, 0 = 0.
  const std::vector<std::uint8_t> bytes = {0, 0, 0, 0x3F, 0, 0, 0x80, 0x3F, 0, 0, 0x80, 0x3E, 0, 0, 0, 0};
  const std::array<float, 4> m = decode_motors(bytes);
  EXPECT_EQ(m, (std::array<float, 4>{0.5f, 1.0f, 0.25f, 0.0f}));
  const auto again = encode_motors(m);
  EXPECT_EQ(std::vector<std::uint8_t>(again.begin(), again.end()), bytes);
  try {
    decode_motors(std::span<const std::uint8_t>(bytes.data(), 15));
    FAIL();
  } catch (const DecodeError& e) {
    EXPECT_NE(std::string(e.what()).find("15 bytes, expected 16"), std::string::npos) << e.what();
  }
}

TEST(BetaflightFrames, StandardAtmosphere) {
  EXPECT_DOUBLE_EQ(pressure_Pa(0.0), 101325.0);
  // The standard atmosphere's table value at 1000 m: 89874.6 Pa.
  EXPECT_NEAR(pressure_Pa(1000.0), 89874.6, 0.5);
}

TEST(BetaflightFrames, GazeboBridgeVectors) {
  const FdmPacket p = gazebo_fdm(0.25, {0.1, 0.2, 0.3}, {0, 0, 9.81}, Eigen::Quaterniond::Identity(), {1, 2, 3},
                                 {8.6, 47.1, 500.0}, {8.5, 47.3});
  EXPECT_EQ(p.timestamp_s, 0.25);
  EXPECT_EQ(p.gyro_rad_s, Eigen::Vector3d(0.1, -0.2, -0.3));  // FRD
  // Level at rest: -9.81 along FRD's down; Betaflight negates it to +1 g (256 counts) on its z.
  EXPECT_EQ(p.accel_m_s2, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_EQ(p.velocity_m_s, Eigen::Vector3d(1, 2, 3));  // ENU as given
  // Mirrored about the first packet's longitude 8.5 and latitude 47.3: 8.4 and 47.5.
  EXPECT_NEAR(p.position.x(), 8.4, 1e-12);
  EXPECT_NEAR(p.position.y(), 47.5, 1e-12);
  EXPECT_EQ(p.position.z(), 500.0);
  EXPECT_EQ(p.quat_wxyz, Eigen::Vector4d(1, 0, 0, 0));
}

TEST(BetaflightFrames, QuaternionConjugatedByRxPi) {
  const double c45 = std::sqrt(0.5);
  auto quat = [](const Eigen::Quaterniond& q) {
    return gazebo_fdm(0, {0, 0, 0}, {0, 0, 0}, q, {0, 0, 0}, {0, 0, 0}, {0, 0}).quat_wxyz;
  };
  // Yaw 90 deg about up: (c45, 0, 0, s45) -> (c45, 0, 0, -s45).
  EXPECT_LT((quat(axis_angle(90 * kDeg, Eigen::Vector3d::UnitZ())) - Eigen::Vector4d(c45, 0, 0, -c45)).norm(), 1e-12);
  // Roll 30 deg: (c15, s15, 0, 0) unchanged; pitch 20 deg: (c10, 0, s10, 0) -> (c10, 0, -s10, 0).
  EXPECT_LT((quat(axis_angle(30 * kDeg, Eigen::Vector3d::UnitX())) -
             Eigen::Vector4d(std::cos(15 * kDeg), std::sin(15 * kDeg), 0, 0))
                .norm(),
            1e-12);
  EXPECT_LT((quat(axis_angle(20 * kDeg, Eigen::Vector3d::UnitY())) -
             Eigen::Vector4d(std::cos(10 * kDeg), 0, -std::sin(10 * kDeg), 0))
                .norm(),
            1e-12);
}

// Betaflight's reconstruction (sitl.c, ENABLE_GAZEBO_BRIDGE): negate qy, qz, then multiply by Rz(pi/2);
// its roll (right side down positive) and pitch (nose down positive) of the result, as imu.c's
// Euler angles of a body-to-NWU quaternion.
void betaflight_roll_pitch(const Eigen::Vector4d& pkt, double& roll_rad, double& pitch_rad) {
  const double w = pkt[0], x = pkt[1], y = -pkt[2], z = -pkt[3];
  const double k = std::sqrt(0.5);
  const double aw = k * (w - z), ax = k * (x - y), ay = k * (y + x), az = k * (z + w);
  roll_rad = std::atan2(2 * (aw * ax + ay * az), 1 - 2 * (ax * ax + ay * ay));
  pitch_rad = std::asin(2 * (aw * ay - az * ax));
}

TEST(BetaflightFrames, BetaflightReadsRollAndPitchBack) {
  double roll = 0, pitch = 0;
  // Nose east, right side 25 deg down (a rotation of +25 deg about FLU x): Betaflight's roll +25 deg.
  const Eigen::Quaterniond rolled = axis_angle(25 * kDeg, Eigen::Vector3d::UnitX());
  betaflight_roll_pitch(gazebo_fdm(0, {}, {}, rolled, {}, {}, {0, 0}).quat_wxyz, roll, pitch);
  EXPECT_NEAR(roll, 25 * kDeg, 1e-12);
  EXPECT_NEAR(pitch, 0, 1e-12);
  // Nose 10 deg down (+10 deg about FLU y), heading 40 deg: Betaflight's pitch +10 deg, roll 0.
  const Eigen::Quaterniond pitched =
      axis_angle(40 * kDeg, Eigen::Vector3d::UnitZ()) * axis_angle(10 * kDeg, Eigen::Vector3d::UnitY());
  betaflight_roll_pitch(gazebo_fdm(0, {}, {}, pitched, {}, {}, {0, 0}).quat_wxyz, roll, pitch);
  EXPECT_NEAR(pitch, 10 * kDeg, 1e-12);
  EXPECT_NEAR(roll, 0, 1e-12);
}

TEST(BetaflightRc, Channels) {
  RcSticks s;
  s.roll_us = 1234.5;  // rounds away from zero
  s.pitch_us = 2500;   // clamped
  s.throttle_us = 999.6;
  s.yaw_us = std::nan("");
  s.arm = true;
  const auto ch = rc_channels(s);
  EXPECT_EQ(ch[0], 1235);
  EXPECT_EQ(ch[1], 2000);
  EXPECT_EQ(ch[2], 1000);
  EXPECT_EQ(ch[3], 1500);
  EXPECT_EQ(ch[4], 2000);
  EXPECT_EQ(ch[15], 1000);
  s.arm = false;
  EXPECT_EQ(rc_channels(s)[4], 1000);
}

// Betaflight's mixerQuadX (mixer_init.c), motors 1..4: throttle, roll, pitch, yaw factors.
constexpr double kQuadX[4][4] = {{1, -1, 1, -1}, {1, -1, -1, 1}, {1, 1, 1, 1}, {1, 1, -1, -1}};

TEST(BetaflightMotors, MapMatchesTheQuadXMixer) {
  model::VehicleParams v;
  v.layout = model::RotorLayout::kX;
  const MotorMap m = motor_map_for(v);
  EXPECT_EQ(m.channel_of_rotor, (std::array<int, 4>{3, 1, 0, 2}));
  for (int i = 0; i < 4; ++i) {
    const double* f = kQuadX[m.channel_of_rotor[i]];
    const Eigen::Vector3d r = model::rotor_position_B(v, i);  // FLU
    // A roll-right command (factor +1) raises the left motors (FLU y > 0); a nose-down pitch command
    // (+1) the rear ones (FLU x < 0); a clockwise yaw command (+1) the counter-clockwise ones (spin -1).
    EXPECT_EQ(f[1] > 0, r.y() > 0) << "rotor " << i + 1;
    EXPECT_EQ(f[2] > 0, r.x() < 0) << "rotor " << i + 1;
    EXPECT_EQ(f[3], -v.spin[i]) << "rotor " << i + 1;
  }
  // Motors 1..4 at 0.1, 0.2, 0.3, 0.4 of 12000 rad/s: rotor 1 <- motor 4, 2 <- 2, 3 <- 1, 4 <- 3.
  const Eigen::Vector4d w = omega_from_motors(m, {0.1f, 0.2f, 0.3f, 0.4f});
  EXPECT_NEAR(w[0], 4800.0, 1e-3);
  EXPECT_NEAR(w[1], 2400.0, 1e-3);
  EXPECT_NEAR(w[2], 1200.0, 1e-3);
  EXPECT_NEAR(w[3], 3600.0, 1e-3);
  // Out of range and not a number.
  EXPECT_EQ(omega_from_motors(m, {-0.5f, 1.5f, std::nanf(""), 0.0f}), Eigen::Vector4d(0, 12000, 0, 0));
}

TEST(BetaflightMotors, RefusesPlusAndOtherSpins) {
  model::VehicleParams plus;
  try {
    motor_map_for(plus);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("QUADX mixer only"), std::string::npos) << e.what();
  }
  model::VehicleParams x;
  x.layout = model::RotorLayout::kX;
  x.spin = {-1, 1, -1, 1};
  try {
    motor_map_for(x);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("spin signs [-1, 1, -1, 1]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace quadcosim::sitl::betaflight
