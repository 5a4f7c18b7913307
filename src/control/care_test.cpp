// Tests of the CARE solver and the per-axis attitude LQR (eqs. (14)-(16)). Expected numbers come from
// closed forms derived here by hand, from the Riccati residual evaluated here (not only through
// care_residual), and from a second solver written here: Kleinman's Newton iteration on Lyapunov
// equations solved by Kronecker products, started from Bass's stabilising gain.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "control/attitude_lqr.hpp"
#include "control/care.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "model/vehicle_params.hpp"

namespace {

using Eigen::MatrixXd;
using quadcosim::control::AxisLqr;
using quadcosim::control::care_residual;
using quadcosim::control::CareError;
using quadcosim::control::design_axis_lqr;
using quadcosim::control::lqr_gain;
using quadcosim::control::LqrWeights;
using quadcosim::control::solve_care;

MatrixXd mat(int rows, int cols, std::initializer_list<double> values) {
  MatrixXd M(rows, cols);
  auto it = values.begin();
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) M(i, j) = *it++;
  return M;
}

MatrixXd scalar(double v) { return MatrixXd::Constant(1, 1, v); }

// Largest real part of the eigenvalues of M.
double spectral_abscissa(const MatrixXd& M) {
  return Eigen::EigenSolver<MatrixXd>(M, false).eigenvalues().real().maxCoeff();
}

// The Riccati residual A^T X + X A - X B R^-1 B^T X + Q, written out here with an LU solve for R^-1
// (the solver uses a Cholesky factorisation), and the scale it is measured against: the sizes of the
// three terms as they stand (not the product bounds ||A|| ||X||, ||X||^2 ||G||, which can be so
// large that even a badly wrong X looks accurate).
struct Residual {
  double abs, scale, bound_scale;
  double rel() const { return abs / scale; }
  /// Relative to the standard bound Q + 2 ||A|| ||X|| + ||X||^2 ||G|| (the backward-error scale).
  double rel_bound() const { return abs / bound_scale; }
};
constexpr double kResidualBound = 1e-14;  // relative to Q + 2 ||A|| ||X|| + ||X||^2 ||G||
constexpr double kResidualTerms = 1e-9;   // relative to ||Q|| + ||A^T X + X A|| + ||X G X||

Residual riccati_residual(const MatrixXd& A, const MatrixXd& B, const MatrixXd& Q, const MatrixXd& R,
                          const MatrixXd& X) {
  const MatrixXd RinvBt = R.fullPivLu().solve(B.transpose());
  const MatrixXd lyap = A.transpose() * X + X * A;
  const MatrixXd quad = (X * B) * (RinvBt * X);
  const MatrixXd res = lyap - quad + Q;
  return {res.norm(), Q.norm() + lyap.norm() + quad.norm(),
          Q.norm() + 2.0 * A.norm() * X.norm() + X.norm() * X.norm() * (B * RinvBt).norm()};
}

