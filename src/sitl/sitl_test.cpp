// The ArduPilot JSON codec, the frame changes and the motor map, against hand-computed packets and
// closed-form rotations (the numbers below are written out, not produced by the code under test).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <random>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "model/mixer.hpp"
#include "sitl/frames.hpp"
#include "sitl/json_codec.hpp"
#include "sitl/motor_map.hpp"

namespace quadcosim::sitl {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Eigen::Quaterniond axis_angle(double angle_rad, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis));
}

void expect_same_attitude(const Eigen::Quaterniond& got, double w, double x, double y, double z) {
  // q and -q are one attitude; attitude_ned_frd returns w >= 0.
  EXPECT_NEAR(got.w(), w, 1e-12);
  EXPECT_NEAR(got.x(), x, 1e-12);
  EXPECT_NEAR(got.y(), y, 1e-12);
  EXPECT_NEAR(got.z(), z, 1e-12);
}

TEST(SitlFrames, VectorsSwapAndNegate) {
  EXPECT_EQ(enu_to_ned({1, 2, 3}), Eigen::Vector3d(2, 1, -3));
  EXPECT_EQ(ned_to_enu({2, 1, -3}), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(flu_to_frd({1, 2, 3}), Eigen::Vector3d(1, -2, -3));
  EXPECT_EQ(frd_to_flu({1, -2, -3}), Eigen::Vector3d(1, 2, 3));
  // At rest the accelerometer reads +g up in FLU: ArduPilot expects -g along its down axis.
  EXPECT_EQ(flu_to_frd({0, 0, 9.81}), Eigen::Vector3d(0, 0, -9.81));
}

TEST(SitlFrames, LevelFacingEastIsYaw90InNed) {
  // Identity in quadcosim: the nose points east (ENU x). In NED that is a yaw of +90 deg about down:
  // q = (cos 45, 0, 0, sin 45).
  const double h = std::sqrt(0.5);
  expect_same_attitude(attitude_ned_frd(Eigen::Quaterniond::Identity()), h, 0, 0, h);
}

TEST(SitlFrames, FacingNorthIsIdentityInNed) {
  expect_same_attitude(attitude_ned_frd(axis_angle(90 * kDeg, Eigen::Vector3d::UnitZ())), 1, 0, 0, 0);
}

TEST(SitlFrames, RollAndPitchSigns) {
  const Eigen::Quaterniond north = axis_angle(90 * kDeg, Eigen::Vector3d::UnitZ());
  // Roll +30 deg about FLU x lifts the left side: the right side goes down, +30 deg roll in FRD.
  expect_same_attitude(attitude_ned_frd(north * axis_angle(30 * kDeg, Eigen::Vector3d::UnitX())), std::cos(15 * kDeg),
                       std::sin(15 * kDeg), 0, 0);
  // Pitch +20 deg about FLU y (left) puts the nose down: -20 deg pitch in FRD.
  expect_same_attitude(attitude_ned_frd(north * axis_angle(20 * kDeg, Eigen::Vector3d::UnitY())), std::cos(10 * kDeg),
                       0, -std::sin(10 * kDeg), 0);
  // Yaw +10 deg (counter-clockwise from above, ENU) from north is -10 deg in NED (clockwise positive).
  expect_same_attitude(attitude_ned_frd(axis_angle(100 * kDeg, Eigen::Vector3d::UnitZ())), std::cos(5 * kDeg), 0, 0,
                       -std::sin(5 * kDeg));
}

TEST(SitlFrames, BodyVectorsRotateConsistently) {
  // A vector fixed in the body maps to the same world direction through either pair of frames.
  const Eigen::Quaterniond q_WB = axis_angle(0.3, Eigen::Vector3d(1, 2, 3).normalized());
  const Eigen::Vector3d v_B(0.4, -1.1, 2.5);
  const Eigen::Vector3d via_ned = attitude_ned_frd(q_WB) * flu_to_frd(v_B);
  const Eigen::Vector3d via_enu = enu_to_ned(q_WB * v_B);
  EXPECT_LT((via_ned - via_enu).norm(), 1e-12);
}

// A 16-channel servo packet written byte by byte: magic 18458 = 0x481a, rate 400 = 0x0190,
// frame 0x01020304, channels 1100, 1200, 1300, 1400 (0x044c, 0x04b0, 0x0514, 0x0578), the rest 0.
std::vector<std::uint8_t> hand_packet() {
  const std::uint8_t head[16] = {0x1a, 0x48, 0x90, 0x01, 0x04, 0x03, 0x02, 0x01,
                                 0x4c, 0x04, 0xb0, 0x04, 0x14, 0x05, 0x78, 0x05};
  std::vector<std::uint8_t> b(40, 0);
  std::copy(std::begin(head), std::end(head), b.begin());
  return b;
}

TEST(SitlCodec, DecodesAHandWrittenPacket) {
  const ServoPacket p = decode_servo_packet(hand_packet());
  EXPECT_EQ(p.frame_rate_hz, 400);
  EXPECT_EQ(p.frame_count, 0x01020304u);
  ASSERT_EQ(p.pwm_us.size(), 16u);
  EXPECT_EQ(p.pwm_us[0], 1100);
  EXPECT_EQ(p.pwm_us[3], 1400);
  EXPECT_EQ(p.pwm_us[15], 0);
  EXPECT_EQ(encode_servo_packet(p), hand_packet());
}

TEST(SitlCodec, Decodes32Channels) {
  std::vector<std::uint8_t> b(72, 0);
  b[0] = 0x81;  // 29569 = 0x7381
  b[1] = 0x73;
  b[4] = 7;
  b[70] = 0xd0;  // channel 32: 2000 = 0x07d0
  b[71] = 0x07;
  const ServoPacket p = decode_servo_packet(b);
  EXPECT_EQ(p.frame_count, 7u);
  ASSERT_EQ(p.pwm_us.size(), 32u);
  EXPECT_EQ(p.pwm_us[31], 2000);
}

TEST(SitlCodec, RefusesWrongMagicAndSize) {
  std::vector<std::uint8_t> b = hand_packet();
  b[0] = 0x1b;
  try {
    decode_servo_packet(b);
    FAIL() << "a wrong magic was accepted";
  } catch (const DecodeError& e) {
    EXPECT_NE(std::string(e.what()).find("magic 18459"), std::string::npos) << e.what();
  }
  b = hand_packet();
  b.pop_back();
  try {
    decode_servo_packet(b);
    FAIL() << "a short packet was accepted";
  } catch (const DecodeError& e) {
    EXPECT_NE(std::string(e.what()).find("39 bytes"), std::string::npos) << e.what();
  }
  EXPECT_THROW(decode_servo_packet(std::vector<std::uint8_t>{}), DecodeError);
  EXPECT_THROW(decode_servo_packet(std::vector<std::uint8_t>(72, 0)), DecodeError);
}

FdmState sample_state() {
  FdmState s;
  s.timestamp_s = 0.0025;
  s.gyro_FRD = {0.1, -0.2, 0.3};
  s.accel_FRD = {0, 0, -9.81};
  s.p_NED = {1, 2, -3};
  s.v_NED = {0.5, 0, 0};
  return s;
}

TEST(SitlCodec, EncodesTheReplyLine) {
  EXPECT_EQ(encode_fdm_json(sample_state()),
            "\n{\"imu\":{\"accel_body\":[0.0,0.0,-9.81],\"gyro\":[0.1,-0.2,0.3]},\"no_time_sync\":1,"
            "\"position\":[1.0,2.0,-3.0],\"quaternion\":[1.0,0.0,0.0,0.0],\"timestamp\":0.0025,"
            "\"velocity\":[0.5,0.0,0.0]}\n");
}

// The line written without building a JSON object holds the bytes nlohmann::json's dump() gives for
// the same object (the reference built here as a json value), for every kind of number: integral,
// tiny, huge, negative zero, subnormal, not finite; into a reused buffer, which then stays put.
TEST(SitlCodec, ReplyLineIsTheJsonLibrarysText) {
  const auto reference = [](const FdmState& s) {
    const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
    nlohmann::json j;
    j["timestamp"] = s.timestamp_s;
    j["imu"] = {{"gyro", vec(s.gyro_FRD)}, {"accel_body", vec(s.accel_FRD)}};
    j["position"] = vec(s.p_NED);
    j["velocity"] = vec(s.v_NED);
    j["quaternion"] = nlohmann::json::array({s.q_NED_FRD.w(), s.q_NED_FRD.x(), s.q_NED_FRD.y(), s.q_NED_FRD.z()});
    j["no_time_sync"] = 1;
    return "\n" + j.dump() + "\n";
  };
  const double kinds[] = {0.0,          -0.0,     1.0,       -9.81,    0.0025, 1e-5, 1.5e-7, 123456789012345678.0,
                          1e300,        -1e-300,  4.9e-324,  0.1,      1e15,   1e16, 1e-4,   -2.5e21,
                          std::nan(""), HUGE_VAL, -HUGE_VAL, 1.0 / 3.0};
  std::string line;
  line.reserve(1024);
  const char* const buffer = line.data();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-12, 12);
  for (int trial = 0; trial < 2000; ++trial) {
    double v[16];
    for (double& x : v) {
      x = trial < 200 ? kinds[(trial + (&x - v)) % std::size(kinds)] : std::ldexp(mantissa(rng), exponent(rng) * 4);
    }
    FdmState s;
    s.timestamp_s = v[0];
    s.gyro_FRD = {v[1], v[2], v[3]};
    s.accel_FRD = {v[4], v[5], v[6]};
    s.p_NED = {v[7], v[8], v[9]};
    s.v_NED = {v[10], v[11], v[12]};
    s.q_NED_FRD = Eigen::Quaterniond(v[13], v[14], v[15], v[0]);
    encode_fdm_json(s, line);
    ASSERT_EQ(line, reference(s)) << "trial " << trial;
  }
  EXPECT_EQ(line.data(), buffer);  // no allocation in the loop
}

