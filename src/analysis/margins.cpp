#include "analysis/margins.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>

#include "control/eigenvalues.hpp"
#include "model/angle.hpp"

namespace quadcosim::analysis {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Frequency response of one state-space system at many frequencies, C (lambda I - A)^-1 B + D with
// lambda = j omega (continuous) or exp(j omega period) (discrete), outputs x inputs (a pole exactly
// at omega gives non-finite entries): A is reduced once to upper Hessenberg form, so each frequency
// costs one O(n^2) solve (delay lines make n large).
class ResponseEvaluator {
 public:
  explicit ResponseEvaluator(const StateSpace& sys) : sys_(sys) {
    const Eigen::Index n = sys.A.rows();
    if (n > 0) {
      Eigen::HessenbergDecomposition<Eigen::MatrixXd> hd(sys.A);
      const Eigen::MatrixXd Q = hd.matrixQ();
      H_ = hd.matrixH();
      B_ = Q.transpose() * sys.B;
      C_ = sys.C * Q;
    }
  }

  Eigen::MatrixXcd operator()(double omega) const {
    const std::complex<double> lambda =
        sys_.discrete() ? std::polar(1.0, omega * sys_.period_s) : std::complex<double>(0.0, omega);
    Eigen::MatrixXcd G = sys_.D.cast<std::complex<double>>();
    const Eigen::Index n = H_.rows();
    if (n == 0) return G;
    // (lambda I - H) X = B, H upper Hessenberg: Gaussian elimination with row pivoting between
    // neighbours (the only sub-diagonal entry of column k is in row k+1).
    Eigen::MatrixXcd M = -H_.cast<std::complex<double>>();
    M.diagonal().array() += lambda;
    Eigen::MatrixXcd X = B_.cast<std::complex<double>>();
    for (Eigen::Index k = 0; k + 1 < n; ++k) {
      if (std::abs(M(k + 1, k)) > std::abs(M(k, k))) {
        M.row(k).swap(M.row(k + 1));
        X.row(k).swap(X.row(k + 1));
      }
      if (M(k + 1, k) == 0.0) continue;
      const std::complex<double> l = M(k + 1, k) / M(k, k);
      M.row(k + 1).tail(n - k) -= l * M.row(k).tail(n - k);
      X.row(k + 1) -= l * X.row(k);
    }
    for (Eigen::Index k = n - 1; k >= 0; --k) {
      for (Eigen::Index j = k + 1; j < n; ++j) X.row(k) -= M(k, j) * X.row(j);
      X.row(k) /= M(k, k);  // a pole exactly at lambda: inf/nan, as documented
    }
    G += C_.cast<std::complex<double>>() * X;
    return G;
  }

 private:
  const StateSpace& sys_;
  Eigen::MatrixXd H_, B_, C_;
};

class LoopEvaluator {
 public:
  explicit LoopEvaluator(const Loop& loop) : plant_(loop.plant), controller_(loop.controller) {}
  std::complex<double> operator()(double omega) const { return -(controller_(omega) * plant_(omega))(0, 0); }

 private:
  ResponseEvaluator plant_, controller_;
};

void check_loop(const Loop& loop) {
  const StateSpace& p = loop.plant;
  const StateSpace& c = loop.controller;
  auto consistent = [](const StateSpace& s) {
    return s.A.rows() == s.A.cols() && s.B.rows() == s.A.rows() && s.C.cols() == s.A.rows() &&
           s.D.rows() == s.C.rows() && s.D.cols() == s.B.cols();
  };
  if (!consistent(p) || !consistent(c)) throw std::invalid_argument("loop: inconsistent state-space sizes");
  if (p.B.cols() != 1 || c.C.rows() != 1)
    throw std::invalid_argument("loop: the plant must have one input and the controller one output");
  if (c.B.cols() != p.C.rows())
    throw std::invalid_argument("loop: the controller's inputs must be the plant's outputs");
  if (p.period_s != c.period_s) throw std::invalid_argument("loop: plant and controller must share their time base");
}

// Strictly stable: a pole on the boundary (an integrator left open) is not.
bool stable_at(const Loop& loop, double gain) {
  const Eigen::VectorXcd p = closed_loop_poles(loop, gain);
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    const double m = loop.plant.discrete() ? std::abs(p(i)) - 1.0 : p(i).real();
    if (!(m < -1e-12)) return false;
  }
  return true;
}

std::vector<double> log_grid(double lo, double hi, int points) {
  std::vector<double> w(static_cast<std::size_t>(points));
  const double a = std::log(lo), b = std::log(hi);
  for (int i = 0; i < points; ++i) w[static_cast<std::size_t>(i)] = std::exp(a + (b - a) * i / (points - 1));
  w.back() = hi;
  return w;
}

