#include "trajectory/piecewise_polynomial.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace quadcosim::trajectory {

PiecewisePolynomial::PiecewisePolynomial(std::vector<Segment> segments, double start_s, std::string label)
    : segments_(std::move(segments)), start_s_(start_s), label_(std::move(label)) {
  if (segments_.empty()) throw std::invalid_argument("a piecewise polynomial needs at least one segment");
  if (!std::isfinite(start_s_)) throw std::invalid_argument("the start time must be finite");
  double t = start_s_;
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    const Segment& s = segments_[i];
    if (!std::isfinite(s.duration_s) || s.duration_s <= 0) {
      throw std::invalid_argument("segment " + std::to_string(i) + ": duration must be finite and > 0");
    }
    if (!s.c.allFinite()) throw std::invalid_argument("segment " + std::to_string(i) + ": non-finite coefficient");
    starts_s_.push_back(t);
    t += s.duration_s;
  }
  end_s_ = t;
}

Eigen::Vector4d PiecewisePolynomial::evaluate(const Coefficients& c, double tau_s, int order) {
  Eigen::Vector4d r = Eigen::Vector4d::Zero();
  if (order < 0 || order >= kCoefficients) return r;
  for (int i = kCoefficients - 1; i >= order; --i) {
    double falling = 1;  // i! / (i - order)!
    for (int m = 0; m < order; ++m) falling *= i - m;
    r = r * tau_s + c.col(i) * falling;
  }
  return r;
}

std::size_t PiecewisePolynomial::locate(double t_s, bool left, double& tau_s) const {
  t_s = std::clamp(t_s, start_s_, end_s_);
  // The last segment starting at or before t (strictly before t for `left`).
  auto it = left ? std::lower_bound(starts_s_.begin(), starts_s_.end(), t_s)
                 : std::upper_bound(starts_s_.begin(), starts_s_.end(), t_s);
  std::size_t i = it == starts_s_.begin() ? 0 : static_cast<std::size_t>(it - starts_s_.begin()) - 1;
  tau_s = std::min(t_s - starts_s_[i], segments_[i].duration_s);
  return i;
}

Eigen::Vector4d PiecewisePolynomial::derivative(double t_s, int order, bool left) const {
  double tau = 0;
  const std::size_t i = locate(t_s, left, tau);
  return evaluate(segments_[i].c, tau, order);
}

FlatOutput PiecewisePolynomial::at(double t_s) const {
  FlatOutput out;
  const bool moving = t_s >= start_s_ && t_s < end_s_;
  double tau = 0;
  const std::size_t i = locate(t_s, false, tau);
  const Coefficients& c = segments_[i].c;
  const Eigen::Vector4d p = evaluate(c, tau, 0);
  out.p_W = p.head<3>();
  out.yaw_rad = p[3];
  if (moving) {
    const Eigen::Vector4d v = evaluate(c, tau, 1);
    out.v_W = v.head<3>();
    out.yaw_rate_rad_s = v[3];
    out.a_W = evaluate(c, tau, 2).head<3>();
    out.j_W = evaluate(c, tau, 3).head<3>();
  }
  return out;
}

std::string PiecewisePolynomial::describe() const {
  char buf[160];
  std::snprintf(buf, sizeof buf, ": %zu segment%s from %g s to %g s", segments_.size(),
                segments_.size() == 1 ? "" : "s", start_s_, end_s_);
  return label_ + buf;
}

}  // namespace quadcosim::trajectory
