// Loop margins of any controller, measured in simulation (docs/margins.md, "Measured margins"): the
// vehicle trimmed at level hover, the loop broken at the wrench the rotor command asks for, one axis
// at a time, small sinusoids injected there at a set of frequencies, and the loop transfer identified
// from whole periods of the steady state. The plant and the controller are the nodes every
// in-process run flies (sim::PlantNode, sim::ControllerNode on the in-process transport, ticked by
// the lockstep loop in its order), so registered, Python and FMU controllers are measured alike.
// Deterministic: same inputs, same numbers bit for bit.
#pragma once

#include <Eigen/Core>
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include "analysis/margins.hpp"
#include "control/controller_config.hpp"
#include "model/vehicle_params.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::analysis {

/// The four hover loops, each broken at one component of the wrench U = M Omega^2 (eq. (4)):
/// altitude at U1 (collective thrust [N]), roll at U2, pitch at U3, yaw at U4 (torques [N m]).
enum class HoverAxis { kRoll, kPitch, kYaw, kAltitude };
const char* to_string(HoverAxis axis);
/// The index of the axis's component in U (0: thrust, 1..3: torques).
int wrench_index(HoverAxis axis);
/// "U2 roll torque [N m]" and so on: where the loop is broken, with its unit.
std::string broken_at(HoverAxis axis);

/// What is flown: the scenario's plant (its timing, delays and sensor rates and latencies; noise,
/// wind, rotor faults and message drops are the caller's to leave out), the plant vehicle, and the
/// controller with its setpoints at the trim. The vehicle starts in hover at `trim_p_W`, level,
/// heading 0, rotors at hover speed.
struct HoverMeasurementSetup {
  sim::SimulationConfig simulation;
  model::VehicleParams vehicle;
  control::ControllerConfig controller;
  Eigen::Vector3d trim_p_W{0.0, 0.0, 10.0};  ///< [m]
};

struct MeasurementOptions {
  /// Injection amplitude as a fraction of the hover rotor speed: the sinusoid on axis i moves no
  /// rotor's speed by more than this fraction (to first order), whatever the axis's unit.
  double amplitude = 1e-4;
  double omega_min_rad_s = 0.1;  ///< lowest grid frequency [rad/s]; the highest is Nyquist, pi / T
  int points = 24;               ///< log-spaced grid frequencies, both ends included
  int refinements = 6;           ///< bisections (each one more measured frequency) per crossover
  double settle_s = 2.0;         ///< at least this long [s] before the first window
  double window_min_s = 2.0;     ///< a window is the fewest whole periods lasting at least this [s]
  /// Steady state: two consecutive windows whose L differ by at most this much relative to |L|.
  double tolerance = 1e-3;
  double max_s = 900.0;  ///< simulated time per frequency [s] before giving up on steady state
};

/// The loop transfer at one frequency, from the windows of one closed-loop run.
struct MeasuredPoint {
  double omega_rad_s = 0.0;  ///< exact: a whole number of periods in a whole number of samples
  std::complex<double> L;    ///< -(controller's U_i) / (plant's U_i), the last window's
  int windows = 0;           ///< windows taken
  int periods_per_window = 0;
  double simulated_s = 0.0;
  bool converged = false;            ///< the last two windows agreed within tolerance
  double max_tilt_rad = 0.0;         ///< largest tilt seen while injecting
  double max_rotor_deviation = 0.0;  ///< largest |omega_cmd - omega_trim| / omega_trim seen
};

/// One axis measured: its response on the grid (and the refinements, in frequency order) and its
/// margins. `problem` says why no margin could be measured (the closed loop left hover); then every
/// margin is kUndefined. A margin of status kInfinite here means: no crossing in the measured band
/// [omega_min, pi / T] (the CLI prints it as "none").
struct MeasuredLoop {
  HoverAxis axis = HoverAxis::kRoll;
  std::vector<MeasuredPoint> points;
  double amplitude = 0.0;  ///< injected amplitude in the axis's unit [N or N m]
  std::string problem;
  Margin gain_margin;            ///< factor (> 1): 1 / |L| at the phase crossover of smallest such factor
  Margin gain_reduction_margin;  ///< factor (< 1): at a phase crossover where |L| > 1 (conditional stability)
  Margin phase_margin;           ///< [rad], smallest |180 deg + angle L| over the gain crossovers
  Margin delay_margin;           ///< [s], min over crossovers of (PM mod 2 pi) / omega_gc
  std::vector<double> gain_crossovers_rad_s;
  std::vector<double> phase_crossovers_rad_s;
  int unconverged_points = 0;
};

/// The closed loop of `setup` with a sinusoid of `omega_rad_s` (adjusted to a whole number of periods
/// in a whole number of controller samples) injected on `axis`: the identified L. Throws
/// std::invalid_argument for a frequency outside (0, pi / T] and what the controller's step throws.
/// Sets `left_hover` when the vehicle tilted past 1 rad or its state stopped being finite.
MeasuredPoint measure_point(const HoverMeasurementSetup& setup, HoverAxis axis, double omega_rad_s,
                            const MeasurementOptions& options, bool& left_hover);

/// The axis's response on the grid, its crossovers refined by bisection, and its margins. `progress`,
/// when set, is told of each measured frequency.
MeasuredLoop measure_loop(const HoverMeasurementSetup& setup, HoverAxis axis, const MeasurementOptions& options,
                          const std::function<void(HoverAxis, const MeasuredPoint&)>& progress = {});

/// Margins from a response measured on increasing frequencies (the last may be Nyquist, where L is
/// real): crossovers by interpolating log |L| and the unwrapped phase linearly in log omega.
/// Fills the margin fields and crossovers of `loop` from loop.points.
void margins_from_points(MeasuredLoop& loop, double period_s);

}  // namespace quadcosim::analysis