std::pair<double, double> grid_bounds(const Loop& loop, const MarginOptions& o) {
  const double hi = o.omega_max_rad_s > 0.0 ? o.omega_max_rad_s
                    : loop.plant.discrete() ? kPi / loop.plant.period_s
                                            : 1e4;
  if (!(o.omega_min_rad_s > 0.0) || !(hi > o.omega_min_rad_s) || o.points < 2)
    throw std::invalid_argument("margins: the frequency grid needs 0 < omega_min < omega_max and >= 2 points");
  return {o.omega_min_rad_s, hi};
}

// Bisection in log frequency on a sign change of f between a and b.
template <class F>
double refine(F f, double a, double b) {
  double fa = f(a);
  for (int i = 0; i < 80; ++i) {
    const double m = std::sqrt(a * b);
    const double fm = f(m);
    if ((fm < 0) == (fa < 0)) {
      a = m;
      fa = fm;
    } else {
      b = m;
    }
  }
  return std::sqrt(a * b);
}

}  // namespace

StateSpace zoh_discretise(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C,
                          double period_s) {
  const Eigen::Index n = A.rows(), m = B.cols();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + m, n + m);
  M.topLeftCorner(n, n) = A * period_s;
  M.topRightCorner(n, m) = B * period_s;
  const Eigen::MatrixXd E = M.exp();
  StateSpace d;
  d.A = E.topLeftCorner(n, n);
  d.B = E.topRightCorner(n, m);
  d.C = C;
  d.D = Eigen::MatrixXd::Zero(C.rows(), m);
  d.period_s = period_s;
  return d;
}

StateSpace sample_plant(const SampledPlantSpec& s) {
  const Eigen::Index n = s.A.rows(), m = s.B.cols(), p = s.C.rows();
  if (s.A.cols() != n || s.B.rows() != n || s.C.cols() != n)
    throw std::invalid_argument("sample_plant: sizes of A, B, C disagree");
  if (!(s.tick_s > 0.0) || s.ticks_per_sample < 1 || s.input_delay_ticks < 0)
    throw std::invalid_argument("sample_plant: tick must be > 0, ticks_per_sample >= 1, delays >= 0");
  std::vector<int> out_delay = s.output_delay_ticks;
  if (out_delay.empty()) out_delay.assign(static_cast<std::size_t>(p), 0);
  if (static_cast<Eigen::Index>(out_delay.size()) != p)
    throw std::invalid_argument("sample_plant: one output delay per output row");
  for (int d : out_delay) {
    if (d < 0) throw std::invalid_argument("sample_plant: output delays must be >= 0");
  }

  const StateSpace tick = zoh_discretise(s.A, s.B, s.C, s.tick_s);
  const Eigen::Index d = s.input_delay_ticks;
  Eigen::Index size = n + d * m;
  std::vector<Eigen::Index> out_at(static_cast<std::size_t>(p));
  for (Eigen::Index r = 0; r < p; ++r) {
    out_at[static_cast<std::size_t>(r)] = size;
    size += out_delay[static_cast<std::size_t>(r)];
  }

  // One tick with the held command c: applied = c (no delay) or the line's oldest entry;
  // x+ = Phi x + Gamma applied; the lines shift by one; output r reads its line's oldest entry.
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(size, size), G = Eigen::MatrixXd::Zero(size, m),
                  H = Eigen::MatrixXd::Zero(p, size);
  F.topLeftCorner(n, n) = tick.A;
  if (d == 0) {
    G.topRows(n) = tick.B;
  } else {
    F.block(0, n + (d - 1) * m, n, m) = tick.B;
    G.block(n, 0, m, m).setIdentity();
    for (Eigen::Index j = 1; j < d; ++j) F.block(n + j * m, n + (j - 1) * m, m, m).setIdentity();
  }
  for (Eigen::Index r = 0; r < p; ++r) {
    const Eigen::Index at = out_at[static_cast<std::size_t>(r)];
    const int L = out_delay[static_cast<std::size_t>(r)];
    if (L == 0) {
      H.row(r).head(n) = s.C.row(r);
      continue;
    }
    F.block(at, 0, 1, n) = s.C.row(r);
    for (int j = 1; j < L; ++j) F(at + j, at + j - 1) = 1.0;
    H(r, at + L - 1) = 1.0;
  }

  Eigen::MatrixXd Fn = Eigen::MatrixXd::Identity(size, size), sum = Eigen::MatrixXd::Zero(size, size);
  for (int i = 0; i < s.ticks_per_sample; ++i) {
    sum += Fn;
    Fn = F * Fn;
  }
  StateSpace out;
  out.A = Fn;
  out.B = sum * G;
  out.C = H;
  out.D = Eigen::MatrixXd::Zero(p, m);
  out.period_s = s.tick_s * s.ticks_per_sample;
  return out;
}

