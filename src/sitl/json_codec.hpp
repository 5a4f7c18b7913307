// ArduPilot's JSON physics protocol (its SITL "--model JSON"), both directions, as bytes and text
// only: no sockets here.
//
// The firmware sends a servo packet as one UDP datagram per physics frame, little-endian:
//   uint16 magic (18458: 16 channels, 29569: 32 channels), uint16 frame_rate [Hz],
//   uint32 frame_count, uint16 pwm[16 or 32] [us]                       (40 or 72 bytes)
// and waits for the physics' answer: one line of JSON, "\n{...}\n", holding the state at the end of
// the frame. The firmware's parser is not a JSON parser: it finds each key by text and reads its
// value with sscanf/atof, so the reply is written compactly ("key":value, vectors as [x,y,z]) and the
// flag no_time_sync as the integer 1 (it reads flags with strtoull, so `true` would read as 0).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::sitl {

inline constexpr std::uint16_t kMagic16 = 18458;  ///< servo packet with 16 channels
inline constexpr std::uint16_t kMagic32 = 29569;  ///< servo packet with 32 channels
inline constexpr std::size_t kServoPacket16Bytes = 8 + 2 * 16;
inline constexpr std::size_t kServoPacket32Bytes = 8 + 2 * 32;

/// A packet that is not a servo packet: the message says what was wrong (size, magic).
class DecodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One servo packet from the firmware.
struct ServoPacket {
  std::uint16_t frame_rate_hz = 0;    ///< the firmware's physics rate [Hz]
  std::uint32_t frame_count = 0;      ///< frames the firmware has completed (the answers it received)
  std::vector<std::uint16_t> pwm_us;  ///< 16 or 32 channels [us]; 0 for a channel with no output
};

/// Decodes one datagram. Throws DecodeError naming the size and magic found when it is not a 16- or
/// 32-channel servo packet (a size that does not match its magic is refused too).
ServoPacket decode_servo_packet(std::span<const std::uint8_t> bytes);
/// The same into `packet` (its channel vector reused: no allocation once it has its size). On a
/// DecodeError `packet` is left as it was.
void decode_servo_packet(std::span<const std::uint8_t> bytes, ServoPacket& packet);

/// Encodes a servo packet (what the firmware sends; the test firmware uses it). 16 or 32 channels.
std::vector<std::uint8_t> encode_servo_packet(const ServoPacket& packet);

/// The state the physics reports at the end of a frame, in ArduPilot's frames.
struct FdmState {
  double timestamp_s = 0.0;                                       ///< simulated time [s], strictly rising
  Eigen::Vector3d gyro_FRD = Eigen::Vector3d::Zero();             ///< body rates [rad/s]
  Eigen::Vector3d accel_FRD = Eigen::Vector3d::Zero();            ///< specific force (a - g) [m/s^2]
  Eigen::Vector3d p_NED = Eigen::Vector3d::Zero();                ///< position relative to home [m]
  Eigen::Vector3d v_NED = Eigen::Vector3d::Zero();                ///< velocity [m/s]
  Eigen::Quaterniond q_NED_FRD = Eigen::Quaterniond::Identity();  ///< attitude body -> earth
};

/// The timestamp sent with the state at simulated time t_s: t_s stretched by kTimestampStretch.
/// ArduPilot advances its clock (whole microseconds, uint64_t) by the difference of two timestamps,
/// `time_now_us += deltat * 1.0e6`, which truncates: the difference of two rounded multiples of the
/// period comes out a hair under the period about half the time, so its clock lost a microsecond now
/// and then and its 400 Hz loop, finding its next sample not yet due, waited a whole frame more
/// ("Main loop slow" at one frame per loop). Stretched, each difference is above the period by far
/// more than the rounding (up to t of about 10^5 s), so with a period of whole microseconds its clock
/// moves by exactly the period every frame. The stretch never accumulates in its clock (each frame's
/// fraction of a microsecond is dropped); the state's own time is t_s.
inline constexpr double kTimestampStretch = 1e-7;
inline double fdm_timestamp_s(double t_s) { return t_s * (1.0 + kTimestampStretch); }

/// The reply line: "\n{...}\n" with timestamp, imu.gyro, imu.accel_body, position, velocity,
/// quaternion [w, x, y, z] and no_time_sync 1 (the firmware then never sleeps to hold real time).
/// Numbers are written to round-trip (the same state, the same bytes), as nlohmann::json writes them.
std::string encode_fdm_json(const FdmState& state);
/// The same line written into `line` (cleared first): no allocation once it has grown (one a frame).
void encode_fdm_json(const FdmState& state, std::string& line);

/// Reads a reply line back (the test firmware's side). Throws DecodeError naming a missing or
/// malformed key.
FdmState decode_fdm_json(std::string_view text);

}  // namespace quadcosim::sitl
