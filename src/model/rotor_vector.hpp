// Per-rotor quantities of a vehicle with 4 to kMaxRotors rotors, without heap allocation: a rotor
// vector sized by the vehicle's rotor count (Eigen storage for kMaxRotors inside the object) and a
// bounded array of flags with its count.
#pragma once

#include <Eigen/Core>
#include <array>

namespace quadcosim::model {

/// The most rotors a vehicle may have (an octorotor); the fewest is 4.
inline constexpr int kMaxRotors = 8;
inline constexpr int kMinRotors = 4;

/// One value per rotor [rad/s, N, ...]: size = the vehicle's rotor count, storage for kMaxRotors.
using RotorVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxRotors, 1>;

/// The mixer: 4 rows (collective thrust, torques about x_B, y_B, z_B) by one column per rotor.
using MixerMatrix = Eigen::Matrix<double, 4, Eigen::Dynamic, 0, 4, kMaxRotors>;

/// The allocation: one row per rotor by 4 (M^-1 for four rotors, the pseudo-inverse M^+ for more).
using AllocationMatrix = Eigen::Matrix<double, Eigen::Dynamic, 4, 0, kMaxRotors, 4>;

/// dst = src; a quadrotor's four entries as one fixed-size block (no size test per entry, no library
/// call): the per-tick copies of the paper's plant cost what they did with fixed four-vectors.
inline void assign_rotors(RotorVector& dst, const RotorVector& src) {
  if (src.size() == 4) {
    dst.resize(4);  // storage for kMaxRotors inside: only the size changes
    dst.head<4>() = src.head<4>();
    return;
  }
  dst = src;
}

/// One flag per rotor (saturation): the first `count` entries are meaningful, the rest false.
struct RotorFlags {
  std::array<bool, kMaxRotors> value{};
  int count = 4;

  bool& operator[](int i) { return value[static_cast<std::size_t>(i)]; }
  bool operator[](int i) const { return value[static_cast<std::size_t>(i)]; }
  int size() const { return count; }
  const bool* begin() const { return value.data(); }
  const bool* end() const { return value.data() + count; }
  bool any() const {
    for (int i = 0; i < count; ++i) {
      if (value[static_cast<std::size_t>(i)]) return true;
    }
    return false;
  }
  /// `n` rotors, none flagged.
  void reset(int n) {
    value.fill(false);
    count = n;
  }
  bool operator==(const RotorFlags&) const = default;
  /// True for `n` == count flags equal to `o` (a quadrotor's {a, b, c, d}).
  template <std::size_t n>
  bool operator==(const std::array<bool, n>& o) const {
    if (static_cast<std::size_t>(count) != n) return false;
    for (std::size_t i = 0; i < n; ++i) {
      if (value[i] != o[i]) return false;
    }
    return true;
  }
};

}  // namespace quadcosim::model
