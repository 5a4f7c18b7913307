// MAVLink 2 framing against frames written by the reference implementation (pymavlink, generated from
// ardupilotmega.xml) and CRC_EXTRA values recomputed from the message definitions.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "sitl/mavlink.hpp"

namespace quadcosim::sitl::mavlink {
namespace {

std::vector<std::uint8_t> hex(const std::string& h) {
  std::vector<std::uint8_t> b;
  for (std::size_t i = 0; i + 1 < h.size(); i += 2)
    b.push_back(static_cast<std::uint8_t>(std::stoi(h.substr(i, 2), nullptr, 16)));
  return b;
}

// Frames from pymavlink with source system 255, component 190.
const char* kHeartbeatFrame = "fd09000000ffbe0000000000000006080000035c2b";  // GCS, autopilot invalid, seq 0
const char* kArm = "fd20000001ffbe4c00000000803f000000000000000000000000000000000000000000000000900101017004";
const char* kTakeoff = "fd20000002ffbe4c000000000000000000000000000000000000000000000000000000002041160001015a4b";
const char* kTarget =
    "fd35000003ffbe540000d20400000000a040000040c0000020c10000000000000000000000000000000000000000000000000000"
    "000000000000f80d01010111cc";
const char* kAck = "fd02000004ffbe4d00009001705d";
const char* kStatus = "fd17000004ffbefd000006454b463320494d5530206973207573696e672047505396b2";

TEST(Mavlink, Crc16OfTheCheckString) {
  // CRC-16/MCRF4XX of "123456789" is 0x6F91 (the catalogue's check value).
  const std::string s = "123456789";
  EXPECT_EQ(crc16(std::vector<std::uint8_t>(s.begin(), s.end())), 0x6F91);
}

// CRC_EXTRA as the MAVLink generator defines it: the CRC of "NAME " and, for each base field in wire
// order, "type name " (and the array length as one byte), folded to 8 bits.
std::uint8_t extra_of(const std::string& name, const std::vector<std::pair<std::string, std::string>>& fields,
                      const std::vector<int>& array_len = {}) {
  std::string s = name + " ";
  std::uint16_t crc = crc16(std::vector<std::uint8_t>(s.begin(), s.end()));
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string t = fields[i].first + " ", n = fields[i].second + " ";
    crc = crc16(std::vector<std::uint8_t>(t.begin(), t.end()), crc);
    crc = crc16(std::vector<std::uint8_t>(n.begin(), n.end()), crc);
    if (i < array_len.size() && array_len[i] > 0) {
      const std::uint8_t l = static_cast<std::uint8_t>(array_len[i]);
      crc = crc16(std::vector<std::uint8_t>{l}, crc);
    }
  }
  return static_cast<std::uint8_t>((crc & 0xff) ^ (crc >> 8));
}

TEST(Mavlink, CrcExtrasFollowTheDefinitions) {
  // Fields as in common.xml, in wire order (largest type first), extensions left out.
  EXPECT_EQ(*crc_extra(kHeartbeat), extra_of("HEARTBEAT", {{"uint32_t", "custom_mode"},
                                                           {"uint8_t", "type"},
                                                           {"uint8_t", "autopilot"},
                                                           {"uint8_t", "base_mode"},
                                                           {"uint8_t", "system_status"},
                                                           {"uint8_t", "mavlink_version"}}));
  EXPECT_EQ(*crc_extra(kHeartbeat), 50);
  EXPECT_EQ(*crc_extra(kCommandLong), extra_of("COMMAND_LONG", {{"float", "param1"},
                                                                {"float", "param2"},
                                                                {"float", "param3"},
                                                                {"float", "param4"},
                                                                {"float", "param5"},
                                                                {"float", "param6"},
                                                                {"float", "param7"},
                                                                {"uint16_t", "command"},
                                                                {"uint8_t", "target_system"},
                                                                {"uint8_t", "target_component"},
                                                                {"uint8_t", "confirmation"}}));
  EXPECT_EQ(*crc_extra(kCommandInt), extra_of("COMMAND_INT", {{"float", "param1"},
                                                              {"float", "param2"},
                                                              {"float", "param3"},
                                                              {"float", "param4"},
                                                              {"int32_t", "x"},
                                                              {"int32_t", "y"},
                                                              {"float", "z"},
                                                              {"uint16_t", "command"},
                                                              {"uint8_t", "target_system"},
                                                              {"uint8_t", "target_component"},
                                                              {"uint8_t", "frame"},
                                                              {"uint8_t", "current"},
                                                              {"uint8_t", "autocontinue"}}));
  EXPECT_EQ(*crc_extra(kCommandInt), 158);
  EXPECT_EQ(*crc_extra(kCommandAck), extra_of("COMMAND_ACK", {{"uint16_t", "command"}, {"uint8_t", "result"}}));
  EXPECT_EQ(*crc_extra(kSetPositionTargetLocalNed),
            extra_of("SET_POSITION_TARGET_LOCAL_NED", {{"uint32_t", "time_boot_ms"},
                                                       {"float", "x"},
                                                       {"float", "y"},
                                                       {"float", "z"},
                                                       {"float", "vx"},
                                                       {"float", "vy"},
                                                       {"float", "vz"},
                                                       {"float", "afx"},
                                                       {"float", "afy"},
                                                       {"float", "afz"},
                                                       {"float", "yaw"},
                                                       {"float", "yaw_rate"},
                                                       {"uint16_t", "type_mask"},
                                                       {"uint8_t", "target_system"},
                                                       {"uint8_t", "target_component"},
                                                       {"uint8_t", "coordinate_frame"}}));
  EXPECT_EQ(*crc_extra(kStatustext), extra_of("STATUSTEXT", {{"uint8_t", "severity"}, {"char", "text"}}, {0, 50}));
  // PX4's simulator link (the published CRC_EXTRA values: 108, 124, 47).
  EXPECT_EQ(*crc_extra(kHilSensor), extra_of("HIL_SENSOR", {{"uint64_t", "time_usec"},
                                                            {"float", "xacc"},
                                                            {"float", "yacc"},
                                                            {"float", "zacc"},
                                                            {"float", "xgyro"},
                                                            {"float", "ygyro"},
                                                            {"float", "zgyro"},
                                                            {"float", "xmag"},
                                                            {"float", "ymag"},
                                                            {"float", "zmag"},
                                                            {"float", "abs_pressure"},
                                                            {"float", "diff_pressure"},
                                                            {"float", "pressure_alt"},
                                                            {"float", "temperature"},
                                                            {"uint32_t", "fields_updated"}}));
  EXPECT_EQ(*crc_extra(kHilSensor), 108);
  EXPECT_EQ(*crc_extra(kHilGps), extra_of("HIL_GPS", {{"uint64_t", "time_usec"},
                                                      {"int32_t", "lat"},
                                                      {"int32_t", "lon"},
                                                      {"int32_t", "alt"},
                                                      {"uint16_t", "eph"},
                                                      {"uint16_t", "epv"},
                                                      {"uint16_t", "vel"},
                                                      {"int16_t", "vn"},
                                                      {"int16_t", "ve"},
                                                      {"int16_t", "vd"},
                                                      {"uint16_t", "cog"},
                                                      {"uint8_t", "fix_type"},
                                                      {"uint8_t", "satellites_visible"}}));
  EXPECT_EQ(*crc_extra(kHilGps), 124);
  EXPECT_EQ(*crc_extra(kHilActuatorControls),
            extra_of("HIL_ACTUATOR_CONTROLS",
                     {{"uint64_t", "time_usec"}, {"uint64_t", "flags"}, {"float", "controls"}, {"uint8_t", "mode"}},
                     {0, 0, 16, 0}));
  EXPECT_EQ(*crc_extra(kHilActuatorControls), 47);
  EXPECT_FALSE(crc_extra(12345).has_value());
}

TEST(Mavlink, EncodesAsTheReferenceDoes) {
  EXPECT_EQ(encode(0, 255, 190, kHeartbeat, heartbeat(6, 8, 0, 0, 0)), hex(kHeartbeatFrame));
  EXPECT_EQ(encode(1, 255, 190, kCommandLong, command_long(1, 1, kCmdComponentArmDisarm, 0, {1, 0, 0, 0, 0, 0, 0})),
            hex(kArm));
  EXPECT_EQ(encode(2, 255, 190, kCommandLong, command_long(1, 1, kCmdNavTakeoff, 0, {0, 0, 0, 0, 0, 0, 10})),
            hex(kTakeoff));
  EXPECT_EQ(
      encode(3, 255, 190, kSetPositionTargetLocalNed, set_position_target_local_ned(1234, 1, 1, 5, -3, -10, false, 0)),
      hex(kTarget));
}

TEST(Mavlink, ParsesFramesOutOfAStream) {
  Parser p;
  std::vector<std::uint8_t> stream = {0x00, 0x13, 0x55};  // noise before the first STX
  for (const char* f : {kAck, kStatus, kHeartbeatFrame}) {
    const auto b = hex(f);
    stream.insert(stream.end(), b.begin(), b.end());
  }
  // Fed in two pieces, split inside the second frame.
  p.feed(std::span<const std::uint8_t>(stream).first(20));
  const auto ack = p.next();
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->msgid, kCommandAck);
  EXPECT_EQ(read_command_ack(*ack).command, 400);
  EXPECT_EQ(read_command_ack(*ack).result, 0);
  EXPECT_FALSE(p.next());
  p.feed(std::span<const std::uint8_t>(stream).subspan(20));
  const auto st = p.next();
  ASSERT_TRUE(st);
  EXPECT_EQ(read_statustext(*st).first, 6);
  EXPECT_EQ(read_statustext(*st).second, "EKF3 IMU0 is using GPS");
  const auto hb = p.next();
  ASSERT_TRUE(hb);
  EXPECT_EQ(read_heartbeat(*hb).type, 6);
  EXPECT_EQ(read_heartbeat(*hb).autopilot, 8);
  EXPECT_FALSE(read_heartbeat(*hb).armed());
  EXPECT_FALSE(p.next());
  EXPECT_EQ(p.bad_crc(), 0);
}

