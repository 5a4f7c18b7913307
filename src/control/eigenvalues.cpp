#include "control/eigenvalues.hpp"

#include <Eigen/Eigenvalues>

namespace quadcosim::control {

Eigen::VectorXcd eigenvalues(const Eigen::MatrixXd& a) {
  if (a.size() == 0) return {};
  return Eigen::EigenSolver<Eigen::MatrixXd>(a, false).eigenvalues();
}

double spectral_radius(const Eigen::MatrixXd& a) {
  if (a.size() == 0) return 0.0;
  return eigenvalues(a).cwiseAbs().maxCoeff();
}

}  // namespace quadcosim::control
