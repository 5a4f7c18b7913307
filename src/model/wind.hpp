// Wind: a constant mean wind plus Dryden turbulence (gusts), as world-frame air velocity [m/s].
//
// Dryden model in the form of MIL-F-8785C (sec. 3.7.2) and MIL-HDBK-1797 (app. A, 3.7), low
// altitude (h below 1000 ft). Spectra (one-sided, per rad/s of temporal frequency ω, for a vehicle
// moving through frozen turbulence at airspeed V):
//   Φ_u(ω) = σ_u² (2 L_u / (π V)) / (1 + (L_u ω / V)²)
//   Φ_v(ω) = σ_v² (L_v / (π V)) (1 + 3 (L_v ω / V)²) / (1 + (L_v ω / V)²)²      (Φ_w alike, with L_w)
// so that ∫₀^∞ Φ dω = σ². Shaping filters:
//   H_u(s) = σ_u sqrt(2 L_u / (π V)) / (1 + (L_u / V) s)
//   H_v(s) = σ_v sqrt(L_v / (π V)) (1 + √3 (L_v / V) s) / (1 + (L_v / V) s)²
// Low-altitude scale lengths and intensities (h in ft inside the formulas; W20 the mean wind at
// 20 ft): L_w = h, L_u = L_v = h / (0.177 + 0.000823 h)^1.2, σ_w = 0.1 W20,
// σ_u = σ_v = σ_w / (0.177 + 0.000823 h)^0.4. h is clamped to [10, 1000] ft, the model's range.
//
// Discretisation: exact, at the plant period T. Each filter is realised in state space (u: first
// order, v and w: second order with a double pole at a = V / L) and sampled so that the discrete
// state has exactly the continuous process's covariance at the sample instants:
// x_{k+1} = A_d x_k + chol(P - A_d P A_dᵀ) n_k, with A_d = exp(A T) in closed form, P the stationary
// covariance (Lyapunov equation, solved in closed form) and n_k ~ N(0, I). The initial state is
// drawn from P, so the gusts are stationary from t = 0. The wind is held over each plant tick.
//
// Axes: u along the horizontal mean wind direction (x_W when there is no mean wind), v horizontal
// and perpendicular to it (u × v = z_W), w along z_W. V is `airspeed_m_s` (default: the mean wind
// speed, floored at 1 m/s), constant, so the filters are time-invariant.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>

#include "model/random.hpp"

namespace quadcosim::model {

struct GustParams {
  bool enabled = false;
  double w20_m_s = 7.7;       ///< mean wind at 20 ft (6.1 m) [m/s]; MIL-F-8785C: light 15 kt, moderate 30, severe 45
  double altitude_m = 5.0;    ///< altitude for the scale lengths and intensities [m] (clamped to 3.048..304.8)
  double airspeed_m_s = 0.0;  ///< V [m/s]; 0: the mean wind speed, floored at 1 m/s
};

struct WindParams {
  Eigen::Vector3d mean_W_m_s = Eigen::Vector3d::Zero();  ///< constant wind, world frame [m/s]
  GustParams gusts;
  bool active() const { return !mean_W_m_s.isZero(0.0) || gusts.enabled; }
};

/// The Dryden figures for one configuration.
struct DrydenScales {
  double sigma_u_m_s, sigma_v_m_s, sigma_w_m_s;  ///< intensities [m/s]
  double L_u_m, L_v_m, L_w_m;                    ///< scale lengths [m]
  double V_m_s;                                  ///< airspeed the spectra are converted with [m/s]
};

/// MIL-F-8785C low-altitude scales for `p` with mean wind speed |mean_W|.
DrydenScales dryden_low_altitude(const GustParams& p, double mean_wind_speed_m_s);

/// Φ_u(ω) [(m/s)² / (rad/s)] (first-order form) for intensity sigma, scale length L, airspeed V.
double dryden_psd_longitudinal(double omega_rad_s, double sigma, double L_m, double V_m_s);
/// Φ_v(ω) = Φ_w(ω) form [(m/s)² / (rad/s)].
double dryden_psd_lateral(double omega_rad_s, double sigma, double L_m, double V_m_s);
/// Autocorrelations R(τ) of the two forms (textbook: σ² e^{-Vτ/L}; σ² (1 - Vτ/(2L)) e^{-Vτ/L}).
double dryden_autocorrelation_longitudinal(double tau_s, double sigma, double L_m, double V_m_s);
double dryden_autocorrelation_lateral(double tau_s, double sigma, double L_m, double V_m_s);

/// One Dryden channel sampled exactly at period T: order 1 (u) or 2 (v, w).
class DrydenFilter {
 public:
  DrydenFilter() = default;
  DrydenFilter(int order, double sigma, double L_m, double V_m_s, double period_s);
  /// Draws the stationary initial state.
  void start(Rng& rng);
  /// The current output [m/s].
  double value() const { return c_[0] * x_[0] + c_[1] * x_[1]; }
  /// Advances one period.
  void advance(Rng& rng);

 private:
  int order_ = 1;
  std::array<double, 4> Ad_{};  ///< row-major 2x2
  std::array<double, 3> Lq_{};  ///< lower Cholesky factor of the step covariance: l11, l21, l22
  std::array<double, 3> Lp_{};  ///< lower Cholesky factor of the stationary covariance
  std::array<double, 2> c_{};
  std::array<double, 2> x_{};
};

/// Mean wind plus gusts, advanced once per plant tick.
class WindField {
 public:
  WindField() = default;
  /// `rng` seeds the gust stream (unused without gusts).
  WindField(const WindParams& p, double period_s, Rng rng);
  /// Wind over tick k [m/s]. Ticks are visited in order: asking for the current tick again returns
  /// the same value (draws nothing), a later tick advances the gusts tick by tick.
  Eigen::Vector3d at_tick(std::int64_t k);
  const DrydenScales& scales() const { return scales_; }

 private:
  WindParams p_;
  DrydenScales scales_{};
  Rng rng_;
  std::array<DrydenFilter, 3> filters_;
  Eigen::Matrix3d R_gust_to_W_ = Eigen::Matrix3d::Identity();
  std::int64_t tick_ = -1;
};

/// Empty when `p` is meaningful, else a message naming the field.
std::string validate(const WindParams& p);

}  // namespace quadcosim::model