TEST(Mavlink, RefusesACorruptFrame) {
  Parser p;
  auto b = hex(kArm);
  b[12] ^= 0x01;  // a payload bit
  p.feed(b);
  EXPECT_FALSE(p.next());
  EXPECT_EQ(p.bad_crc(), 1);
}

}  // namespace
}  // namespace quadcosim::sitl::mavlink

namespace quadcosim::sitl::mavlink {
namespace {

// The simulator link's payloads at the byte offsets of the wire order (8-byte fields, then 4, 2, 1,
// extensions last), written and read against offsets counted by hand.
TEST(Mavlink, HilMessagesLieWhereTheWireOrderPutsThem) {
  HilSensor s;
  s.time_usec = 4000;
  s.acc_m_s2 = {0.5f, -0.25f, -9.75f};
  s.mag_gauss = {0.21f, 0.0f, 0.43f};
  s.abs_pressure_hpa = 1013.25f;
  s.fields_updated = 0x1BFF;
  s.id = 0;
  const std::vector<std::uint8_t> p = hil_sensor(s);
  ASSERT_EQ(p.size(), 65u);  // 8 + 13 floats + a uint32 + the extension's byte
  auto f32 = [&](std::size_t at) {
    float v;
    std::memcpy(&v, &p[at], 4);
    return v;
  };
  EXPECT_EQ(p[0], 0xA0);  // 4000 = 0x0FA0, little-endian
  EXPECT_EQ(p[1], 0x0F);
  EXPECT_EQ(f32(8), 0.5f);
  EXPECT_EQ(f32(16), -9.75f);
  EXPECT_EQ(f32(32), 0.21f);     // xmag after 3 accelerations and 3 rates
  EXPECT_EQ(f32(44), 1013.25f);  // abs_pressure
  EXPECT_EQ(p[60], 0xFF);        // fields_updated
  EXPECT_EQ(p[61], 0x1B);

  HilGps g;
  g.lat = 473977420;  // 47.397742 deg
  g.eph = 30;
  g.vn = -150;
  g.fix_type = 3;
  g.satellites_visible = 10;
  const std::vector<std::uint8_t> q = hil_gps(g);
  ASSERT_EQ(q.size(), 39u);  // 8 + 3 x 4 + 7 x 2 + 2 + the extensions' 3
  std::int32_t lat;
  std::memcpy(&lat, &q[8], 4);
  EXPECT_EQ(lat, 473977420);
  EXPECT_EQ(q[20], 30);  // eph after time, lat, lon, alt
  std::int16_t vn;
  std::memcpy(&vn, &q[26], 2);
  EXPECT_EQ(vn, -150);
  EXPECT_EQ(q[34], 3);   // fix_type
  EXPECT_EQ(q[35], 10);  // satellites_visible

  // HIL_ACTUATOR_CONTROLS as PX4 writes it, its trailing zeros cut as MAVLink 2 sends it.
  std::vector<std::uint8_t> a(81, 0);
  const std::uint64_t t = 123456789, flags = 1;
  std::memcpy(&a[0], &t, 8);
  std::memcpy(&a[8], &flags, 8);
  const float m1 = 0.5625f, m4 = 0.125f;
  std::memcpy(&a[16], &m1, 4);
  std::memcpy(&a[28], &m4, 4);
  a[80] = 129;
  Parser parser;
  parser.feed(encode(7, 1, 1, kHilActuatorControls, a));
  const auto frame = parser.next();
  ASSERT_TRUE(frame.has_value());
  const HilActuatorControls c = read_hil_actuator_controls(*frame);
  EXPECT_EQ(c.time_usec, 123456789u);
  EXPECT_EQ(c.flags, 1u);
  EXPECT_EQ(c.controls[0], 0.5625f);
  EXPECT_EQ(c.controls[3], 0.125f);
  EXPECT_EQ(c.controls[1], 0.0f);
  EXPECT_EQ(c.mode, 129);
  // Cut after the controls (mode 0 and zero controls at the end): still read, the rest as zeros.
  a[80] = 0;
  parser.feed(encode(8, 1, 1, kHilActuatorControls, a));
  const auto cut = parser.next();
  ASSERT_TRUE(cut.has_value());
  EXPECT_LT(cut->payload.size(), 81u);
  EXPECT_EQ(read_hil_actuator_controls(*cut).controls[3], 0.125f);
  EXPECT_EQ(read_hil_actuator_controls(*cut).mode, 0);
}

TEST(Mavlink, CommandIntPayloadAtItsOffsets) {
  // DO_REPOSITION to 47.3977420 N, 8.5455940 E, 498 m: params at 0..15, x 16, y 20, z 24, command 28,
  // targets 30 and 31, frame 32, current 33, autocontinue 34 (35 bytes, counted by hand).
  const std::vector<std::uint8_t> p =
      command_int(1, 1, kCmdDoReposition, 0, {-1.0f, 1.0f, 0.0f, 0.5f}, 473977420, 85455940, 498.0f);
  ASSERT_EQ(p.size(), 35u);
  float f;
  std::memcpy(&f, &p[0], 4);
  EXPECT_EQ(f, -1.0f);
  std::memcpy(&f, &p[12], 4);
  EXPECT_EQ(f, 0.5f);
  std::int32_t x, y;
  std::memcpy(&x, &p[16], 4);
  std::memcpy(&y, &p[20], 4);
  EXPECT_EQ(x, 473977420);
  EXPECT_EQ(y, 85455940);
  std::memcpy(&f, &p[24], 4);
  EXPECT_EQ(f, 498.0f);
  EXPECT_EQ(p[28], 192);
  EXPECT_EQ(p[29], 0);
  EXPECT_EQ(p[30], 1);
  EXPECT_EQ(p[31], 1);
  EXPECT_EQ(p[32], 0);
}

}  // namespace
}  // namespace quadcosim::sitl::mavlink
