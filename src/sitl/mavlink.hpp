// The few MAVLink 2 messages quadcosim sends to and reads from a firmware's GCS link (docs/sitl.md):
// HEARTBEAT, COMMAND_LONG, COMMAND_INT, COMMAND_ACK, SET_POSITION_TARGET_LOCAL_NED and STATUSTEXT, and the
// simulator link's HIL_SENSOR, HIL_GPS and HIL_ACTUATOR_CONTROLS (PX4's simulator interface), framed as
// MAVLink 2 (STX 0xFD, no signing) from the message definitions (common.xml): fields on the wire by
// size, largest first, extensions after; trailing zero bytes of the payload left out; the checksum
// CRC-16/MCRF4XX over the frame after STX, then over the message's CRC_EXTRA.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace quadcosim::sitl::mavlink {

inline constexpr std::uint8_t kStx = 0xFD;

/// Message ids and their CRC_EXTRA.
enum MessageId : std::uint32_t {
  kHeartbeat = 0,
  kCommandInt = 75,
  kCommandLong = 76,
  kCommandAck = 77,
  kSetPositionTargetLocalNed = 84,
  kHilActuatorControls = 93,
  kHilSensor = 107,
  kHilGps = 113,
  kStatustext = 253,
};
/// The CRC_EXTRA of a message id this file knows, or nothing.
std::optional<std::uint8_t> crc_extra(std::uint32_t msgid);

/// CRC-16/MCRF4XX (init 0xFFFF, the X.25 accumulate step) of `bytes`, continuing from `crc`.
std::uint16_t crc16(std::span<const std::uint8_t> bytes, std::uint16_t crc = 0xFFFF);

/// One frame's contents.
struct Frame {
  std::uint8_t seq = 0;
  std::uint8_t sysid = 0;
  std::uint8_t compid = 0;
  std::uint32_t msgid = 0;
  std::vector<std::uint8_t> payload;  ///< as sent (trailing zeros may be missing: read as zeros)
};

/// A whole MAVLink 2 frame for `payload` (its trailing zero bytes left out, at least one byte kept).
std::vector<std::uint8_t> encode(std::uint8_t seq, std::uint8_t sysid, std::uint8_t compid, std::uint32_t msgid,
                                 std::span<const std::uint8_t> payload);

/// Reads frames out of a byte stream: skips bytes until STX, waits for a whole frame, checks its CRC
/// (frames of unknown ids and of MAVLink 1 are skipped; a bad CRC is counted).
class Parser {
 public:
  void feed(std::span<const std::uint8_t> bytes);
  /// The next whole, checked frame of a known id, or nothing yet.
  std::optional<Frame> next();
  long long bad_crc() const { return bad_crc_; }

 private:
  std::vector<std::uint8_t> buf_;
  long long bad_crc_ = 0;
};

// Payloads (wire order), and what is read back.
std::vector<std::uint8_t> heartbeat(std::uint8_t type, std::uint8_t autopilot, std::uint8_t base_mode,
                                    std::uint32_t custom_mode, std::uint8_t system_status);
std::vector<std::uint8_t> command_long(std::uint8_t target_system, std::uint8_t target_component, std::uint16_t command,
                                       std::uint8_t confirmation, const std::array<float, 7>& params);
/// COMMAND_INT: params 1-4, x and y (a global position's latitude and longitude [degE7]), z (its
/// altitude [m]) in `frame` (0: MAV_FRAME_GLOBAL, altitude above mean sea level).
std::vector<std::uint8_t> command_int(std::uint8_t target_system, std::uint8_t target_component, std::uint16_t command,
                                      std::uint8_t frame, const std::array<float, 4>& params, std::int32_t x,
                                      std::int32_t y, float z);
/// Position target in MAV_FRAME_LOCAL_NED (1) with only x, y, z (and yaw when `use_yaw`) used.
std::vector<std::uint8_t> set_position_target_local_ned(std::uint32_t time_boot_ms, std::uint8_t target_system,
                                                        std::uint8_t target_component, float x, float y, float z,
                                                        bool use_yaw, float yaw);

/// HIL_SENSOR (107): what a simulator gives PX4's sensor drivers, body FRD. fields_updated: bits 0-2
/// acceleration, 3-5 rates, 6-8 magnetic field, 9 absolute pressure, 10 differential pressure, 11
/// pressure altitude, 12 temperature. `id` (an extension) names the sensor instance.
struct HilSensor {
  std::uint64_t time_usec = 0;
  std::array<float, 3> acc_m_s2{}, gyro_rad_s{}, mag_gauss{};
  float abs_pressure_hpa = 0, diff_pressure_hpa = 0, pressure_alt_m = 0, temperature_c = 0;
  std::uint32_t fields_updated = 0;
  std::uint8_t id = 0;
};
std::vector<std::uint8_t> hil_sensor(const HilSensor& m);
/// HIL_GPS (113): a GNSS fix. lat, lon [degE7], alt [mm above MSL], eph, epv [cm], vel [cm/s],
/// vn, ve, vd [cm/s, NED], cog [cdeg]; `id` and `yaw` [cdeg] are extensions.
struct HilGps {
  std::uint64_t time_usec = 0;
  std::int32_t lat = 0, lon = 0, alt = 0;
  std::uint16_t eph = 0, epv = 0, vel = 0;
  std::int16_t vn = 0, ve = 0, vd = 0;
  std::uint16_t cog = 0;
  std::uint8_t fix_type = 0, satellites_visible = 0, id = 0;
  std::uint16_t yaw = 0;
};
std::vector<std::uint8_t> hil_gps(const HilGps& m);
/// HIL_ACTUATOR_CONTROLS (93): the firmware's outputs (motors 0..1, others -1..1), its mode and flags.
struct HilActuatorControls {
  std::uint64_t time_usec = 0, flags = 0;
  std::array<float, 16> controls{};
  std::uint8_t mode = 0;
};
HilActuatorControls read_hil_actuator_controls(const Frame& f);

struct Heartbeat {
  std::uint8_t type = 0, autopilot = 0, base_mode = 0, system_status = 0;
  std::uint32_t custom_mode = 0;
  bool armed() const { return (base_mode & 0x80) != 0; }  ///< MAV_MODE_FLAG_SAFETY_ARMED
};
Heartbeat read_heartbeat(const Frame& f);
struct CommandAck {
  std::uint16_t command = 0;
  std::uint8_t result = 0;  ///< MAV_RESULT: 0 accepted, 1 temporarily rejected, 2 denied, 3 unsupported, 4 failed
};
CommandAck read_command_ack(const Frame& f);
/// STATUSTEXT's severity and text (up to 50 characters).
std::pair<std::uint8_t, std::string> read_statustext(const Frame& f);

// MAV_CMD numbers used.
inline constexpr std::uint16_t kCmdNavLand = 21;
inline constexpr std::uint16_t kCmdNavTakeoff = 22;
inline constexpr std::uint16_t kCmdDoSetMode = 176;
inline constexpr std::uint16_t kCmdDoReposition = 192;
inline constexpr std::uint16_t kCmdComponentArmDisarm = 400;

}  // namespace quadcosim::sitl::mavlink
