// Polynomial trajectory files in the layout of Crazyswarm2 / the Crazyflie (uav_trajectory.py):
// a header `Duration,x^0,...,x^7,y^0,...,y^7,z^0,...,z^7,yaw^0,...,yaw^7` (33 columns), then one
// segment per row, each polynomial in the segment's own time tau in [0, Duration] [s]; x, y, z [m],
// yaw [rad].
#pragma once

#include <stdexcept>
#include <string>

#include "trajectory/piecewise_polynomial.hpp"

namespace quadcosim::trajectory {

/// A polynomial file that cannot be read; what() names the file, the line and the problem, e.g.
/// "fig8.csv: line 4, column 3 (x^1): got 'abc', expected a number".
class FileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a polynomial file; the first segment starts at start_s [s]. The header is matched without
/// regard to case or spaces around names; blank lines are skipped. Throws FileError for a missing
/// file, a bad header, a row without exactly 33 columns, a field that is not a number or not finite,
/// a Duration <= 0, or no segment.
PiecewisePolynomial read_polynomial_csv(const std::string& path, double start_s = 0);

/// Writes `poly` in that layout, every number in shortest round-trip form (reading it back gives the
/// same doubles). Throws std::runtime_error when the file cannot be written.
void write_polynomial_csv(const std::string& path, const PiecewisePolynomial& poly);

}  // namespace quadcosim::trajectory
