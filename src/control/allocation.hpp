// Control allocation (Algorithm 1, lines 16-20): [U1..U4] -> rotor speeds, for any rotor count.
#pragma once

#include <Eigen/Core>
#include <array>

#include "model/rotor_vector.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::control {

struct Allocation {
  model::RotorVector omega_rad_s = model::RotorVector::Zero(4);  ///< commanded rotor speeds [rad/s], one per rotor
  model::RotorFlags saturated;  ///< rotor i hit omega_min or omega_max (count = the rotor count)
};

/// Omega^2 = M^-1 U, each entry clamped to [omega_min^2, omega_max^2], omega = sqrt(max(0, .)).
/// `mixer_inverse` is M^-1 of eq. (4) (a four-rotor vehicle).
Allocation allocate(const Eigen::Matrix4d& mixer_inverse, const Eigen::Vector4d& U, double omega_min_rad_s,
                    double omega_max_rad_s);

/// The allocation of a vehicle's layout: Omega^2 = A U with A = M^-1 for four rotors (computed as the
/// paper's controllers always did, so their numbers stay bit for bit) and the Moore-Penrose
/// pseudo-inverse M^+ = M^T (M M^T)^-1 for more (of all squared speeds that make U, the one of least
/// norm: equal speeds for a pure thrust on a symmetric frame); each rotor then clamped to its range.
/// The clamp is per rotor: a saturated rotor's share is not redistributed (the wrench is then not met
/// exactly, as for the quadrotor).
class RotorAllocation {
 public:
  RotorAllocation() = default;
  /// The vehicle's allocation (model::allocation_matrix).
  explicit RotorAllocation(const model::VehicleParams& vehicle);
  /// A four-rotor allocation from a given M^-1 (a controller that inverts the mixer its own way).
  explicit RotorAllocation(const Eigen::Matrix4d& mixer_inverse);

  int rotor_count() const { return static_cast<int>(matrix_.rows()); }
  /// A (N x 4): Omega^2 = A U.
  const model::AllocationMatrix& matrix() const { return matrix_; }
  /// The squared speeds A U, before any clamp [rad^2/s^2].
  model::RotorVector squared_speeds(const Eigen::Vector4d& U) const;
  /// The clamped speeds and flags, as allocate() above.
  Allocation allocate(const Eigen::Vector4d& U, double omega_min_rad_s, double omega_max_rad_s) const;

 private:
  model::AllocationMatrix matrix_ = model::AllocationMatrix::Zero(4, 4);
  Eigen::Matrix4d inverse4_ = Eigen::Matrix4d::Zero();  ///< matrix_ as a fixed-size 4x4 when N = 4
};

}  // namespace quadcosim::control
