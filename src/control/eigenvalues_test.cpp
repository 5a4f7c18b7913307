// Tests of control::eigenvalues and control::spectral_radius (the one eigen-solver of the design and
// analysis code) against closed forms written here: the 2 x 2 characteristic polynomial, a companion
// matrix built from chosen roots, and a scaled rotation whose eigenvalues are r e^{+-i theta}.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "control/eigenvalues.hpp"

namespace {

using cd = std::complex<double>;
using quadcosim::control::eigenvalues;
using quadcosim::control::spectral_radius;

// Sorted by real part, then imaginary part, so two sets compare element by element.
std::vector<cd> sorted(const Eigen::VectorXcd& v) {
  std::vector<cd> out(v.data(), v.data() + v.size());
  std::sort(out.begin(), out.end(),
            [](cd a, cd b) { return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag(); });
  return out;
}

TEST(Eigenvalues, TwoByTwoAreTheRootsOfItsCharacteristicPolynomial) {
  // [a b; c d]: lambda^2 - (a + d) lambda + (ad - bc) = 0, solved here by the quadratic formula.
  const double a = 0.3, b = -2.0, c = 1.5, d = -0.7;
  Eigen::MatrixXd m(2, 2);
  m << a, b, c, d;
  const double tr = a + d, det = a * d - b * c;
  const cd disc = std::sqrt(cd(tr * tr - 4.0 * det, 0.0));
  const std::vector<cd> want = sorted((Eigen::VectorXcd(2) << (tr - disc) / 2.0, (tr + disc) / 2.0).finished());
  const std::vector<cd> got = sorted(eigenvalues(m));
  ASSERT_EQ(got.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) EXPECT_NEAR(std::abs(got[i] - want[i]), 0.0, 1e-12) << i;
}

TEST(Eigenvalues, CompanionMatrixGivesBackTheChosenRoots) {
  // p(x) = (x + 1)(x - 2)(x + 0.5)(x^2 + 0.4 x + 4.04): roots -1, 2, -0.5, -0.2 +- 2i.
  const std::vector<cd> roots = {-1.0, 2.0, -0.5, cd(-0.2, 2.0), cd(-0.2, -2.0)};
  std::vector<cd> coeff = {1.0};  // highest power first
  for (const cd r : roots) {
    std::vector<cd> next(coeff.size() + 1, 0.0);
    for (std::size_t i = 0; i < coeff.size(); ++i) {
      next[i] += coeff[i];
      next[i + 1] -= r * coeff[i];
    }
    coeff = next;
  }
  const int n = static_cast<int>(roots.size());
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);  // companion: first row -a_{n-1} .. -a_0
  for (int j = 0; j < n; ++j) c(0, j) = -coeff[static_cast<std::size_t>(j) + 1].real();
  for (int i = 1; i < n; ++i) c(i, i - 1) = 1.0;
  const std::vector<cd> got = sorted(eigenvalues(c));
  const std::vector<cd> want = sorted(Eigen::Map<const Eigen::VectorXcd>(roots.data(), n));
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(std::abs(got[i] - want[i]), 0.0, 1e-9) << i;
  EXPECT_NEAR(spectral_radius(c), std::abs(cd(-0.2, 2.0)), 1e-9);  // |-0.2 + 2i| = 2.00998 > 2
}

TEST(Eigenvalues, ScaledRotationHasItsScaleAsSpectralRadius) {
  const double r = 0.93, theta = 0.4 * std::numbers::pi;
  Eigen::MatrixXd m(2, 2);
  m << r * std::cos(theta), -r * std::sin(theta), r * std::sin(theta), r * std::cos(theta);
  const std::vector<cd> got = sorted(eigenvalues(m));
  ASSERT_EQ(got.size(), 2u);
  EXPECT_NEAR(std::abs(got[0] - std::polar(r, -theta)), 0.0, 1e-12);
  EXPECT_NEAR(std::abs(got[1] - std::polar(r, theta)), 0.0, 1e-12);
  EXPECT_NEAR(spectral_radius(m), r, 1e-12);
}

TEST(Eigenvalues, EmptyMatrixHasNone) {
  EXPECT_EQ(eigenvalues(Eigen::MatrixXd(0, 0)).size(), 0);
  EXPECT_EQ(spectral_radius(Eigen::MatrixXd(0, 0)), 0.0);
}

}  // namespace