// Expects `f` to throw CareError whose message contains every one of `needles`.
void expect_care_error(const std::function<void()>& f, const std::vector<std::string>& needles,
                       const std::string& what) {
  SCOPED_TRACE(what);
  try {
    f();
    ADD_FAILURE() << "no CareError thrown";
  } catch (const CareError& e) {
    const std::string msg = e.what();
    for (const auto& n : needles) {
      EXPECT_NE(msg.find(n), std::string::npos) << "message '" << msg << "' lacks '" << n << "'";
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw something other than CareError: " << e.what();
  }
}

// ---------------------------------------------------------------------------------------------------
// Closed forms.

// Double integrator x1' = x2, x2' = b u, Q = diag(q1, q2), R = r, b > 0. With X = [x1 x2; x2 x3] the
// Riccati equation reads, entry by entry,
//   (1,1): q1 - (b^2/r) x2^2 = 0,  (1,2): x1 - (b^2/r) x2 x3 = 0,  (2,2): 2 x2 + q2 - (b^2/r) x3^2 = 0,
// and the stabilising root (A - B K = [0 1; -b k1 -b k2] Hurwitz needs k1, k2 > 0) gives
//   K = (b/r) [x2 x3] = [sqrt(q1/r), sqrt(q2/r + 2 sqrt(q1/r)/b)],
//   X = [r k1 k2, r k1/b; r k1/b, r k2/b].
TEST(CareClosedForm, DoubleIntegrator) {
  struct Case {
    double b, q1, q2, r;
  };
  for (const Case c : {Case{1.0, 1.0, 1.0, 1.0}, Case{2.5, 3.0, 0.5, 0.2}, Case{0.1, 10.0, 0.0, 4.0},
                       Case{1.0 / 0.0149, 1.3, 2.4, 100.0}, Case{7.0, 1e-3, 1e3, 1e-2}}) {
    SCOPED_TRACE(testing::Message() << "b=" << c.b << " q1=" << c.q1 << " q2=" << c.q2 << " r=" << c.r);
    const MatrixXd A = mat(2, 2, {0, 1, 0, 0});
    const MatrixXd B = mat(2, 1, {0, c.b});
    const MatrixXd Q = mat(2, 2, {c.q1, 0, 0, c.q2});
    const MatrixXd R = scalar(c.r);

    const double k1 = std::sqrt(c.q1 / c.r);
    const double k2 = std::sqrt(c.q2 / c.r + 2.0 * std::sqrt(c.q1 / c.r) / c.b);
    const MatrixXd X_exact = mat(2, 2, {c.r * k1 * k2, c.r * k1 / c.b, c.r * k1 / c.b, c.r * k2 / c.b});

    const MatrixXd X = solve_care(A, B, Q, R);
    const MatrixXd K = lqr_gain(A, B, Q, R);
    ASSERT_EQ(X.rows(), 2);
    ASSERT_EQ(X.cols(), 2);
    ASSERT_EQ(K.rows(), 1);
    ASSERT_EQ(K.cols(), 2);
    // The sign iteration converges to ~1e-13 relative; 1e-10 leaves room for the conditioning of the
    // wider-ranging cases (q2/q1 = 1e6).
    EXPECT_NEAR(K(0, 0), k1, 1e-10 * k1);
    EXPECT_NEAR(K(0, 1), k2, 1e-10 * k2);
    EXPECT_LE((X - X_exact).norm(), 1e-10 * X_exact.norm());
    // The closed loop s^2 + b k2 s + b k1 is Hurwitz.
    EXPECT_LT(spectral_abscissa(A - B * K), 0.0);
  }
}

// Scalar x' = a x + b u: the Riccati equation 2 a x - (b^2/r) x^2 + q = 0 has the stabilising root
// x = (a r + sqrt(a^2 r^2 + b^2 q r)) / b^2, with closed-loop pole a - b^2 x / r = -sqrt(a^2 + b^2 q / r).
TEST(CareClosedForm, ScalarStableAndUnstable) {
  struct Case {
    double a, b, q, r;
  };
  for (const Case c : {Case{-1.0, 1.0, 1.0, 1.0}, Case{2.0, 1.0, 1.0, 1.0}, Case{0.0, 3.0, 2.0, 0.5},
                       Case{5.0, -0.3, 0.7, 2.0}, Case{-4.0, 2.0, 0.0, 1.0},  // q = 0, stable: x = 0
                       Case{3.0, 0.5, 0.0, 1.0}}) {  // q = 0, unstable: mirrors the pole, x = 2 a r / b^2
    SCOPED_TRACE(testing::Message() << "a=" << c.a << " b=" << c.b << " q=" << c.q << " r=" << c.r);
    const double x = (c.a * c.r + std::sqrt(c.a * c.a * c.r * c.r + c.b * c.b * c.q * c.r)) / (c.b * c.b);
    const double k = c.b * x / c.r;
    const double pole = -std::sqrt(c.a * c.a + c.b * c.b * c.q / c.r);

    const MatrixXd X = solve_care(scalar(c.a), scalar(c.b), scalar(c.q), scalar(c.r));
    const MatrixXd K = lqr_gain(scalar(c.a), scalar(c.b), scalar(c.q), scalar(c.r));
    const double tol = 1e-12 * (1.0 + std::abs(x));
    EXPECT_NEAR(X(0, 0), x, tol);
    EXPECT_NEAR(K(0, 0), k, 1e-12 * (1.0 + std::abs(k)));
    EXPECT_NEAR(c.a - c.b * K(0, 0), pole, 1e-12 * (1.0 + std::abs(pole)));
    EXPECT_GE(X(0, 0), -tol);
  }
}

// An unstable scalar plant: the feedback must move the pole across the axis by the exact amount.
TEST(CareClosedForm, UnstableScalarIsStabilised) {
  const double a = 10.0, b = 2.0, q = 3.0, r = 0.25;
  const double x = (a * r + std::sqrt(a * a * r * r + b * b * q * r)) / (b * b);  // = (2.5 + sqrt(9.25))/4
  EXPECT_NEAR(x, (2.5 + std::sqrt(9.25)) / 4.0, 1e-15);
  const MatrixXd X = solve_care(scalar(a), scalar(b), scalar(q), scalar(r));
  EXPECT_NEAR(X(0, 0), x, 1e-12 * x);
  const double cl = a - b * b / r * X(0, 0);
  EXPECT_NEAR(cl, -std::sqrt(a * a + b * b * q / r), 1e-11);  // -sqrt(148)
  EXPECT_LT(cl, 0.0);
  // Hand-check of the residual of the scalar equation.
  EXPECT_NEAR(2.0 * a * X(0, 0) - b * b / r * X(0, 0) * X(0, 0) + q, 0.0, 1e-11);
}

// ---------------------------------------------------------------------------------------------------
// Random systems: residual, definiteness, stability, and agreement with Kleinman's iteration.

// Uniform in [-1, 1) from the top 53 bits, so the systems are the same on every standard library.
double uniform(std::mt19937_64& g) { return 2.0 * static_cast<double>(g() >> 11) * 0x1.0p-53 - 1.0; }

MatrixXd random_matrix(std::mt19937_64& g, int rows, int cols, double scale = 1.0) {
  MatrixXd M(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) M(i, j) = scale * uniform(g);
  return M;
}

MatrixXd kron(const MatrixXd& a, const MatrixXd& b) {
  MatrixXd k(a.rows() * b.rows(), a.cols() * b.cols());
  for (int i = 0; i < a.rows(); ++i)
    for (int j = 0; j < a.cols(); ++j) k.block(i * b.rows(), j * b.cols(), b.rows(), b.cols()) = a(i, j) * b;
  return k;
}

// Solves F^T X + X F = -W (F Hurwitz) through vec(F^T X + X F) = (I (x) F^T + F^T (x) I) vec(X).
MatrixXd lyapunov(const MatrixXd& F, const MatrixXd& W) {
  const auto n = F.rows();
  const MatrixXd I = MatrixXd::Identity(n, n);
  const MatrixXd L = kron(I, F.transpose()) + kron(F.transpose(), I);
  const Eigen::VectorXd w = Eigen::Map<const Eigen::VectorXd>(W.data(), n * n);
  const Eigen::VectorXd x = L.fullPivLu().solve(-w);
  MatrixXd X = Eigen::Map<const MatrixXd>(x.data(), n, n);
  return 0.5 * (X + X.transpose());
}

// Bass's stabilising gain: with beta > max(0, -min Re(lambda(A))), Z > 0 solving
// (A + beta I) Z + Z (A + beta I)^T = 2 B B^T gives (A - B K) Z + Z (A - B K)^T = -2 beta Z for
// K = B^T Z^-1, so A - B K is Hurwitz (all poles left of -beta) when (A, B) is controllable.
// beta is kept just above its bound: a larger shift makes Z ill-conditioned and K_0 huge, and
// Kleinman's iteration from a huge gain loses its (exact-arithmetic) stability to rounding.
MatrixXd bass_gain(const MatrixXd& A, const MatrixXd& B) {
  const auto n = A.rows();
  const double min_re = Eigen::EigenSolver<MatrixXd>(A, false).eigenvalues().real().minCoeff();
  const double beta = std::max(0.0, -min_re) + 0.5;
  const MatrixXd M = A + beta * MatrixXd::Identity(n, n);
  // M Z + Z M^T = 2 B B^T is the Lyapunov form above with F = M^T and W = -2 B B^T.
  const MatrixXd Z = lyapunov(M.transpose(), -2.0 * B * B.transpose());
  return B.transpose() * Z.inverse();
}

struct KleinmanResult {
  MatrixXd X;
  int iterations = 0;
  bool converged = false;
};

// Kleinman (1968): K_0 stabilising; (A - B K_k)^T X_k + X_k (A - B K_k) + Q + K_k^T R K_k = 0,
// K_{k+1} = R^-1 B^T X_k. Converges monotonically (quadratically near the end) to the stabilising X.
// Stops one iteration after the step falls below 1e-10 relative: quadratic convergence puts that
// last iterate at the rounding floor (~1e-12 here; asking for less than the floor never ends).
KleinmanResult kleinman(const MatrixXd& A, const MatrixXd& B, const MatrixXd& Q, const MatrixXd& R, MatrixXd K) {
  KleinmanResult out;
  MatrixXd X_prev;
  bool small_step = false;
  for (int it = 0; it < 200; ++it) {
    const MatrixXd F = A - B * K;
    if (!(spectral_abscissa(F) < 0.0)) return out;  // lost stability: cannot happen in exact arithmetic
    const MatrixXd X = lyapunov(F, Q + K.transpose() * R * K);
    K = R.fullPivLu().solve(B.transpose() * X);
    out.iterations = it + 1;
    out.X = X;
    if (small_step) {
      out.converged = true;
      return out;
    }
    small_step = it > 0 && (X - X_prev).norm() <= 1e-10 * X.norm();
    X_prev = X;
  }
  return out;
}

TEST(CareRandom, ResidualDefinitenessStabilityAndKleinmanAgree) {
  int systems = 0;
  for (int n = 2; n <= 8; ++n) {
    for (int m = 1; m <= 3; ++m) {
      for (std::uint64_t seed : {1u, 2u, 3u}) {
        SCOPED_TRACE(testing::Message() << "n=" << n << " m=" << m << " seed=" << seed);
        std::mt19937_64 g(1000 * seed + 10 * n + m);
        const MatrixXd A = random_matrix(g, n, n, 1.5);
        const MatrixXd B = random_matrix(g, n, m);
        const MatrixXd C = random_matrix(g, n, n);
        const MatrixXd Q = C.transpose() * C + 1e-3 * MatrixXd::Identity(n, n);
        const MatrixXd L = random_matrix(g, m, m);
        const MatrixXd R = L * L.transpose() + 0.1 * MatrixXd::Identity(m, m);

        const MatrixXd X = solve_care(A, B, Q, R);
        ASSERT_EQ(X.rows(), n);
        ASSERT_EQ(X.cols(), n);
        ASSERT_TRUE(X.allFinite());

        // Residual, evaluated here. Against the backward-error scale it must be at the rounding
        // level, n eps ~ 2e-15 (observed <= 3e-16 on these systems; bound 1e-14). Against the
        // terms as they stand (which cancel in A^T X + X A for the worse-conditioned systems) the
        // observed worst is 2e-11 (n = 7, nearly uncontrollable); bound 1e-9. A wrong X scores O(1)
        // there: 0.75 for the undamped uncontrollable oscillator the solver used to return.
        const Residual res = riccati_residual(A, B, Q, R, X);
        EXPECT_LE(res.rel_bound(), kResidualBound) << "abs " << res.abs << " scale " << res.bound_scale;
        EXPECT_LE(res.rel(), kResidualTerms) << "abs " << res.abs << " scale " << res.scale;
        // The library's own residual agrees with ours.
        EXPECT_NEAR(care_residual(A, B, Q, R, X), res.abs, 1e-9 * res.scale);

        // Symmetric, positive (semi)definite: Q > 0 makes X > 0.
        EXPECT_LE((X - X.transpose()).norm(), 1e-14 * X.norm());
        const double min_eig = Eigen::SelfAdjointEigenSolver<MatrixXd>(X).eigenvalues().minCoeff();
        EXPECT_GT(min_eig, -1e-12 * X.norm());

        // The LQR gain stabilises.
        const MatrixXd K = lqr_gain(A, B, Q, R);
        ASSERT_EQ(K.rows(), m);
        ASSERT_EQ(K.cols(), n);
        EXPECT_LT(spectral_abscissa(A - B * K), 0.0);
        // and is R^-1 B^T X (computed here with LU).
        const MatrixXd K_from_X = R.fullPivLu().solve(B.transpose() * X);
        EXPECT_LE((K - K_from_X).norm(), 1e-10 * (1.0 + K_from_X.norm()));

        // Second method: Kleinman from Bass's gain.
        const MatrixXd K0 = bass_gain(A, B);
        ASSERT_LT(spectral_abscissa(A - B * K0), 0.0) << "Bass's gain must stabilise (test setup)";
        const KleinmanResult kl = kleinman(A, B, Q, R, K0);
        ASSERT_TRUE(kl.converged) << "Kleinman stopped after " << kl.iterations << " iterations";
        // Two different O(eps cond) solutions of the same problem: observed worst 6e-10 (the same
        // nearly uncontrollable n = 7 system); bound 1e-8.
        EXPECT_LE((kl.X - X).norm(), 1e-8 * X.norm()) << "Kleinman X:\n" << kl.X << "\nsolve_care X:\n" << X;
        ++systems;
      }
    }
  }
  EXPECT_EQ(systems, 7 * 3 * 3);
}

// An uncontrollable but lightly damped mode (poles -d/2 +- i sqrt(1 - d^2/4)) is stabilisable: the
// stabilising X exists (large, ~1/d) and must be found, not refused. K_0 = 0 already stabilises.
TEST(CareRandom, LightlyDampedUncontrollableModeIsSolved) {
  for (double coupling : {0.0, 0.5}) {
    for (double d : {1e-1, 1e-3}) {
      SCOPED_TRACE(testing::Message() << "d=" << d << " coupling=" << coupling);
      // State 3 (the controlled one) is driven by the oscillator when coupling != 0.
      const MatrixXd A = mat(3, 3, {0, 1, 0, -1, -d, 0, coupling, 0, -1});
      const MatrixXd B = mat(3, 1, {0, 0, 1});
      const MatrixXd Q = MatrixXd::Identity(3, 3);
      const MatrixXd R = scalar(1);
      const MatrixXd X = solve_care(A, B, Q, R);
      EXPECT_LE(riccati_residual(A, B, Q, R, X).rel_bound(), kResidualBound);
      EXPECT_LE(riccati_residual(A, B, Q, R, X).rel(), kResidualTerms);
      const KleinmanResult kl = kleinman(A, B, Q, R, MatrixXd::Zero(1, 3));
      ASSERT_TRUE(kl.converged);
      EXPECT_LE((kl.X - X).norm(), 1e-8 * X.norm());
      if (coupling == 0.0) {
        // Decoupled: the oscillator block is the Lyapunov solution of A11 alone, whose (1,1) entry is
        // (2 + d^2)/(2 d) by hand (A11 = [0 1; -1 -d], Q11 = I), and the third state the scalar case
        // a = -1, b = q = r = 1: x = sqrt(2) - 1.
        EXPECT_NEAR(X(0, 0), (2.0 + d * d) / (2.0 * d), 1e-9 * X(0, 0));
        EXPECT_NEAR(X(0, 1), 0.5, 1e-9 * X(0, 0));
        EXPECT_NEAR(X(1, 1), 1.0 / d, 1e-9 * X(0, 0));
        EXPECT_NEAR(X(2, 2), std::sqrt(2.0) - 1.0, 1e-9);
      }
    }
  }
}

// A lightly damped, badly scaled plant (two oscillators with very different stiffness) still solves
// to a small residual and agrees with Kleinman.
TEST(CareRandom, OscillatorsOfDifferentScale) {
  const MatrixXd A = mat(4, 4,
                         {0, 1, 0, 0,          //
                          -1e-2, -1e-3, 0, 0,  //
                          0, 0, 0, 1,          //
                          0, 0, -1e2, 1e-3});  // unstable: negative damping
  const MatrixXd B = mat(4, 2, {0, 0, 1, 0, 0, 0, 0.5, 1});
  const MatrixXd Q = MatrixXd::Identity(4, 4);
  const MatrixXd R = mat(2, 2, {2, 0.5, 0.5, 1});
  const MatrixXd X = solve_care(A, B, Q, R);
  EXPECT_LE(riccati_residual(A, B, Q, R, X).rel_bound(), kResidualBound);
  EXPECT_LE(riccati_residual(A, B, Q, R, X).rel(), kResidualTerms);
  const KleinmanResult kl = kleinman(A, B, Q, R, bass_gain(A, B));
  ASSERT_TRUE(kl.converged);
  EXPECT_LE((kl.X - X).norm(), 1e-8 * X.norm());
}

// ---------------------------------------------------------------------------------------------------
// Bad input.

TEST(CareErrors, NotStabilisable) {
  // Unstable mode x1' = x1 with no input in that direction.
  const MatrixXd A = mat(2, 2, {1, 0, 0, -2});
  const MatrixXd Q = MatrixXd::Identity(2, 2);
  const MatrixXd R = scalar(1);
  expect_care_error([&] { solve_care(A, mat(2, 1, {0, 1}), Q, R); }, {"stabilis"}, "B = [0; 1]");
  expect_care_error([&] { lqr_gain(A, mat(2, 1, {0, 1}), Q, R); }, {"stabilis"}, "lqr_gain");
  expect_care_error([&] { solve_care(A, mat(2, 1, {0, 0}), Q, R); }, {"stabilis"}, "B = 0");
  // Coupled: A upper triangular with the unstable mode upstream of the input.
  expect_care_error(
      [&] {
        solve_care(mat(2, 2, {0.5, 0, 1, -1}), mat(2, 1, {0, 1}), Q, R);
      },
      {"stabilis"}, "unstable mode feeds the controlled one");
  // An uncontrollable mode on the imaginary axis: x' = 0, B = 0.
  expect_care_error([&] { solve_care(scalar(0), scalar(0), scalar(1), scalar(1)); }, {"stabilis"}, "marginal, B = 0");
  // An uncontrollable undamped oscillator (eigenvalues +-i w): feedback cannot move it, so there is
  // no stabilising solution, whatever Q weights.
  for (double w : {1.0, 2.0, 0.3}) {
    const MatrixXd Ao = mat(3, 3, {0, w, 0, -w, 0, 0, 0, 0, -1});
    const MatrixXd Bo = mat(3, 1, {0, 0, 1});
    expect_care_error([&] { solve_care(Ao, Bo, MatrixXd::Identity(3, 3), R); }, {"stabilis"},
                      "uncontrollable oscillator, Q = I, w = " + std::to_string(w));
    expect_care_error(
        [&] {
          solve_care(Ao, Bo, mat(3, 3, {0, 0, 0, 0, 0, 0, 0, 0, 1}), R);
        },
        {"stabilis"}, "uncontrollable oscillator, Q = 0 on it, w = " + std::to_string(w));
    // The same plant in rotated coordinates (T orthogonal), so the structure is not visible.
    const Eigen::Matrix3d T = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
    expect_care_error([&] { solve_care(T * Ao * T.transpose(), T * Bo, MatrixXd::Identity(3, 3), R); }, {"stabilis"},
                      "rotated uncontrollable oscillator, w = " + std::to_string(w));
  }
}

TEST(CareErrors, RNotPositiveDefinite) {
  const MatrixXd A = mat(2, 2, {0, 1, 0, 0});
  const MatrixXd B1 = mat(2, 1, {0, 1});
  const MatrixXd B2 = MatrixXd::Identity(2, 2);
  const MatrixXd Q = MatrixXd::Identity(2, 2);
  expect_care_error([&] { solve_care(A, B1, Q, scalar(0)); }, {"R", "positive definite"}, "R = 0");
  expect_care_error([&] { solve_care(A, B1, Q, scalar(-1)); }, {"R", "positive definite"}, "R = -1");
  expect_care_error([&] { solve_care(A, B2, Q, mat(2, 2, {1, 2, 2, 1})); }, {"R", "positive definite"}, "R indefinite");
  expect_care_error([&] { solve_care(A, B2, Q, mat(2, 2, {1, 0.5, 0, 1})); }, {"R", "symmetric"}, "R not symmetric");
  expect_care_error(
      [&] {
        solve_care(A, B1, mat(2, 2, {1, 0, 0, -1}), scalar(1));
      },
      {"Q", "positive semidefinite"}, "Q indefinite");
  expect_care_error(
      [&] {
        solve_care(A, B1, mat(2, 2, {1, 1, 0, 1}), scalar(1));
      },
      {"Q", "symmetric"}, "Q not symmetric");
}

TEST(CareErrors, MismatchedSizes) {
  const MatrixXd A = mat(2, 2, {0, 1, 0, 0});
  const MatrixXd B = mat(2, 1, {0, 1});
  const MatrixXd Q = MatrixXd::Identity(2, 2);
  const MatrixXd R = scalar(1);
  expect_care_error([&] { solve_care(mat(2, 3, {0, 1, 0, 0, 0, 0}), B, Q, R); }, {"A", "2x3"}, "A not square");
  expect_care_error([&] { solve_care(MatrixXd(0, 0), MatrixXd(0, 1), MatrixXd(0, 0), R); }, {"A"}, "empty A");
  expect_care_error([&] { solve_care(A, mat(3, 1, {0, 1, 0}), Q, R); }, {"B", "3x1"}, "B rows");
  expect_care_error([&] { solve_care(A, MatrixXd(2, 0), Q, MatrixXd(0, 0)); }, {"B", "2x0"}, "B no columns");
  expect_care_error([&] { solve_care(A, B, MatrixXd::Identity(3, 3), R); }, {"Q", "3x3"}, "Q size");
  expect_care_error([&] { solve_care(A, B, Q, MatrixXd::Identity(2, 2)); }, {"R", "2x2"}, "R size");
  expect_care_error([&] { lqr_gain(A, B, Q, MatrixXd::Identity(2, 2)); }, {"R", "2x2"}, "lqr_gain R size");
}

TEST(CareErrors, NonFiniteInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const MatrixXd A = mat(2, 2, {0, 1, 0, 0});
  const MatrixXd B = mat(2, 1, {0, 1});
  const MatrixXd Q = MatrixXd::Identity(2, 2);
  const MatrixXd R = scalar(1);
  for (double bad : {nan, inf, -inf}) {
    SCOPED_TRACE(testing::Message() << "bad=" << bad);
    MatrixXd A1 = A, B1 = B, Q1 = Q, R1 = R;
    A1(1, 0) = bad;
    B1(0, 0) = bad;
    Q1(0, 0) = bad;
    R1(0, 0) = bad;
    expect_care_error([&] { solve_care(A1, B, Q, R); }, {"finite"}, "A");
    expect_care_error([&] { solve_care(A, B1, Q, R); }, {"finite"}, "B");
    expect_care_error([&] { solve_care(A, B, Q1, R); }, {"finite"}, "Q");
    expect_care_error([&] { solve_care(A, B, Q, R1); }, {"finite"}, "R");
    expect_care_error([&] { lqr_gain(A1, B, Q, R); }, {"finite"}, "lqr_gain A");
  }
}

// ---------------------------------------------------------------------------------------------------
// The attitude axis of eq. (14): x = [e, rate], e' = -rate, rate' = U / I.
//
// Same algebra as the double integrator with the first state negated: the stabilising X has
// x2 = -sqrt(q1 r) I, so K = [-sqrt(q1/r), sqrt(q2/r + 2 I sqrt(q1/r))], i.e. in Algorithm 1's
// notation k1 = -K(0) = sqrt(q1/r) and k2 = K(1) = sqrt(q2/r + 2 I k1).
// With U = -K x and e = phi_des - phi: I phi'' = k1 (phi_des - phi) - k2 phi', i.e.
// I phi'' + k2 phi' + k1 phi = k1 phi_des, poles (-k2 +- sqrt(k2^2 - 4 I k1)) / (2 I),
// damping ratio zeta = k2 / (2 sqrt(I k1)).

struct AxisCase {
  const char* name;
  double inertia;
  LqrWeights w;
};

std::vector<AxisCase> default_axes() {
  const quadcosim::model::VehicleParams v;
  const quadcosim::controllers::PaperParams p;
  return {{"roll", v.Ixx_kg_m2, p.roll}, {"pitch", v.Iyy_kg_m2, p.pitch}, {"yaw", v.Izz_kg_m2, p.yaw}};
}

// Poles of I s^2 + k2 s + k1, sorted by real part then imaginary part.
std::vector<std::complex<double>> second_order_poles(double I, double k1, double k2) {
  const std::complex<double> disc = std::sqrt(std::complex<double>(k2 * k2 - 4.0 * I * k1, 0.0));
  std::vector<std::complex<double>> p = {(-k2 - disc) / (2.0 * I), (-k2 + disc) / (2.0 * I)};
  return p;
}

void sort_poles(std::vector<std::complex<double>>& p) {
  std::sort(p.begin(), p.end(),
            [](auto a, auto b) { return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag(); });
}

TEST(AxisLqr, GainMatchesClosedFormAndPolesFollowFromIt) {
  std::vector<AxisCase> cases = default_axes();
  cases.push_back({"light, underdamped", 0.01, {100.0, 0.0, 1.0}});
  cases.push_back({"heavy", 2.0, {0.5, 3.0, 0.01}});
  cases.push_back({"no rate weight", 0.0153, {1.0, 0.0, 10.0}});
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const AxisLqr d = design_axis_lqr(c.inertia, c.w);
    // The plant of eq. (14), written out.
    EXPECT_EQ(d.A, (Eigen::Matrix2d() << 0, -1, 0, 0).finished());
    EXPECT_NEAR(d.B(0), 0.0, 0.0);
    EXPECT_NEAR(d.B(1), 1.0 / c.inertia, 1e-15 / c.inertia);
    EXPECT_EQ(d.R, c.w.r);

    const double k1 = std::sqrt(c.w.q_angle / c.w.r);
    const double k2 = std::sqrt(c.w.q_rate / c.w.r + 2.0 * c.inertia * k1);
    EXPECT_NEAR(-d.K(0), k1, 1e-10 * k1);
    EXPECT_NEAR(d.K(1), k2, 1e-10 * k2);
    // Algorithm 1 sign convention: k1 = -K(0) > 0 and k2 = K(1) > 0.
    EXPECT_GT(-d.K(0), 0.0);
    EXPECT_GT(d.K(1), 0.0);

    // Poles derived here from the design's own K through the second-order closed loop.
    auto expected = second_order_poles(c.inertia, -d.K(0), d.K(1));
    std::vector<std::complex<double>> got = {d.closed_loop_poles(0), d.closed_loop_poles(1)};
    sort_poles(expected);
    sort_poles(got);
    const double scale = std::abs(expected[0]) + std::abs(expected[1]);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(got[i].real(), expected[i].real(), 1e-9 * scale);
      EXPECT_NEAR(got[i].imag(), expected[i].imag(), 1e-9 * scale);
      EXPECT_LT(got[i].real(), 0.0);
    }

    // torque() is U = -K x: k1 e - k2 rate.
    EXPECT_NEAR(d.torque(0.1, 0.0), k1 * 0.1, 1e-10 * k1);
    EXPECT_NEAR(d.torque(0.0, 0.3), -k2 * 0.3, 1e-10 * k2);
  }
}

