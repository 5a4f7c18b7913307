// What quadcosim says to Betaflight's SITL build (docs/sitl.md, "Betaflight"), as pure functions: its
// three UDP packets (src/platform/SIMULATOR/target/SITL/target.h: fdm_packet, rc_packet,
// servo_packet, native x86-64 little-endian layouts without padding), the state in the frames its
// Gazebo bridge (ENABLE_GAZEBO_BRIDGE 1, the default of `make TARGET=SITL`) reads, the RC channels of an
// angle-mode flight, and which motor drives which quadcosim rotor.
//
// Frames (sitl.c, sitl_gyro.h, as the Gazebo BetaflightPlugin sends them):
//   imu_angular_velocity_rpy     body rates in FRD [rad/s]: flu_to_frd(w_B)
//   imu_linear_acceleration_xyz  specific force in FRD [m/s^2] (Betaflight negates it: level reads +1 g)
//   imu_orientation_quat         w, x, y, z of q_WB (body FLU -> world ENU) conjugated by Rx(pi):
//                                (w, x, -y, -z); Betaflight undoes it and turns ENU into its NWU
//   velocity_xyz                 world ENU [m/s]
//   position_xyz                 longitude, latitude [deg], altitude [m] (its virtual GPS), each
//                                horizontal coordinate mirrored about the first packet's (the bridge
//                                undoes Gazebo's inverted spherical coordinates by mirroring again)
//   pressure                     the standard atmosphere at that altitude [Pa] (the Gazebo bridge
//                                derives it from the altitude itself; filled for the legacy bridges)
//
// Motors: Betaflight's QUADX mixer (src/main/flight/mixer_init.c, mixerQuadX) numbers them 1 rear-right,
// 2 front-right, 3 rear-left, 4 front-left; with props in (its default, yaw_motors_reversed off) 1 and 4
// turn clockwise seen from above, 2 and 3 counter-clockwise. quadcosim's 'x' layout numbers its rotors
// clockwise from the front-left with spin signs (+1, -1, +1, -1) (+1 clockwise): rotor 1 (front-left, CW)
// <- motor 4, rotor 2 (front-right, CCW) <- motor 2, rotor 3 (rear-right, CW) <- motor 1, rotor 4
// (rear-left, CCW) <- motor 3. A motor value u (servo_packet's motor_speed, 0..1) is an ESC throttle:
// omega = omega_max clamp(u, 0, 1), as PX4's outputs (px4.hpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "model/vehicle_params.hpp"
#include "sitl/motor_map.hpp"

namespace quadcosim::sitl::betaflight {

inline constexpr int kPwmRawPort = 9001;  ///< UDP, out of Betaflight: servo_packet_raw (RealFlight bridge)
inline constexpr int kMotorPort = 9002;   ///< UDP, out of Betaflight: servo_packet (motor_speed[4])
inline constexpr int kStatePort = 9003;   ///< UDP, into Betaflight: fdm_packet
inline constexpr int kRcPort = 9004;      ///< UDP, into Betaflight: rc_packet
inline constexpr int kCliPort = 5761;     ///< TCP, Betaflight's UART1 (MSP, CLI)

inline constexpr std::size_t kFdmPacketBytes = 18 * 8;     ///< 18 doubles
inline constexpr std::size_t kRcPacketBytes = 8 + 16 * 2;  ///< a double and 16 uint16
inline constexpr std::size_t kServoPacketBytes = 4 * 4;    ///< 4 floats
inline constexpr int kRcChannels = 16;

/// fdm_packet's fields, in its order.
struct FdmPacket {
  double timestamp_s = 0.0;
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Vector4d quat_wxyz = Eigen::Vector4d(1, 0, 0, 0);
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< longitude [deg], latitude [deg], altitude [m]
  double pressure_Pa = 0.0;
};

std::array<std::uint8_t, kFdmPacketBytes> encode_fdm(const FdmPacket& p);
/// The inverse (the test firmware reads with it). Throws DecodeError (json_codec.hpp) naming the size.
FdmPacket decode_fdm(std::span<const std::uint8_t> bytes);

std::array<std::uint8_t, kRcPacketBytes> encode_rc(double timestamp_s,
                                                   const std::array<std::uint16_t, kRcChannels>& ch);
/// The inverse: the channels [us]; the timestamp into `timestamp_s` when given. Throws DecodeError.
std::array<std::uint16_t, kRcChannels> decode_rc(std::span<const std::uint8_t> bytes, double* timestamp_s = nullptr);

std::array<std::uint8_t, kServoPacketBytes> encode_motors(const std::array<float, 4>& motor_speed);
/// servo_packet's motor_speed[4]. Throws DecodeError naming the size when it is not 16 bytes.
std::array<float, 4> decode_motors(std::span<const std::uint8_t> bytes);

/// The standard atmosphere's pressure at `altitude_m` [Pa], as sitl.c computes it for the Gazebo bridge:
/// 101325 (1 - 2.25577e-5 h)^5.25588.
double pressure_Pa(double altitude_m);

/// The state of a vehicle in the Gazebo bridge's frames (the table above): body rates w_B and specific
/// force f_B in FLU, attitude q_WB (FLU -> ENU), velocity v_W (ENU); its geodetic position (longitude,
/// latitude [deg], altitude [m]) and the first packet's longitude and latitude, about which the
/// horizontal position is mirrored.
FdmPacket gazebo_fdm(double timestamp_s, const Eigen::Vector3d& w_B, const Eigen::Vector3d& f_B,
                     const Eigen::Quaterniond& q_WB, const Eigen::Vector3d& v_W, const Eigen::Vector3d& lon_lat_alt,
                     const Eigen::Vector2d& first_lon_lat_deg);

/// RC channels (Betaflight's default map AETR1234: 1 roll, 2 pitch, 3 throttle, 4 yaw, 5 AUX1 ...) [us].
struct RcSticks {
  double roll_us = 1500, pitch_us = 1500, throttle_us = 1000, yaw_us = 1500;
  bool arm = false;  ///< AUX1 (channel 5) at 2000 us, else 1000 us
};
/// The 16 channels: the sticks rounded to whole microseconds and clamped to [1000, 2000], AUX1 from arm,
/// channels 6..16 at 1000 us.
std::array<std::uint16_t, kRcChannels> rc_channels(const RcSticks& s);

/// The motor map for `vehicle` (layout 'x', spin signs (+1, -1, +1, -1): see above); throws
/// std::invalid_argument naming the layout or spin signs Betaflight's QUADX cannot fly.
MotorMap motor_map_for(const model::VehicleParams& vehicle);
/// Rotor speeds [rad/s] from Betaflight's motors 1..4 (a non-finite value: 0).
Eigen::Vector4d omega_from_motors(const MotorMap& map, const std::array<float, 4>& motor_speed);

/// The CLI lines quadcosim applies before the user's (docs/sitl.md): ARM on AUX1 (1700..2100 us), ANGLE
/// mode always on (900..2100 us on AUX1), the QUADX mixer, the motor protocol PWM whose 1000..2000
/// range the SITL target turns into 0..1, no arming grace time after power-on (pwr_on_arm_grace 0) and no
/// runaway-takeoff prevention (it disarmed a hover after a stick step; docs/sitl.md).
std::vector<std::string> base_cli();

}  // namespace quadcosim::sitl::betaflight