// ArduPilot's clock over frames, as SIM_JSON.cpp advances it: a uint64_t of microseconds to which
// `deltat * 1.0e6` is added (the sum converted back, truncating), deltat the difference of two
// timestamps. With the stretched timestamps it stands at exactly n periods after n frames, at 400,
// 800 and 1000 Hz up to 10^6 frames; with the plain ones (n * dt) it falls behind.
std::uint64_t firmware_clock_us(std::uint64_t clock_us, double last_s, double now_s) {
  return static_cast<std::uint64_t>(static_cast<double>(clock_us) + (now_s - last_s) * 1.0e6);
}

TEST(SitlCodec, TimestampsMoveTheFirmwaresClockByWholePeriods) {
  for (const int rate_hz : {400, 800, 1000}) {
    const double dt_s = 1.0 / rate_hz;
    const std::uint64_t period_us = 1'000'000 / rate_hz;
    std::uint64_t clock_us = 0, plain_us = 0;
    double last_s = 0.0, plain_last_s = 0.0;
    long long behind = 0;
    for (long long n = 1; n <= 1'000'000; ++n) {
      const double t_s = static_cast<double>(n) * dt_s;                                  // the controller's step times
      const double sent_s = std::atof(fmt::format("{}", fdm_timestamp_s(t_s)).c_str());  // as text and back
      clock_us = firmware_clock_us(clock_us, last_s, sent_s);
      last_s = sent_s;
      ASSERT_EQ(clock_us, static_cast<std::uint64_t>(n) * period_us) << rate_hz << " Hz, frame " << n;
      plain_us = firmware_clock_us(plain_us, plain_last_s, t_s);
      plain_last_s = t_s;
      if (plain_us < static_cast<std::uint64_t>(n) * period_us) ++behind;
    }
    EXPECT_GT(behind, 0) << rate_hz << " Hz: the plain timestamps kept the clock (the stretch would be moot)";
  }
}

