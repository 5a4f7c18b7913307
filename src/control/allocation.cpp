#include "control/allocation.hpp"

#include <algorithm>
#include <cmath>

#include "model/mixer.hpp"

namespace quadcosim::control {

namespace {

// Each squared speed clamped to [lo^2, hi^2] and flagged when it had to be; omega = sqrt. kN: the rotor
// count when known at compile time (4: the quadrotor's loop, unrolled), else 0 and n.
template <int kN, class Vec>
Allocation clamp_speeds(const Vec& omega_sq, Eigen::Index n, double omega_min_rad_s, double omega_max_rad_s) {
  const double lo = omega_min_rad_s * omega_min_rad_s;
  const double hi = omega_max_rad_s * omega_max_rad_s;
  if constexpr (kN > 0) n = kN;
  Allocation out;
  out.omega_rad_s.resize(n);
  out.saturated.count = static_cast<int>(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    // A non-finite demand (only possible from a non-finite U) is treated as the lowest speed.
    const double demand = std::isfinite(omega_sq[i]) ? omega_sq[i] : lo;
    const double w2 = std::clamp(demand, lo, hi);
    out.saturated[static_cast<int>(i)] = !(omega_sq[i] >= lo && omega_sq[i] <= hi);
    out.omega_rad_s[i] = std::sqrt(std::max(0.0, w2));
  }
  return out;
}

}  // namespace

Allocation allocate(const Eigen::Matrix4d& mixer_inverse, const Eigen::Vector4d& U, double omega_min_rad_s,
                    double omega_max_rad_s) {
  const Eigen::Vector4d omega_sq = mixer_inverse * U;
  return clamp_speeds<4>(omega_sq, 4, omega_min_rad_s, omega_max_rad_s);
}

RotorAllocation::RotorAllocation(const model::VehicleParams& vehicle) : matrix_(model::allocation_matrix(vehicle)) {
  if (matrix_.rows() == 4) inverse4_ = matrix_.topRows<4>();
}

RotorAllocation::RotorAllocation(const Eigen::Matrix4d& mixer_inverse)
    : matrix_(mixer_inverse), inverse4_(mixer_inverse) {}

model::RotorVector RotorAllocation::squared_speeds(const Eigen::Vector4d& U) const {
  if (matrix_.rows() == 4) {
    const Eigen::Vector4d omega_sq = inverse4_ * U;  // the fixed-size product, as allocate()
    return omega_sq;
  }
  return matrix_ * U;
}

Allocation RotorAllocation::allocate(const Eigen::Vector4d& U, double omega_min_rad_s, double omega_max_rad_s) const {
  if (matrix_.rows() == 4) {  // the fixed-size product of the paper's controllers
    const Eigen::Vector4d omega_sq = inverse4_ * U;
    return clamp_speeds<4>(omega_sq, 4, omega_min_rad_s, omega_max_rad_s);
  }
  const model::RotorVector omega_sq = matrix_ * U;
  return clamp_speeds<0>(omega_sq, matrix_.rows(), omega_min_rad_s, omega_max_rad_s);
}

}  // namespace quadcosim::control
