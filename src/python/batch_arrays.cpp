// python/batch_class.hpp: what Python reads from and sets in a Batch (setpoints, references, vehicle
// parameters, the state and sensor arrays).
#include <pybind11/stl.h>

#include "python/batch_class.hpp"

namespace py = pybind11;

namespace quadcosim::python {

namespace {

/// Row-major (rows, cols) float64 array holding a copy of `v` (cols 0: a 1-D array of `rows`).
py::array_t<double> to_array(const std::vector<double>& v, std::size_t rows, std::size_t cols) {
  py::array_t<double> a = cols == 0
                              ? py::array_t<double>(static_cast<py::ssize_t>(rows))
                              : py::array_t<double>({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// The keys of set_setpoints and the controller node's parameters they set.
const std::map<std::string, std::string>& setpoint_names() {
  static const std::map<std::string, std::string> names = {
      {"x", "x_des"},         {"y", "y_des"},     {"z", "z_des"},  {"roll", "roll_des"},
      {"pitch", "pitch_des"}, {"yaw", "yaw_des"}, {"mode", "mode"}};
  return names;
}

}  // namespace

void Batch::set_setpoints(const std::optional<std::vector<long long>>& indices, const py::kwargs& values) {
  if (plant_only_) {
    throw py::value_error("Batch.set_setpoints: this batch is plant_only: it has no controllers to set");
  }
  std::vector<std::size_t> which;
  if (indices) {
    for (const long long i : *indices) {
      if (i < 0 || i >= static_cast<long long>(n_)) {
        throw py::index_error("Batch.set_setpoints: vehicle index " + std::to_string(i) + " out of range [0, " +
                              std::to_string(n_ - 1) + "]; no setpoint was changed");
      }
      which.push_back(static_cast<std::size_t>(i));
    }
  } else {
    for (std::size_t i = 0; i < n_; ++i) which.push_back(i);
  }
  // Every value checked and converted first (with the GIL), then applied to all vehicles or none.
  struct Column {
    std::string key, parameter;
    std::vector<control::ParameterValue> values;
  };
  std::vector<Column> columns;
  const std::size_t m = which.size();
  for (const auto& [k, v] : values) {
    const std::string key = k.cast<std::string>();
    const auto name = setpoint_names().find(key);
    if (name == setpoint_names().end()) {
      throw py::type_error("Batch.set_setpoints: unknown setpoint '" + key +
                           "'; expected x, y, z [m], roll, pitch, yaw [rad] or mode ('attitude' or 'position')");
    }
    Column c{key, name->second, {}};
    if (key == "mode") {
      if (py::isinstance<py::str>(v)) {
        c.values.assign(m, v.cast<std::string>());
      } else {
        const auto modes = v.cast<std::vector<std::string>>();
        if (modes.size() != m) {
          throw py::value_error("Batch.set_setpoints: mode: " + std::to_string(modes.size()) + " values for " +
                                std::to_string(m) + " vehicles");
        }
        c.values.assign(modes.begin(), modes.end());
      }
    } else {
      const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(v);
      if (!a || !(a.ndim() == 0 || (a.ndim() == 1 && a.shape(0) == static_cast<py::ssize_t>(m)))) {
        throw py::value_error("Batch.set_setpoints: " + key + ": expected a number or an array of " +
                              std::to_string(m) + " numbers, got " + py::repr(v).cast<std::string>());
      }
      for (std::size_t j = 0; j < m; ++j) {
        const double d = a.ndim() == 0 ? *a.data() : a.data()[j];
        if (!std::isfinite(d)) {
          throw py::value_error("Batch.set_setpoints: vehicle " + std::to_string(which[j]) + ": " + key + " = " +
                                py::repr(py::float_(d)).cast<std::string>() +
                                ": expected a finite number; no setpoint was changed");
        }
        c.values.emplace_back(d);
      }
    }
    columns.push_back(std::move(c));
  }
  std::lock_guard lock(mutex_);
  // Applied vehicle by vehicle; a refused value puts back what was set before it.
  std::vector<std::vector<control::ParameterValue>> before(m);
  for (std::size_t j = 0; j < m; ++j) {
    sim::ControllerCore& node = controller_of(which[j]);
    for (const Column& c : columns) before[j].push_back(*node.get_parameter(c.parameter));
  }
  for (std::size_t j = 0; j < m; ++j) {
    sim::ControllerCore& node = controller_of(which[j]);
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const std::string why = node.set_parameter(columns[c].parameter, columns[c].values[j]);
      if (why.empty()) continue;
      for (std::size_t r = 0; r <= j; ++r) {
        sim::ControllerCore& back = controller_of(which[r]);
        for (std::size_t b = columns.size(); b-- > 0;) back.set_parameter(columns[b].parameter, before[r][b]);
      }
      const control::ParameterValue& got = columns[c].values[j];
      const std::string shown = std::holds_alternative<double>(got)
                                    ? py::repr(py::float_(std::get<double>(got))).cast<std::string>()
                                    : "'" + std::get<std::string>(got) + "'";
      throw py::value_error("Batch.set_setpoints: vehicle " + std::to_string(which[j]) + ": " + columns[c].key + " = " +
                            shown + ": " + why + "; no setpoint was changed");
    }
  }
}

py::dict Batch::setpoints() {
  std::lock_guard lock(mutex_);
  std::vector<double> x(n_), y(n_), z(n_), roll(n_), pitch(n_), yaw(n_);
  py::list modes;
  for (std::size_t i = 0; i < n_; ++i) {
    const control::Setpoint& s = setpoint_of(i);
    modes.append(s.mode == control::Mode::kPosition ? "position" : "attitude");
    x[i] = s.p_des_W.x();
    y[i] = s.p_des_W.y();
    z[i] = s.p_des_W.z();
    roll[i] = s.roll_des_rad;
    pitch[i] = s.pitch_des_rad;
    yaw[i] = s.yaw_des_rad;
  }
  py::dict d;
  d["mode"] = modes;
  d["x"] = to_array(x, n_, 0);
  d["y"] = to_array(y, n_, 0);
  d["z"] = to_array(z, n_, 0);
  d["roll"] = to_array(roll, n_, 0);
  d["pitch"] = to_array(pitch, n_, 0);
  d["yaw"] = to_array(yaw, n_, 0);
  return d;
}

py::dict Batch::reference() {
  std::lock_guard lock(mutex_);
  std::vector<double> p(3 * n_), v(3 * n_, 0.0), yaw(n_);
  for (std::size_t i = 0; i < n_; ++i) {
    const control::ControllerConfig& c = vehicles_[i].scenario->controller;
    if (c.trajectory) {
      const trajectory::FlatOutput f = c.trajectory->at(t_[i]);
      const Eigen::Vector3d pi = f.p_W + c.trajectory_offset_W;
      for (int a = 0; a < 3; ++a) {
        p[3 * i + a] = pi[a];
        v[3 * i + a] = f.v_W[a];
      }
      yaw[i] = f.yaw_rad;
    } else {
      const control::Setpoint& s = setpoint_of(i);
      for (int a = 0; a < 3; ++a) p[3 * i + a] = s.p_des_W[a];
      yaw[i] = s.yaw_des_rad;
    }
  }
  py::dict d;
  d["p"] = to_array(p, n_, 3);
  d["v"] = to_array(v, n_, 3);
  d["yaw"] = to_array(yaw, n_, 0);
  return d;
}

bool Batch::tracks_trajectory() {
  std::lock_guard lock(mutex_);
  return static_cast<bool>(vehicles_[0].scenario->controller.trajectory);
}

py::dict Batch::vehicle_params() {
  std::lock_guard lock(mutex_);
  py::dict d;
  for (const model::VehicleParameter& p : model::vehicle_parameters()) {
    if (p.kind != model::VehicleParameter::Kind::kNumber) continue;
    std::vector<double> values(n_);
    for (std::size_t i = 0; i < n_; ++i) values[i] = p.get(vehicles_[i].scenario->vehicle);
    d[py::str(std::string(p.name))] = to_array(values, n_, 0);
  }
  std::vector<double> hover(n_);
  for (std::size_t i = 0; i < n_; ++i) hover[i] = vehicles_[i].scenario->vehicle.hover_omega_rad_s();
  d["hover_omega_rad_s"] = to_array(hover, n_, 0);
  d["rotor_count"] = to_array(std::vector<double>(n_, static_cast<double>(rotors_)), n_, 0);
  return d;
}

py::array_t<double> Batch::get(const std::string& name) {
  std::lock_guard lock(mutex_);
  static const std::map<std::string, std::pair<std::vector<double> Batch::*, std::size_t>> arrays = {
      {"p", {&Batch::p_, 3}},
      {"v", {&Batch::v_, 3}},
      {"q", {&Batch::q_, 4}},
      {"w", {&Batch::w_, 3}},
      {"omega", {&Batch::omega_, 4}},
      {"command", {&Batch::command_, 4}},
      {"t", {&Batch::t_, 0}},
      {"pose.t", {&Batch::pose_t_, 0}},
      {"pose.p", {&Batch::pose_p_, 3}},
      {"pose.q", {&Batch::pose_q_, 4}},
      {"velocity.t", {&Batch::velocity_t_, 0}},
      {"velocity.v", {&Batch::velocity_v_, 3}},
      {"velocity.w", {&Batch::velocity_w_, 3}},
      {"imu.t", {&Batch::imu_t_, 0}},
      {"imu.q", {&Batch::imu_q_, 4}},
      {"imu.w", {&Batch::imu_w_, 3}},
      {"imu.a", {&Batch::imu_a_, 3}},
  };
  const auto it = arrays.find(name);
  if (it != arrays.end()) {
    // The rotor arrays are one column per rotor.
    const bool per_rotor = name == "omega" || name == "command";
    return to_array(this->*(it->second.first), n_, per_rotor ? rotors_ : it->second.second);
  }
  if (name == "R") {
    // The rotation matrices body -> world of q, row by row (what an RL observation holds: in numpy
    // they cost a step of a few dozen vehicles more than the stepping itself).
    std::vector<double> r(9 * n_);
    for (std::size_t i = 0; i < n_; ++i) {
      const Eigen::Matrix3d m =
          Eigen::Quaterniond(q_[4 * i], q_[4 * i + 1], q_[4 * i + 2], q_[4 * i + 3]).toRotationMatrix();
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) r[9 * i + 3 * row + col] = m(row, col);
      }
    }
    return to_array(r, n_, 9);
  }
  // "<sensor>.t" and "<sensor>.<column>" of the extra sensors the scenario configures.
  std::optional<py::array_t<double>> found;
  sensors::for_each_kind([&]<class Kind>() {
    const std::optional<SensorRows>& rows = sensor_rows_[sensors::kind_index<Kind>()];
    if (!rows || found) return;
    if (name == rows->name + ".t") {
      found = to_array(rows->t, n_, 0);
      return;
    }
    int offset = 0;
    for (const auto& c : Kind::kColumns) {
      if (name == rows->name + "." + std::string(c.name)) {
        std::vector<double> column(n_ * static_cast<std::size_t>(c.width));
        for (std::size_t i = 0; i < n_; ++i) {
          for (int a = 0; a < c.width; ++a) column[i * c.width + a] = rows->values[i * rows->width + offset + a];
        }
        found = to_array(column, n_, c.width == 1 ? 0 : static_cast<std::size_t>(c.width));
        return;
      }
      offset += c.width;
    }
  });
  if (!found) throw py::key_error(name);
  return *found;
}

py::dict Batch::sensor_columns() {
  py::dict d;
  sensors::for_each_kind([&]<class Kind>() {
    if (!sensor_rows_[sensors::kind_index<Kind>()]) return;
    py::list names;
    for (const auto& c : Kind::kColumns) names.append(std::string(c.name));
    d[py::str(std::string(Kind::kName))] = names;
  });
  return d;
}

py::array_t<std::int64_t> Batch::ticks() {
  std::lock_guard lock(mutex_);
  py::array_t<std::int64_t> a(static_cast<py::ssize_t>(n_));
  for (std::size_t i = 0; i < n_; ++i) a.mutable_data()[i] = static_cast<std::int64_t>(vehicles_[i].next_tick);
  return a;
}

py::array_t<std::uint64_t> Batch::seeds() {
  std::lock_guard lock(mutex_);
  py::array_t<std::uint64_t> a(static_cast<py::ssize_t>(n_));
  for (std::size_t i = 0; i < n_; ++i) a.mutable_data()[i] = vehicles_[i].seed;
  return a;
}

double Batch::dt() {
  std::lock_guard lock(mutex_);
  const auto& s = vehicles_[0].scenario->simulation;
  return s.plant.clock.period_s() * s.controller_divider;
}

int Batch::ticks_per_step() {
  std::lock_guard lock(mutex_);
  return vehicles_[0].scenario->simulation.controller_divider;
}

double Batch::plant_period_s() {
  std::lock_guard lock(mutex_);
  return vehicles_[0].scenario->simulation.plant.clock.period_s();
}

}  // namespace quadcosim::python
