// quadcosim.Batch's part for the environments (quadcosim/envs.py): an env step's observation, reward
// and termination computed in one pass over the vehicles' rows, with the formulas the envs document
// (envs.py's docstring, docs/python.md "Gymnasium-style environments") and in the order numpy
// evaluates them, so that the numbers are the ones the numpy expressions give, bit for bit (tested
// against them in tests/python/test_envs_terms.py). In numpy they were a dozen passes over (n, k)
// arrays and as many temporaries: about as long as stepping the vehicles at ctbr
// (docs/performance.md, "Env-steps per second").
#include <cmath>
#include <cstring>

#include "python/batch_class.hpp"

namespace py = pybind11;

namespace quadcosim::python {

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// `a`'s data after checking it is (rows, cols) (cols 0: one-dimensional (rows,)); else ValueError.
const double* checked(const Array& a, const char* name, std::size_t rows, std::size_t cols) {
  const bool ok = cols == 0 ? a.ndim() == 1 && static_cast<std::size_t>(a.shape(0)) == rows
                            : a.ndim() == 2 && static_cast<std::size_t>(a.shape(0)) == rows &&
                                  static_cast<std::size_t>(a.shape(1)) == cols;
  if (!ok) {
    throw py::value_error(std::string("env_terms: ") + name + ": expected shape (" + std::to_string(rows) +
                          (cols ? ", " + std::to_string(cols) : std::string(",")) + "), got " +
                          py::repr(a.attr("shape")).cast<std::string>());
  }
  return a.data();
}

}  // namespace

py::tuple Batch::env_terms(const Array& p_ref, const std::optional<Array>& v_ref, const Array& action,
                           const Array& hover_action, const Array& obs_bound, const EnvWeights& weights,
                           const EnvLimits& limits) {
  const std::size_t n = n_;
  const double* pr = checked(p_ref, "p_ref", n, 3);
  const double* vr = v_ref ? checked(*v_ref, "v_ref", n, 3) : nullptr;
  // The action's columns: 4, or the rotor count at rotor speeds (4 to 8).
  const std::size_t k = action.ndim() == 2 ? static_cast<std::size_t>(action.shape(1)) : 0;
  if (k < 4 || k > 8) {
    throw py::value_error("env_terms: action: expected shape (" + std::to_string(n) + ", 4..8), got " +
                          py::repr(action.attr("shape")).cast<std::string>());
  }
  const double* a = checked(action, "action", n, k);
  const double* h = checked(hover_action, "hover_action", n, k);
  const double* bound = checked(obs_bound, "obs_bound", kEnvObservationSize, 0);

  py::array_t<float> obs({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(kEnvObservationSize)});
  py::array_t<double> reward(static_cast<py::ssize_t>(n));
  py::array_t<bool> terminated(static_cast<py::ssize_t>(n)), crashed(static_cast<py::ssize_t>(n)),
      out(static_cast<py::ssize_t>(n));
  float* o = obs.mutable_data();
  double* r = reward.mutable_data();
  bool* term = terminated.mutable_data();
  bool* crash = crashed.mutable_data();
  bool* leave = out.mutable_data();
  std::lock_guard lock(mutex_);
  // Three-term and four-term sums left to right: numpy's np.sum over a short axis adds in that order.
  const auto sum_sq3 = [](const double* x) { return x[0] * x[0] + x[1] * x[1] + x[2] * x[2]; };
  for (std::size_t i = 0; i < n; ++i) {
    double row[kEnvObservationSize];
    double* e_p = row;
    double* e_v = row + 3;
    double* rot = row + 6;
    double* w = row + 15;
    for (int c = 0; c < 3; ++c) {
      e_p[c] = p_[3 * i + c] - pr[3 * i + c];
      e_v[c] = vr ? v_[3 * i + c] - vr[3 * i + c] : v_[3 * i + c] - 0.0;
      w[c] = w_[3 * i + c];
    }
    // The rotation matrix body -> world of q, row by row (as Batch.R gives it).
    const Eigen::Matrix3d m =
        Eigen::Quaterniond(q_[4 * i], q_[4 * i + 1], q_[4 * i + 2], q_[4 * i + 3]).toRotationMatrix();
    for (int rr = 0; rr < 3; ++rr) {
      for (int c = 0; c < 3; ++c) rot[3 * rr + c] = m(rr, c);
    }
    for (std::size_t c = 0; c < kEnvObservationSize; ++c) {
      o[kEnvObservationSize * i + c] = static_cast<float>(std::clamp(row[c], -bound[c], bound[c]));
    }
    double action_sq = 0.0;
    for (std::size_t j = 0; j < k; ++j) {
      const double d = a[k * i + j] - h[k * i + j];
      action_sq = j == 0 ? d * d : action_sq + d * d;
    }
    const double cost = weights.position * sum_sq3(e_p) + weights.velocity * sum_sq3(e_v) + weights.rate * sum_sq3(w) +
                        weights.action * action_sq;
    crash[i] = p_[3 * i + 2] < limits.crash_altitude_m || rot[8] < limits.cos_max_tilt;
    leave[i] = std::abs(e_p[0]) > limits.max_position_error_m || std::abs(e_p[1]) > limits.max_position_error_m ||
               std::abs(e_p[2]) > limits.max_position_error_m;
    term[i] = crash[i] || leave[i];
    r[i] = 1.0 - cost - limits.termination_penalty * (term[i] ? 1.0 : 0.0);
  }
  return py::make_tuple(obs, reward, terminated, crashed, out);
}

}  // namespace quadcosim::python
