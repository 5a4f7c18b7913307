#include "trajectory/waypoints.hpp"

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <cmath>
#include <stdexcept>
#include <string>

#include "model/angle.hpp"

namespace quadcosim::trajectory {

namespace {

/// r-th derivative of u^j at u = 1 (j! / (j - r)!), or at u = 0 (r! when j == r).
double falling(int j, int r) {
  double f = 1;
  for (int m = 0; m < r; ++m) f *= j - m;
  return f;
}

/// Coefficients (seconds-based, per segment, columns 0..2k-1) of the spline of degree 2k - 1 through
/// values(i, :) at the waypoints, C^(2k-2) inside, derivatives 1..k-1 zero at the ends.
std::vector<Eigen::MatrixXd> spline(const std::vector<double>& durations, const Eigen::MatrixXd& values, int k) {
  const int M = static_cast<int>(durations.size());
  const int n = 2 * k;
  const int N = n * M;
  const int dims = static_cast<int>(values.cols());
  std::vector<Eigen::Triplet<double>> a;
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(N, dims);
  int row = 0;
  auto var = [&](int seg, int j) { return seg * n + j; };
  for (int i = 0; i < M; ++i) {  // p_i(0) = w_i, p_i(1) = w_i+1 (u = tau / T_i)
    a.emplace_back(row, var(i, 0), 1.0);
    b.row(row++) = values.row(i);
    for (int j = 0; j < n; ++j) a.emplace_back(row, var(i, j), 1.0);
    b.row(row++) = values.row(i + 1);
  }
  for (int i = 0; i + 1 < M; ++i) {  // h^r (T_i^-r p_i^(r)(1) - T_i+1^-r p_i+1^(r)(0)) = 0, h the mean duration
    const double h = 0.5 * (durations[i] + durations[i + 1]);
    for (int r = 1; r <= n - 2; ++r) {
      const double left = std::pow(h / durations[i], r), right = std::pow(h / durations[i + 1], r);
      for (int j = r; j < n; ++j) a.emplace_back(row, var(i, j), left * falling(j, r));
      a.emplace_back(row, var(i + 1, r), -right * falling(r, r));
      ++row;
    }
  }
  for (int r = 1; r < k; ++r) {  // at rest at both ends
    a.emplace_back(row++, var(0, r), 1.0);
    for (int j = r; j < n; ++j) a.emplace_back(row, var(M - 1, j), falling(j, r));
    ++row;
  }
  Eigen::SparseMatrix<double> A(N, N);
  A.setFromTriplets(a.begin(), a.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  lu.compute(A);
  if (lu.info() != Eigen::Success) throw std::invalid_argument("waypoint spline: singular system");
  const Eigen::MatrixXd x = lu.solve(b);
  std::vector<Eigen::MatrixXd> out;
  for (int i = 0; i < M; ++i) {
    Eigen::MatrixXd c(dims, n);
    for (int j = 0; j < n; ++j) c.col(j) = x.row(var(i, j)).transpose() / std::pow(durations[i], j);
    out.push_back(c);
  }
  return out;
}

}  // namespace

const char* method_name(WaypointMethod method) { return method == WaypointMethod::kMinSnap ? "min_snap" : "min_jerk"; }

PiecewisePolynomial plan_waypoints(const std::vector<Waypoint>& w, WaypointMethod method) {
  if (w.size() < 2) throw std::invalid_argument("at least two waypoints are needed");
  const int N = static_cast<int>(w.size());
  std::vector<double> durations;
  Eigen::MatrixXd p(N, 3), yaw(N, 1);
  for (int i = 0; i < N; ++i) {
    const Waypoint& e = w[static_cast<std::size_t>(i)];
    const std::string where = "waypoint " + std::to_string(i) + ": ";
    if (!std::isfinite(e.t_s)) throw std::invalid_argument(where + "time is not finite");
    if (!e.p_W.allFinite()) throw std::invalid_argument(where + "position is not finite");
    if (e.yaw_rad && !std::isfinite(*e.yaw_rad)) throw std::invalid_argument(where + "yaw is not finite");
    p.row(i) = e.p_W.transpose();
    const double previous = i == 0 ? 0.0 : yaw(i - 1, 0);
    yaw(i, 0) = e.yaw_rad ? (i == 0 ? *e.yaw_rad : previous + model::wrap_pi(*e.yaw_rad - previous)) : previous;
    if (i > 0) {
      const double d = e.t_s - w[static_cast<std::size_t>(i - 1)].t_s;
      if (!(d > 0)) throw std::invalid_argument(where + "time must be after the previous waypoint's");
      durations.push_back(d);
    }
  }
  const int k = method == WaypointMethod::kMinSnap ? 4 : 3;
  const auto xyz = spline(durations, p, k);
  const auto psi = spline(durations, yaw, 3);
  std::vector<PiecewisePolynomial::Segment> segments;
  for (std::size_t i = 0; i < durations.size(); ++i) {
    PiecewisePolynomial::Segment s;
    s.duration_s = durations[i];
    s.c.topLeftCorner(3, 2 * k) = xyz[i];
    s.c.row(3).head(6) = psi[i].row(0);
    segments.push_back(s);
  }
  return PiecewisePolynomial(std::move(segments), w.front().t_s,
                             std::string(method_name(method)) + " through " + std::to_string(N) + " waypoints");
}

}  // namespace quadcosim::trajectory