std::complex<double> Loop::transfer(double omega_rad_s) const {
  check_loop(*this);
  return LoopEvaluator(*this)(omega_rad_s);
}

Eigen::MatrixXd Loop::closed_loop_matrix(double k) const {
  check_loop(*this);
  const StateSpace& P = plant;
  const StateSpace& K = controller;
  // u = k (Cc s + Dc y), y = Cp x + Dp u  =>  u = alpha (Dc Cp x + Cc s), alpha = k / (1 - k Dc Dp).
  const double denom = 1.0 - k * (K.D * P.D)(0, 0);
  if (denom == 0.0) throw std::invalid_argument("loop: algebraic loop is singular at this gain");
  const double alpha = k / denom;
  const Eigen::Index n = P.A.rows(), q = K.A.rows();
  Eigen::MatrixXd A(n + q, n + q);
  const Eigen::MatrixXd ux = alpha * K.D * P.C;  // u per plant state
  const Eigen::MatrixXd us = alpha * K.C;        // u per controller state
  A.topLeftCorner(n, n) = P.A + P.B * ux;
  A.topRightCorner(n, q) = P.B * us;
  A.bottomLeftCorner(q, n) = K.B * (P.C + P.D * ux);
  A.bottomRightCorner(q, q) = K.A + K.B * P.D * us;
  return A;
}

Eigen::VectorXcd closed_loop_poles(const Loop& loop, double gain) {
  return control::eigenvalues(loop.closed_loop_matrix(gain));  // none for a loop without states
}

int unstable_count(const Eigen::VectorXcd& poles, bool discrete, double tol) {
  int count = 0;
  for (Eigen::Index i = 0; i < poles.size(); ++i) {
    const double m = discrete ? std::abs(poles(i)) - 1.0 : poles(i).real();
    if (m > tol) ++count;
  }
  return count;
}

const char* to_string(MarginStatus s) {
  switch (s) {
    case MarginStatus::kFinite: return "finite";
    case MarginStatus::kInfinite: return "infinite";
    case MarginStatus::kUndefined: return "undefined";
  }
  return "undefined";
}

std::vector<FrequencyPoint> frequency_response(const Loop& loop, const MarginOptions& options) {
  check_loop(loop);
  const auto [lo, hi] = grid_bounds(loop, options);
  const LoopEvaluator L(loop);
  std::vector<FrequencyPoint> out;
  out.reserve(static_cast<std::size_t>(options.points));
  double previous = 0.0;
  bool first = true;
  for (double w : log_grid(lo, hi, options.points)) {
    const std::complex<double> v = L(w);
    double phase = std::arg(v);
    if (first) {
      if (phase > 0.0) phase -= 2.0 * kPi;  // start in (-360, 0]
      first = false;
    } else if (std::isfinite(phase)) {
      phase = previous + model::wrap_pi(phase - previous);
    }
    if (std::isfinite(phase)) previous = phase;
    out.push_back({w, v, 20.0 * std::log10(std::abs(v)), phase * 180.0 / kPi});
  }
  return out;
}

