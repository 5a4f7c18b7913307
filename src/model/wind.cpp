#include "model/wind.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

namespace quadcosim::model {

namespace {
constexpr double kFt = 0.3048;
}

DrydenScales dryden_low_altitude(const GustParams& p, double mean_wind_speed_m_s) {
  const double h_ft = std::clamp(p.altitude_m / kFt, 10.0, 1000.0);
  const double k = 0.177 + 0.000823 * h_ft;
  DrydenScales s{};
  s.L_w_m = h_ft * kFt;
  s.L_u_m = s.L_v_m = h_ft / std::pow(k, 1.2) * kFt;
  s.sigma_w_m_s = 0.1 * p.w20_m_s;
  s.sigma_u_m_s = s.sigma_v_m_s = s.sigma_w_m_s / std::pow(k, 0.4);
  s.V_m_s = p.airspeed_m_s > 0.0 ? p.airspeed_m_s : std::max(mean_wind_speed_m_s, 1.0);
  return s;
}

double dryden_psd_longitudinal(double w, double sigma, double L, double V) {
  const double r = L * w / V;
  return sigma * sigma * 2.0 * L / (std::numbers::pi * V) / (1.0 + r * r);
}

double dryden_psd_lateral(double w, double sigma, double L, double V) {
  const double r2 = (L * w / V) * (L * w / V);
  return sigma * sigma * L / (std::numbers::pi * V) * (1.0 + 3.0 * r2) / ((1.0 + r2) * (1.0 + r2));
}

double dryden_autocorrelation_longitudinal(double tau, double sigma, double L, double V) {
  return sigma * sigma * std::exp(-V * std::abs(tau) / L);
}

double dryden_autocorrelation_lateral(double tau, double sigma, double L, double V) {
  const double x = V * std::abs(tau) / L;
  return sigma * sigma * (1.0 - 0.5 * x) * std::exp(-x);
}

DrydenFilter::DrydenFilter(int order, double sigma, double L, double V, double T) : order_(order) {
  assert(order == 1 || order == 2);
  const double a = V / L;
  const double e = std::exp(-a * T);
  if (order == 1) {
    // x' = -a x + noise, y = x; stationary variance σ².
    Ad_ = {e, 0.0, 0.0, 0.0};
    Lp_ = {sigma, 0.0, 0.0};
    Lq_ = {sigma * std::sqrt(1.0 - e * e), 0.0, 0.0};
    c_ = {1.0, 0.0};
    return;
  }
  // H(s) = a² (1 + b s) / (s² + 2 a s + a²), b = √3 / a, times σ sqrt(L/(πV)): controllable canonical
  // form x1' = x2, x2' = -a² x1 - 2a x2 + n with white-noise intensity q, y = a² x1 + a² b x2.
  // Lyapunov A P + P Aᵀ + diag(0, q) = 0 gives P = diag(q / (4a³), q / (4a)); the output variance is
  // then q a (1 + a² b²) / 4 = q a, so q = σ² / a makes it σ².
  const double b = std::sqrt(3.0) / a;
  const double q = sigma * sigma / a;
  const double p11 = q / (4.0 * a * a * a), p22 = q / (4.0 * a);
  // exp(A T) for the double pole -a: e^{-aT} [[1 + aT, T], [-a² T, 1 - aT]].
  Ad_ = {e * (1.0 + a * T), e * T, -e * a * a * T, e * (1.0 - a * T)};
  // Q = P - Ad P Adᵀ (P diagonal).
  const double q11 = p11 - (Ad_[0] * Ad_[0] * p11 + Ad_[1] * Ad_[1] * p22);
  const double q21 = -(Ad_[2] * Ad_[0] * p11 + Ad_[3] * Ad_[1] * p22);
  const double q22 = p22 - (Ad_[2] * Ad_[2] * p11 + Ad_[3] * Ad_[3] * p22);
  const double l11 = std::sqrt(std::max(q11, 0.0));
  const double l21 = l11 > 0.0 ? q21 / l11 : 0.0;
  Lq_ = {l11, l21, std::sqrt(std::max(q22 - l21 * l21, 0.0))};
  Lp_ = {std::sqrt(p11), 0.0, std::sqrt(p22)};
  c_ = {a * a, a * a * b};
}

void DrydenFilter::start(Rng& rng) {
  const double n1 = rng.normal();
  const double n2 = order_ == 2 ? rng.normal() : 0.0;
  x_ = {Lp_[0] * n1, Lp_[1] * n1 + Lp_[2] * n2};
}

void DrydenFilter::advance(Rng& rng) {
  const double n1 = rng.normal();
  const double n2 = order_ == 2 ? rng.normal() : 0.0;
  const std::array<double, 2> x = x_;
  x_[0] = Ad_[0] * x[0] + Ad_[1] * x[1] + Lq_[0] * n1;
  x_[1] = Ad_[2] * x[0] + Ad_[3] * x[1] + Lq_[1] * n1 + Lq_[2] * n2;
}

WindField::WindField(const WindParams& p, double period_s, Rng rng) : p_(p), rng_(rng) {
  if (!p.gusts.enabled) return;
  const Eigen::Vector2d horizontal = p.mean_W_m_s.head<2>();
  scales_ = dryden_low_altitude(p.gusts, p.mean_W_m_s.norm());
  const double V = scales_.V_m_s;
  filters_[0] = DrydenFilter(1, scales_.sigma_u_m_s, scales_.L_u_m, V, period_s);
  filters_[1] = DrydenFilter(2, scales_.sigma_v_m_s, scales_.L_v_m, V, period_s);
  filters_[2] = DrydenFilter(2, scales_.sigma_w_m_s, scales_.L_w_m, V, period_s);
  const double n = horizontal.norm();
  const Eigen::Vector3d u =
      n > 0.0 ? Eigen::Vector3d(horizontal.x() / n, horizontal.y() / n, 0.0) : Eigen::Vector3d::UnitX();
  R_gust_to_W_.col(0) = u;
  R_gust_to_W_.col(1) = Eigen::Vector3d::UnitZ().cross(u);
  R_gust_to_W_.col(2) = Eigen::Vector3d::UnitZ();
  for (auto& f : filters_) f.start(rng_);
}

Eigen::Vector3d WindField::at_tick(std::int64_t k) {
  if (!p_.gusts.enabled) return p_.mean_W_m_s;
  if (tick_ < 0) tick_ = 0;  // tick 0 is the stationary start
  for (; tick_ < k; ++tick_) {
    for (auto& f : filters_) f.advance(rng_);
  }
  const Eigen::Vector3d g(filters_[0].value(), filters_[1].value(), filters_[2].value());
  return p_.mean_W_m_s + R_gust_to_W_ * g;
}

std::string validate(const WindParams& p) {
  if (!p.mean_W_m_s.allFinite()) return "wind.mean_m_s must be finite";
  if (!p.gusts.enabled) return {};
  if (!std::isfinite(p.gusts.w20_m_s) || p.gusts.w20_m_s < 0.0) return "gusts.w20_m_s must be >= 0";
  if (!std::isfinite(p.gusts.altitude_m) || p.gusts.altitude_m <= 0.0) return "gusts.altitude_m must be > 0";
  if (!std::isfinite(p.gusts.airspeed_m_s) || p.gusts.airspeed_m_s < 0.0) return "gusts.airspeed_m_s must be >= 0";
  return {};
}

}  // namespace quadcosim::model
