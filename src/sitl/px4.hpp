// What quadcosim says to PX4's SITL build over its simulator interface (docs/sitl.md, "PX4"), as pure
// functions: the HIL_SENSOR and HIL_GPS messages made from an Observation and its extra sensors, in
// PX4's frames and units (body FRD; field [gauss], pressure [hPa], temperature [degC]; latitude and
// longitude [degE7], altitude [mm], accuracies [cm], velocities [cm/s] NED), the rotor speeds of a
// HIL_ACTUATOR_CONTROLS, PX4's mode numbers, and the parameters that describe the vehicle to it.
//
// Motors: PX4's airframe 10016 (quad X) numbers its outputs 1 front-right CCW, 2 back-left CCW,
// 3 front-left CW, 4 back-right CW; quadcosim's rotors (clockwise from the nose or the front-left,
// spin signs +1, -1, +1, -1: 1 and 3 clockwise) take the same outputs as from ArduPilot's quad:
// rotor 1 <- output 3, 2 <- 1, 3 <- 4, 4 <- 2 (motor_map.hpp). A control u in [0, 1] is an ESC
// throttle: omega = omega_max u, so thrust grows as u^2, which PX4's THR_MDL_FAC = 1 inverts exactly.
// quadcosim writes the vehicle's own rotor positions and moment ratio into CA_ROTORi_* (the '+' and
// the 'x' layout alike) and its hover thrust into MPC_THR_HOVER.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "control/controller.hpp"
#include "model/vehicle_params.hpp"
#include "sitl/mavlink.hpp"
#include "sitl/motor_map.hpp"

namespace quadcosim::sitl::px4 {

/// PX4's main mode and AUTO sub mode of a mode name (lower case), as MAV_CMD_DO_SET_MODE takes them
/// (param2, param3) and HEARTBEAT's custom_mode shows them (main << 16 | sub << 24).
struct ModeNumbers {
  int main = 0;
  int sub = 0;  ///< 0: not an AUTO sub mode
};
std::optional<ModeNumbers> mode_numbers(const std::string& name);
/// The names mode_numbers knows, for messages.
const char* mode_names();

/// HIL_SENSOR's fields_updated groups (PX4 takes a group only when all its bits are set).
inline constexpr std::uint32_t kAccel = 0x7, kGyro = 0x38, kMag = 0x1C0, kBaro = 0x1A00;  // baro: 9, 11, 12

/// The HIL_SENSOR of a step: the IMU of `obs` (specific force, rates) always; the magnetometer's and the
/// barometer's newest samples when `mag` / `baro` (new ones arrived). Body FLU -> FRD; tesla ->
/// gauss; Pa -> hPa; pressure altitude [m]; temperature the standard atmosphere's at that altitude.
mavlink::HilSensor hil_sensor(const control::Observation& obs, std::uint64_t time_usec, bool mag, bool baro);

/// The HIL_GPS of a GNSS sample: fix_type 3 and 10 satellites with a fix, else fix_type 1 (none) and
/// zeros. eph / epv: the sample's horizontal / vertical standard deviation [cm], at least 1 cm.
/// Velocity ENU -> NED [cm/s]; cog [cdeg] 0..35999, 65535 below 1 cm/s. time_usec: `utc_usec`.
mavlink::HilGps hil_gps(const sensors::GnssSample& s, std::uint64_t utc_usec);

/// The simulated UTC time [us since 1970] at simulated time t_s: 2026-01-01T00:00:00Z + t_s (a fixed
/// date: the same numbers on every run).
std::uint64_t utc_usec(double t_s);

/// Rotor speeds [rad/s] from a HIL_ACTUATOR_CONTROLS' controls (0..1, outputs as `map` assigns them).
Eigen::Vector4d omega_from_controls(const MotorMap& map, const std::array<float, 16>& controls);

/// The parameters that describe `vehicle` to PX4 (name, value as text), in order: CA_ROTOR_COUNT,
/// CA_ROTORi_PX/PY/PZ (FRD [m]) and KM (k_m / k_t, + for a rotor turning counter-clockwise seen from
/// above) for outputs 1..4, THR_MDL_FAC 1, MPC_THR_HOVER (the hover thrust fraction m g / (4 k_t
/// omega_max^2), clamped to PX4's range 0.1..0.8).
std::vector<std::pair<std::string, std::string>> vehicle_params(const model::VehicleParams& vehicle,
                                                                const MotorMap& map);

/// A parameter file's NAME VALUE lines ('#' comments, blank lines, commas or spaces between): throws
/// std::invalid_argument naming the file and line of one that is not so.
std::vector<std::pair<std::string, std::string>> read_param_file(const std::string& path);

}  // namespace quadcosim::sitl::px4
