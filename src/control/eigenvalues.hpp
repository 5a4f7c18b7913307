// Eigenvalues of a real square matrix, for the one-off design and analysis code (the CARE's check,
// the LQR designs' poles, the inner loops' check, the loop margins). One function compiled once in
// quadcosim_design: Eigen's eigen-solver (Schur and Hessenberg decompositions, Householder
// sequences) is the heaviest template code of the build, and every unit that instantiated it paid a
// few CPU seconds of compile time for it (docs/performance.md, "Build time").
#pragma once

#include <Eigen/Core>

namespace quadcosim::control {

/// The eigenvalues of the square matrix `a` (Eigen::EigenSolver, eigenvalues only), in the solver's
/// order; empty for a 0 x 0 matrix.
Eigen::VectorXcd eigenvalues(const Eigen::MatrixXd& a);

/// The largest |eigenvalue| of the square matrix `a` (0 for a 0 x 0 matrix).
double spectral_radius(const Eigen::MatrixXd& a);

}  // namespace quadcosim::control
