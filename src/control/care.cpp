#include "control/care.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "control/eigenvalues.hpp"

namespace quadcosim::control {

namespace {

std::string dims(const Eigen::MatrixXd& M) { return std::to_string(M.rows()) + "x" + std::to_string(M.cols()); }

void check_inputs(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                  const Eigen::MatrixXd& R) {
  const auto n = A.rows(), m = B.cols();
  if (n == 0 || A.cols() != n) throw CareError("CARE: A must be square and non-empty, got " + dims(A));
  if (B.rows() != n || m == 0) throw CareError("CARE: B must be " + std::to_string(n) + "xm, got " + dims(B));
  if (Q.rows() != n || Q.cols() != n) throw CareError("CARE: Q must be " + dims(A) + ", got " + dims(Q));
  if (R.rows() != m || R.cols() != m) {
    throw CareError("CARE: R must be " + std::to_string(m) + "x" + std::to_string(m) + ", got " + dims(R));
  }
  for (const auto* M : {&A, &B, &Q, &R}) {
    if (!M->allFinite()) throw CareError("CARE: matrices must be finite");
  }
  if ((Q - Q.transpose()).norm() > 1e-12 * (1.0 + Q.norm())) throw CareError("CARE: Q must be symmetric");
  if ((R - R.transpose()).norm() > 1e-12 * (1.0 + R.norm())) throw CareError("CARE: R must be symmetric");
  Eigen::LLT<Eigen::MatrixXd> llt(R);
  if (llt.info() != Eigen::Success) throw CareError("CARE: R must be positive definite");
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> qe(Q);
  if (qe.eigenvalues().minCoeff() < -1e-12 * (1.0 + Q.norm())) {
    throw CareError("CARE: Q must be positive semidefinite");
  }
}

}  // namespace

Eigen::MatrixXd solve_care(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                           const Eigen::MatrixXd& R) {
  check_inputs(A, B, Q, R);
  const auto n = A.rows();
  const Eigen::MatrixXd G = B * R.llt().solve(B.transpose());

  Eigen::MatrixXd Z(2 * n, 2 * n);
  Z << A, -G, -Q, -A.transpose();

  // Newton iteration for sign(Z): Z <- (Z/c + c Z^-1) / 2, c = |det Z|^(1/2n).
  constexpr int kMaxIterations = 100;
  bool converged = false;
  for (int it = 0; it < kMaxIterations; ++it) {
    Eigen::PartialPivLU<Eigen::MatrixXd> lu(Z);
    const double logdet = lu.matrixLU().diagonal().array().abs().log().sum();
    if (!std::isfinite(logdet)) {
      throw CareError(
          "CARE: the Hamiltonian is singular (eigenvalue on the imaginary axis); "
          "(A, B) is not stabilisable or (Q, A) not detectable");
    }
    const double c = std::exp(logdet / static_cast<double>(2 * n));
    const Eigen::MatrixXd Znext = 0.5 * (Z / c + c * lu.inverse());
    const double change = (Znext - Z).norm();
    Z = Znext;
    if (!Z.allFinite()) break;
    if (change <= 1e-13 * Z.norm()) {
      converged = true;
      break;
    }
  }
  if (!converged) {
    throw CareError(
        "CARE: sign iteration did not converge (eigenvalues near the imaginary axis); "
        "(A, B) is not stabilisable or (Q, A) not detectable");
  }

  // With W = sign(H): [W12; W22 + I] X = -[W11 + I; W21].
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd lhs(2 * n, n), rhs(2 * n, n);
  lhs << Z.topRightCorner(n, n), Z.bottomRightCorner(n, n) + I;
  rhs << Z.topLeftCorner(n, n) + I, Z.bottomLeftCorner(n, n);
  Eigen::MatrixXd X = lhs.colPivHouseholderQr().solve(-rhs);
  X = 0.5 * (X + X.transpose()).eval();

  if (!X.allFinite()) throw CareError("CARE: no finite solution");
  const Eigen::MatrixXd Acl = A - G * X;
  const Eigen::VectorXcd poles = eigenvalues(Acl);
  // Computed eigenvalues carry rounding errors of order eps ||Acl|| (times their condition number):
  // a pole closer to the imaginary axis than this margin cannot be told from one on it (e.g. an
  // uncontrollable undamped mode, which feedback cannot move), so it does not count as stable.
  const double margin = 1e-10 * (1.0 + Acl.norm());
  if (poles.real().maxCoeff() >= -margin) {
    throw CareError("CARE: the solution does not stabilise the system; (A, B) is not stabilisable");
  }
  return X;
}

Eigen::MatrixXd lqr_gain(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                         const Eigen::MatrixXd& R) {
  const Eigen::MatrixXd X = solve_care(A, B, Q, R);
  return R.llt().solve(B.transpose() * X);
}

double care_residual(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const Eigen::MatrixXd& X) {
  const Eigen::MatrixXd G = B * R.llt().solve(B.transpose());
  return (A.transpose() * X + X * A - X * G * X + Q).norm();
}

}  // namespace quadcosim::control
