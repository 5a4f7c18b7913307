// MAVLink 2 framing against frames written by the reference implementation (pymavlink, generated from
// ardupilotmega.xml) and CRC_EXTRA values recomputed from the message definitions.
#include <gtest/gtest.h>

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