TEST(AxisLqr, DefaultWeightsGiveRealOverdampedPoles) {
  for (const auto& c : default_axes()) {
    SCOPED_TRACE(c.name);
    const AxisLqr d = design_axis_lqr(c.inertia, c.w);
    const double k1 = -d.K(0), k2 = d.K(1);
    ASSERT_GT(k1, 0.0);
    ASSERT_GT(k2, 0.0);
    const double zeta = k2 / (2.0 * std::sqrt(c.inertia * k1));
    EXPECT_GE(zeta, 1.0) << "overshoot: the paper's step responses have none";
    // Real poles: the discriminant is non-negative and the solver reports no imaginary part.
    EXPECT_GE(k2 * k2 - 4.0 * c.inertia * k1, 0.0);
    for (int i = 0; i < 2; ++i) {
      EXPECT_LE(std::abs(d.closed_loop_poles(i).imag()), 1e-12 * std::abs(d.closed_loop_poles(i)));
      EXPECT_LT(d.closed_loop_poles(i).real(), 0.0);
    }
  }
}

// Simulates I phi'' = torque(phi_des - phi, phi') (RK4, 1 ms) for a step of 0.1 rad: it must settle on
// the setpoint with no overshoot. This checks the sign convention end to end, not just K.
TEST(AxisLqr, DefaultStepResponseSettlesWithoutOvershoot) {
  for (const auto& c : default_axes()) {
    SCOPED_TRACE(c.name);
    const AxisLqr d = design_axis_lqr(c.inertia, c.w);
    const double des = 0.1, h = 1e-3;
    auto f = [&](const Eigen::Vector2d& s) { return Eigen::Vector2d(s(1), d.torque(des - s(0), s(1)) / c.inertia); };
    Eigen::Vector2d s = Eigen::Vector2d::Zero();
    double peak = 0.0;
    for (int i = 0; i < 30000; ++i) {  // 30 s
      const Eigen::Vector2d a = f(s), b = f(s + 0.5 * h * a), cc = f(s + 0.5 * h * b), e = f(s + h * cc);
      s += h / 6.0 * (a + 2.0 * b + 2.0 * cc + e);
      peak = std::max(peak, s(0));
    }
    EXPECT_LE(peak, des * (1.0 + 1e-9));
    EXPECT_NEAR(s(0), des, 1e-4 * des);
  }
}

TEST(AxisLqr, InvalidDesignsThrow) {
  expect_care_error([] { design_axis_lqr(0.0, {}); }, {"inertia"}, "I = 0");
  expect_care_error([] { design_axis_lqr(-1.0, {}); }, {"inertia"}, "I < 0");
  expect_care_error([] { design_axis_lqr(std::nan(""), {}); }, {"inertia"}, "I nan");
  expect_care_error([] { design_axis_lqr(0.01, {1.0, 1.0, 0.0}); }, {"positive definite"}, "r = 0");
  expect_care_error([] { design_axis_lqr(0.01, {1.0, 1.0, -2.0}); }, {"positive definite"}, "r < 0");
  expect_care_error([] { design_axis_lqr(0.01, {-1.0, 1.0, 1.0}); }, {"positive semidefinite"}, "q < 0");
  // No weight on the angle error: the angle mode is unobservable in the cost and sits at s = 0, so no
  // stabilising solution exists.
  expect_care_error([] { design_axis_lqr(0.01, {0.0, 1.0, 1.0}); }, {"stabilis"}, "q_angle = 0");
}

}  // namespace
