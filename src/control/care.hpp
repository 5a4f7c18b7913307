// Continuous-time algebraic Riccati equation and the LQR gain built on it.
#pragma once

#include <Eigen/Core>
#include <stdexcept>

namespace quadcosim::control {

/// Thrown when (A, B, Q, R) has no stabilising solution or the input is malformed.
class CareError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Solves A^T X + X A - X B R^-1 B^T X + Q = 0 for the symmetric stabilising X (A - B R^-1 B^T X
/// Hurwitz). A is n x n, B n x m, Q n x n symmetric positive semidefinite, R m x m symmetric positive
/// definite; any n, m. Method: the matrix sign function of the Hamiltonian
/// H = [A, -B R^-1 B^T; -Q, -A^T] (Newton iteration with determinant scaling, Byers 1987), then the
/// stable invariant subspace by least squares. Throws CareError when the sizes disagree, R is not
/// positive definite, or H has eigenvalues on the imaginary axis ((A, B) not stabilisable or
/// (Q, A) not detectable there).
Eigen::MatrixXd solve_care(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                           const Eigen::MatrixXd& R);

/// The LQR gain K = R^-1 B^T X for u = -K x minimising the integral of x^T Q x + u^T R u.
Eigen::MatrixXd lqr_gain(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                         const Eigen::MatrixXd& R);

/// Frobenius norm of the Riccati residual A^T X + X A - X B R^-1 B^T X + Q.
double care_residual(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const Eigen::MatrixXd& X);

}  // namespace quadcosim::control
