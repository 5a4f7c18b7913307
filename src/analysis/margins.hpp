// Stability margins of a single-input feedback loop: the loop broken at one plant input, in
// continuous time or sampled at the controller's period (zero-order hold, whole-tick delays).
// Pure numerics on Eigen: no YAML, no CLI. docs/margins.md gives the method and conventions.
#pragma once

#include <Eigen/Core>
#include <complex>
#include <optional>
#include <string>
#include <vector>

namespace quadcosim::analysis {

/// x' = A x + B u, y = C x + D u. period_s == 0: continuous time (x' = dx/dt); period_s > 0:
/// discrete time at that period [s] (x' = x of the next sample).
struct StateSpace {
  Eigen::MatrixXd A, B, C, D;
  double period_s = 0.0;

  bool discrete() const { return period_s > 0.0; }
};

/// Exact zero-order-hold discretisation of dx/dt = A x + B u, y = C x at period T [s] (matrix
/// exponential of [[A, B], [0, 0]] T).
StateSpace zoh_discretise(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C,
                          double period_s);

/// A continuous plant run on integer ticks and read by a controller every `ticks_per_sample` ticks:
/// the controller's output is held (zero-order hold) until its next sample, reaches the plant
/// `input_delay_ticks` ticks after it was computed, and output row r is measured as it was
/// `output_delay_ticks[r]` ticks before the sample (empty: no delays). The exact sampled model at the
/// controller period: see sample_plant.
struct SampledPlantSpec {
  Eigen::MatrixXd A, B, C;  ///< continuous plant (states x inputs, outputs x states)
  double tick_s = 0.01;     ///< plant tick [s]
  int ticks_per_sample = 1;
  int input_delay_ticks = 0;
  std::vector<int> output_delay_ticks;  ///< per output row (empty: all 0)
};

/// The discrete plant at the controller period tick_s * ticks_per_sample, from the held controller
/// output to the measurements the controller reads. Exact for the linear plant: ZOH at the tick, the
/// delays as shift registers on ticks, then N = ticks_per_sample ticks composed (X+ = F^N X +
/// sum F^i G u). Its state is [plant state, input delay line, each output's delay line].
/// Throws std::invalid_argument for sizes that disagree, a non-positive tick or negative delays.
StateSpace sample_plant(const SampledPlantSpec& spec);

/// A loop broken at one plant input: `plant` maps that input u to the measurements y, `controller`
/// maps y to the u it commands (both continuous, or both discrete at one period). Negative-feedback
/// convention: the loop transfer is L = -controller * plant, and the loop is closed stably when
/// 1 + L has no zeros in the unstable region.
struct Loop {
  StateSpace plant;       ///< 1 input (the break point), p outputs
  StateSpace controller;  ///< p inputs, 1 output (the command at the break point)

  /// L(j omega) or L(exp(j omega T)).
  std::complex<double> transfer(double omega_rad_s) const;
  /// The closed loop's state matrix with a gain k inserted at the break point (u = k * command).
  Eigen::MatrixXd closed_loop_matrix(double gain) const;
  double period_s() const { return plant.period_s; }
};

/// Eigenvalues of the closed loop with gain k: s-plane (continuous) or z-plane (discrete).
Eigen::VectorXcd closed_loop_poles(const Loop& loop, double gain = 1.0);
/// Poles strictly in the unstable region: Re s > tol or |z| > 1 + tol.
int unstable_count(const Eigen::VectorXcd& poles, bool discrete, double tol = 1e-9);

/// A margin is a number, infinite (no crossing limits it), or undefined (the loop as given is not
/// stable closed-loop, so it has no margin to lose).
enum class MarginStatus { kFinite, kInfinite, kUndefined };
const char* to_string(MarginStatus s);

struct Margin {
  MarginStatus status = MarginStatus::kUndefined;
  double value = 0.0;            ///< meaningful when kFinite (units per field below)
  double frequency_rad_s = 0.0;  ///< the crossover it was found at, when kFinite
};

struct MarginOptions {
  double omega_min_rad_s = 1e-4;  ///< low end of the log grid [rad/s]
  /// High end [rad/s]; 0: the Nyquist frequency pi / T (discrete) or 1e4 rad/s (continuous).
  double omega_max_rad_s = 0.0;
  int points = 6000;  ///< log-spaced grid points (crossings are refined by bisection)
};

/// Everything the margin analysis finds for one loop.
struct LoopMargins {
  bool closed_loop_stable = false;   ///< at the nominal gain (1)
  int open_loop_unstable_poles = 0;  ///< of plant and controller together, strictly unstable
  int open_loop_marginal_poles = 0;  ///< on the imaginary axis / unit circle (integrators)
  Eigen::VectorXcd closed_loop_poles;
  /// Upper gain margin: the closed loop stays stable for gains in [1, value) [factor, not dB];
  /// frequency = the phase crossover where it is lost (0 for a loss at omega = 0).
  Margin gain_margin;
  /// Lower gain margin: stable for gains in (value, 1]; kInfinite when the gain may drop to 0
  /// (stable for every gain in (0, 1]).
  Margin gain_reduction_margin;
  /// Phase margin [rad], the smallest |180 deg + angle L| over the gain crossovers, signed.
  Margin phase_margin;
  /// Delay margin [s]: the smallest extra loop delay that puts a gain crossover on -1, i.e. the
  /// minimum over crossovers of (phase margin mod 2 pi) / omega_gc. For discrete loops it is also
  /// reported in controller samples (value / period).
  Margin delay_margin;
  std::vector<double> gain_crossovers_rad_s;   ///< every |L| = 1 crossing found
  std::vector<double> phase_crossovers_rad_s;  ///< every crossing of the negative real axis
  /// Gain intervals (lo, hi) of closed-loop stability (hi = +inf when unbounded), from the
  /// eigenvalues at each interval's midpoint.
  std::vector<std::pair<double, double>> stable_gain_ranges;
};

LoopMargins analyse_margins(const Loop& loop, const MarginOptions& options = {});

/// The loop transfer on the grid the analysis uses, for plots: omega, L, |L| [dB], phase [deg]
/// (unwrapped from the lowest frequency, starting within (-360, 0]).
struct FrequencyPoint {
  double omega_rad_s;
  std::complex<double> L;
  double magnitude_db;
  double phase_deg;
};
std::vector<FrequencyPoint> frequency_response(const Loop& loop, const MarginOptions& options = {});

}  // namespace quadcosim::analysis