LoopMargins analyse_margins(const Loop& loop, const MarginOptions& options) {
  check_loop(loop);
  const bool discrete = loop.plant.discrete();
  LoopMargins r;

  Eigen::VectorXcd open(loop.plant.A.rows() + loop.controller.A.rows());
  open << control::eigenvalues(loop.plant.A), control::eigenvalues(loop.controller.A);  // either may have none
  constexpr double kTol = 1e-7;
  r.open_loop_unstable_poles = unstable_count(open, discrete, kTol);
  for (Eigen::Index i = 0; i < open.size(); ++i) {
    const double m = discrete ? std::abs(open(i)) - 1.0 : open(i).real();
    if (std::abs(m) <= kTol) ++r.open_loop_marginal_poles;
  }
  r.closed_loop_poles = closed_loop_poles(loop, 1.0);
  r.closed_loop_stable = stable_at(loop, 1.0);

  const auto [lo, hi] = grid_bounds(loop, options);
  const std::vector<double> w = log_grid(lo, hi, options.points);
  const LoopEvaluator L(loop);
  std::vector<std::complex<double>> v(w.size());
  for (std::size_t i = 0; i < w.size(); ++i) v[i] = L(w[i]);
  const bool nyquist_end = discrete && options.omega_max_rad_s <= 0.0;

  // Gain crossovers |L| = 1 and phase crossovers (L on the negative real axis).
  std::vector<std::pair<double, double>> candidates;  // (gain -1/L, frequency)
  auto finite = [](std::complex<double> c) { return std::isfinite(c.real()) && std::isfinite(c.imag()); };
  for (std::size_t i = 0; i + 1 < w.size(); ++i) {
    if (!finite(v[i]) || !finite(v[i + 1])) continue;
    const double a = std::abs(v[i]) - 1.0, b = std::abs(v[i + 1]) - 1.0;
    if ((a < 0) != (b < 0)) {
      r.gain_crossovers_rad_s.push_back(refine([&](double x) { return std::abs(L(x)) - 1.0; }, w[i], w[i + 1]));
    }
    if (nyquist_end && i + 2 == w.size()) continue;  // the Nyquist point is taken below
    const double ia = v[i].imag(), ib = v[i + 1].imag();
    if ((ia < 0) != (ib < 0)) {
      const double x = refine([&](double f) { return L(f).imag(); }, w[i], w[i + 1]);
      const std::complex<double> at = L(x);
      if (at.real() < 0.0) {
        r.phase_crossovers_rad_s.push_back(x);
        candidates.emplace_back(-1.0 / at.real(), x);
      }
    }
  }
  // omega = 0 (s = 0, z = 1): L is real there; a finite negative value is a crossing too.
  if (const std::complex<double> dc = L(0.0); finite(dc) && dc.real() < 0.0) {
    r.phase_crossovers_rad_s.insert(r.phase_crossovers_rad_s.begin(), 0.0);
    candidates.emplace_back(-1.0 / dc.real(), 0.0);
  }
  if (nyquist_end && finite(v.back()) && v.back().real() < 0.0) {
    r.phase_crossovers_rad_s.push_back(w.back());
    candidates.emplace_back(-1.0 / v.back().real(), w.back());
  }
  std::sort(candidates.begin(), candidates.end());

  // Stable gain intervals: stability can change only at the candidate gains; test each interval once.
  std::vector<double> edges = {0.0};
  for (const auto& c : candidates) {
    if (c.first > edges.back()) edges.push_back(c.first);
  }
  edges.push_back(kInf);
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    const double a = edges[i], b = edges[i + 1];
    const double mid = a == 0.0 ? (std::isinf(b) ? 1.0 : b / 2.0) : std::isinf(b) ? 2.0 * a : std::sqrt(a * b);
    if (!stable_at(loop, mid)) continue;
    if (!r.stable_gain_ranges.empty() && r.stable_gain_ranges.back().second == a)
      r.stable_gain_ranges.back().second = b;
    else
      r.stable_gain_ranges.emplace_back(a, b);
  }

  if (!r.closed_loop_stable) return r;  // every margin stays kUndefined

  double upper = kInf, lower = 0.0;
  for (const auto& [a, b] : r.stable_gain_ranges) {
    if (a < 1.0 && 1.0 < b) upper = b, lower = a;
  }
  auto frequency_of = [&](double gain) {
    for (const auto& c : candidates) {
      if (c.first == gain) return c.second;
    }
    return 0.0;
  };
  if (std::isinf(upper)) {
    r.gain_margin.status = MarginStatus::kInfinite;
  } else {
    r.gain_margin = {MarginStatus::kFinite, upper, frequency_of(upper)};
  }
  if (lower == 0.0) {
    r.gain_reduction_margin.status = MarginStatus::kInfinite;
  } else {
    r.gain_reduction_margin = {MarginStatus::kFinite, lower, frequency_of(lower)};
  }

  r.phase_margin.status = MarginStatus::kInfinite;
  r.delay_margin.status = MarginStatus::kInfinite;
  for (double wc : r.gain_crossovers_rad_s) {
    const double pm = model::wrap_pi(std::arg(L(wc)) + kPi);
    if (r.phase_margin.status == MarginStatus::kInfinite || std::abs(pm) < std::abs(r.phase_margin.value))
      r.phase_margin = {MarginStatus::kFinite, pm, wc};
    const double lag = pm >= 0.0 ? pm : pm + 2.0 * kPi;
    const double dm = lag / wc;
    if (r.delay_margin.status == MarginStatus::kInfinite || dm < r.delay_margin.value)
      r.delay_margin = {MarginStatus::kFinite, dm, wc};
  }
  return r;
}

}  // namespace quadcosim::analysis