// ArduPilot reads the line by finding each key's text and scanning the value after `key":`, vectors
// with sscanf "[%f, %f, %f]", flags with strtoull: the reply must survive exactly that.
const char* after_key(const char* json, const char* section, const char* key) {
  const char* p = std::strstr(json, section);
  if (!p) return nullptr;
  p += std::strlen(section) + 1;
  p = std::strstr(p, key);
  return p ? p + std::strlen(key) + 2 : nullptr;
}

TEST(SitlCodec, SurvivesTheFirmwaresKeyScanner) {
  const std::string line = encode_fdm_json(sample_state());
  const std::string body = line.substr(1, line.size() - 2);
  const char* j = body.c_str();
  float x = 0, y = 0, z = 0, w = 0;
  ASSERT_NE(after_key(j, "imu", "gyro"), nullptr);
  ASSERT_EQ(std::sscanf(after_key(j, "imu", "gyro"), "[%f, %f, %f]", &x, &y, &z), 3);
  EXPECT_FLOAT_EQ(y, -0.2f);
  ASSERT_EQ(std::sscanf(after_key(j, "imu", "accel_body"), "[%f, %f, %f]", &x, &y, &z), 3);
  EXPECT_FLOAT_EQ(z, -9.81f);
  double px = 0, py = 0, pz = 0;
  ASSERT_EQ(std::sscanf(after_key(j, "", "position"), "[%lf, %lf, %lf]", &px, &py, &pz), 3);
  EXPECT_EQ(pz, -3.0);
  ASSERT_EQ(std::sscanf(after_key(j, "", "quaternion"), "[%f, %f, %f, %f]", &w, &x, &y, &z), 4);
  EXPECT_EQ(w, 1.0f);
  EXPECT_EQ(std::atof(after_key(j, "", "timestamp")), 0.0025);
  EXPECT_EQ(std::strtoull(after_key(j, "", "no_time_sync"), nullptr, 10), 1u);
}

