// The flight controller's loops linearised about level hover, each broken at one plant input, as
// Loops for analysis/margins.hpp. docs/margins.md defines every loop and its break point.
#pragma once

#include <string>
#include <vector>

#include "analysis/margins.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::analysis {

/// When the controller samples and how late its inputs and outputs are, in plant ticks.
struct LoopTiming {
  double tick_s = 0.01;            ///< plant period [s]
  int controller_divider = 2;      ///< controller period = divider * tick
  int command_delay_ticks = 0;     ///< a command acts this many ticks after it was computed
  int imu_latency_ticks = 0;       ///< age of the attitude and body rates the controller reads
  int pose_latency_ticks = 0;      ///< age of the position
  int velocity_latency_ticks = 0;  ///< age of the linear velocity
  /// True: the loops in continuous time (no sample-and-hold, no delays), for comparison.
  bool continuous = false;
};

struct HoverLoop {
  std::string name;       ///< roll, pitch, yaw, altitude, position_x, position_y
  std::string broken_at;  ///< the signal where the loop is cut, with its unit
  Loop loop;
};

/// Empty when `plant` can hover with every rotor strictly inside [omega_min, omega_max] (the
/// linearisation point exists and the allocation is not saturated there), else why not.
std::string hover_trim_problem(const model::VehicleParams& plant);

/// The loops of the paper controller `controller` (its gains as designed for the vehicle it believes
/// it flies) on the
/// plant `plant` about level hover: roll, pitch, yaw (U2..U4), altitude (U1), and in position mode
/// also position_x and position_y (broken at the tilt setpoint, heading frame). In position mode the
/// roll and pitch loops, broken at the torque, include the position loop around them.
/// Motor lag (first_order motors) enters as one first-order lag of the larger time constant.
/// Linear drag (body and rotor drag) damps the translational channels; quadratic drag, wind, ground
/// effect and faults are not part of the linearisation. Throws std::invalid_argument when hover
/// cannot be trimmed (hover_trim_problem) and control::CareError when an LQR design fails.
std::vector<HoverLoop> hover_loops(const model::VehicleParams& plant, const controllers::PaperController& controller,
                                   control::Mode mode, const LoopTiming& timing);

}  // namespace quadcosim::analysis