TEST(SitlCodec, ReplyReadsBack) {
  const FdmState s = decode_fdm_json(encode_fdm_json(sample_state()));
  EXPECT_EQ(s.timestamp_s, 0.0025);
  EXPECT_EQ(s.accel_FRD, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_EQ(s.p_NED, Eigen::Vector3d(1, 2, -3));
  EXPECT_THROW(decode_fdm_json("{\"timestamp\":1}"), DecodeError);
  EXPECT_THROW(decode_fdm_json("not json"), DecodeError);
}

TEST(SitlMotors, ChannelsAndSpeeds) {
  const MotorMap m = motor_map_for(model::VehicleParams{});
  EXPECT_EQ(m.frame_type, 0);
  const std::vector<std::uint16_t> pwm = {1100, 1200, 1300, 1400, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  // rotor 1 <- channel 3 (1300: 30 % of 12000 rad/s), 2 <- 1, 3 <- 4, 4 <- 2.
  const Eigen::Vector4d w = m.omega_from_pwm(pwm);
  EXPECT_DOUBLE_EQ(w[0], 3600.0);
  EXPECT_DOUBLE_EQ(w[1], 1200.0);
  EXPECT_DOUBLE_EQ(w[2], 4800.0);
  EXPECT_DOUBLE_EQ(w[3], 2400.0);
  // Below the range, above it, and a channel with no output.
  const std::vector<std::uint16_t> edge = {900, 0, 2100, 1000};
  const Eigen::Vector4d e = m.omega_from_pwm(edge);
  EXPECT_EQ(e, Eigen::Vector4d(12000.0, 0.0, 0.0, 0.0));
  // Hover of the paper's vehicle: 4830.6 rad/s is 40.26 % of 12000, PWM 1402.6 us.
  EXPECT_NEAR(m.pwm_from_omega(4830.6), 1402.55, 1e-9);
}

// ArduPilot's quad matrix, as its motor table states it: per output channel, the angle clockwise
// from the nose [deg] and the yaw factor (+1 CCW, -1 CW seen from above).
struct ApMotor {
  double angle_deg;
  int yaw_factor;
};
constexpr ApMotor kApPlus[4] = {{90, 1}, {-90, 1}, {0, -1}, {180, -1}};
constexpr ApMotor kApX[4] = {{45, 1}, {-135, 1}, {-45, -1}, {135, -1}};

void expect_layout_matches(const model::VehicleParams& v, const ApMotor (&ap)[4]) {
  const MotorMap m = motor_map_for(v);
  for (int i = 0; i < 4; ++i) {
    const ApMotor& a = ap[m.channel_of_rotor[i]];
    // The channel's arm direction in FRD (cos, sin of the angle), in FLU (cos, -sin).
    const Eigen::Vector3d dir_flu(std::cos(a.angle_deg * kDeg), -std::sin(a.angle_deg * kDeg), 0);
    const Eigen::Vector3d r = model::rotor_position_B(v, i).normalized();
    EXPECT_LT((r - dir_flu).norm(), 1e-12) << "rotor " << i + 1;
    // quadcosim's spin +1 is a clockwise rotor (reaction torque +z up): ArduPilot's CW, factor -1.
    EXPECT_EQ(a.yaw_factor, -v.spin[i]) << "rotor " << i + 1;
  }
}

TEST(SitlMotors, ChannelMapMatchesArduPilotsPlusAndX) {
  model::VehicleParams plus;
  expect_layout_matches(plus, kApPlus);
  model::VehicleParams x;
  x.layout = model::RotorLayout::kX;
  expect_layout_matches(x, kApX);
  EXPECT_EQ(motor_map_for(x).frame_type, 1);
}

TEST(SitlMotors, RefusesOtherSpins) {
  model::VehicleParams v;
  v.spin = {-1, 1, -1, 1};
  try {
    motor_map_for(v);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("spin signs [-1, 1, -1, 1]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace quadcosim::sitl
