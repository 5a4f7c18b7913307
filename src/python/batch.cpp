// quadcosim.Batch's compiled part: N vehicles of one scenario, each with its own seed, vehicle
// parameters and setpoint, flying the numbers quadcosim.Simulation flies (plant node, controller node,
// in-process bus). C++ keeps their state and the sensor readings their controllers see in
// preallocated row-major (N, k) buffers, written by the thread that steps the vehicle; Python gets
// copies as numpy arrays. Stepping releases the GIL and splits the vehicles over a pool of threads
// kept between steps; the vehicles do not interact, so the thread count changes no number.
//
// A vehicle is one small object of a contiguous array (LeanVehicle), not a bus with two nodes on it:
// its plant's sim::PlantCore (what PlantNode steps) and its controller's sim::ControllerCore (what
// ControllerNode decides with), the core fed the samples the plant node would publish and stepped on
// the ticks the node steps, its commands checked and queued as the plant node takes them. Nobody can subscribe to a
// Batch vehicle's topics, so nothing else of the nodes feeds a number; a tick touches a fraction of the memory (what
// bounds a step of many vehicles once per control period, the cache being too small for them). A scenario that needs
// the bus (injected message faults) or a plant from elsewhere (an FMU) makes each vehicle a whole sim::Simulation. The
// tests hold both to a single Simulation bit for bit.
//
// Plant only (Batch(plant_only=True)): the rotor commands always come from Python; no controllers.
#include "batch.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "control/care.hpp"
#include "io/scenario.hpp"
#include "model/vehicle_params.hpp"
#include "python/module_resolvers.hpp"
#include "sensors/suite.hpp"
#include "sim/controller_core.hpp"
#include "sim/parameter_schedule.hpp"
#include "sim/plant_node.hpp"
#include "sim/realism.hpp"
#include "sim/sensor_wire.hpp"
#include "sim/simulation.hpp"
#include "sim/swarm.hpp"
#include "sim/topics.hpp"
#include "sim/validation.hpp"
#include "worker_pool.hpp"

namespace py = pybind11;

namespace quadcosim::python {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Merges the mapping `keys` into the mapping `into` (nested mappings key by key; anything else replaces).
void merge(YAML::Node into, const YAML::Node& keys) {
  for (const auto& kv : keys) {
    const std::string key = kv.first.Scalar();
    YAML::Node existing = into[key];
    if (kv.second.IsMap() && existing.IsMap()) {
      merge(existing, kv.second);
    } else {
      into[key] = YAML::Clone(kv.second);
    }
  }
}

double stamp_s(const msg::Time& t) { return t.sec + t.nanosec * 1e-9; }

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

/// N vehicles of one scenario (the class _Batch; quadcosim.Batch in __init__ wraps it).
class Batch {
 public:
  /// yaml, source: the scenario's document and where it came from (relative paths in it resolve
  /// against source's folder, as for the file itself). vehicle_keys[i]: vehicle i's keys of the
  /// `vehicle:` section as a JSON/YAML mapping ("" for none). seeds[i]: its seed.
  /// nominal_controller: every controller is designed for the scenario's own vehicle (as a sweep's
  /// runs are) instead of for its vehicle's parameters.
  Batch(const std::string& yaml, const std::string& source, const std::vector<std::string>& vehicle_keys,
        const std::vector<std::uint64_t>& seeds, int threads, bool nominal_controller, bool plant_only)
      : source_(source),
        nominal_controller_(nominal_controller),
        plant_only_(plant_only),
        pool_(std::max(1, std::min<int>(threads, static_cast<int>(vehicle_keys.size())))) {
    if (vehicle_keys.empty()) throw py::value_error("Batch: n must be at least 1");
    if (seeds.size() != vehicle_keys.size()) throw py::value_error("Batch: one seed per vehicle expected");
    root_ = YAML::Load(yaml);
    base_ = load_checked(root_, "");
    n_ = vehicle_keys.size();
    vehicles_.resize(n_);
    const sim::SimulationConfig& c = base_->simulation;
    if (plant_only_) {
      if (c.plant.external) {
        throw io::ConfigError(source_ + ": plant_only: the plant is " + c.plant.external->describe() +
                              ", plant_only steps quadcosim's own plant model only");
      }
      if (c.faults.active()) {
        throw io::ConfigError(source_ +
                              ": plant_only: the scenario injects message faults, which act on the bus plant_only "
                              "has none of");
      }
    }
    lean_vehicles_ = !c.plant.external && !c.faults.active();
    if (lean_vehicles_) lean_.resize(n_);
    p_.assign(3 * n_, 0.0);
    v_.assign(3 * n_, 0.0);
    q_.assign(4 * n_, 0.0);
    w_.assign(3 * n_, 0.0);
    omega_.assign(4 * n_, 0.0);
    command_.assign(4 * n_, 0.0);
    omega_cmd_.assign(4 * n_, 0.0);
    t_.assign(n_, 0.0);
    pose_t_.assign(n_, kNaN);
    pose_p_.assign(3 * n_, kNaN);
    pose_q_.assign(4 * n_, kNaN);
    velocity_t_.assign(n_, kNaN);
    velocity_v_.assign(3 * n_, kNaN);
    velocity_w_.assign(3 * n_, kNaN);
    imu_t_.assign(n_, kNaN);
    imu_q_.assign(4 * n_, kNaN);
    imu_w_.assign(3 * n_, kNaN);
    imu_a_.assign(3 * n_, kNaN);
    // The extra sensors' rows (vehicle keys change only the vehicle: every vehicle carries the same set).
    sensors::for_each_kind([&]<class Kind>() {
      if (Kind::config(c.plant.realism.extra_sensors)) {
        sensor_rows_[sensors::kind_index<Kind>()].emplace(
            SensorRows{std::string(Kind::kName), sensors::sample_width<Kind>(), std::vector<double>(n_, kNaN),
                       std::vector<double>(n_ * sensors::sample_width<Kind>(), kNaN)});
      }
    });
    std::vector<std::size_t> all(n_);
    for (std::size_t i = 0; i < n_; ++i) all[i] = i;
    reset_vehicles(all, seeds, vehicle_keys);
  }

  std::size_t size() const { return n_; }
  int threads() const { return pool_.size(); }
  bool plant_only() const { return plant_only_; }
  /// The vehicles are LeanVehicles (no bus), not whole Simulations.
  bool lean_vehicles() const { return lean_vehicles_; }

  /// Advances every vehicle `periods` control periods (back to back, each vehicle's data staying in
  /// the cache); with omega_cmd ((N, 4) rotor speeds [rad/s]) the controllers are bypassed and the
  /// command held for them, as Simulation.step(omega_cmd=).
  void step(const std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>& omega_cmd,
            int periods) {
    if (periods < 1) {
      throw py::value_error("Batch.step: periods = " + std::to_string(periods) + ": expected at least 1");
    }
    if (plant_only_ && !omega_cmd) {
      throw py::value_error(
          "Batch.step: this batch is plant_only (no controllers): give omega_cmd, an (n, 4) array of rotor speeds "
          "[rad/s]; nothing was stepped");
    }
    if (omega_cmd) {
      if (omega_cmd->ndim() != 2 || omega_cmd->shape(0) != static_cast<py::ssize_t>(n_) || omega_cmd->shape(1) != 4) {
        throw py::value_error("Batch.step: omega_cmd: expected an array of shape (" + std::to_string(n_) +
                              ", 4) (4 rotor speeds [rad/s] per vehicle), got shape " +
                              py::repr(omega_cmd->attr("shape")).cast<std::string>() + "; nothing was stepped");
      }
      const double* c = omega_cmd->data();
      for (std::size_t j = 0; j < 4 * n_; ++j) {
        if (!std::isfinite(c[j])) {
          throw py::value_error("Batch.step: omega_cmd[" + std::to_string(j / 4) + ", " + std::to_string(j % 4) +
                                "] = " + py::repr(py::float_(c[j])).cast<std::string>() +
                                ": rotor speeds must be finite; nothing was stepped");
        }
      }
    }
    const bool bypass = omega_cmd.has_value();
    const double* c = bypass ? omega_cmd->data() : nullptr;
    py::gil_scoped_release release;
    std::lock_guard lock(mutex_);
    if (bypass) std::copy(c, c + 4 * n_, omega_cmd_.begin());
    if (lean_vehicles_) {
      pool_.run(chunks(), [&](std::uint32_t c) {
        const std::size_t last = std::min(n_, (c + 1) * kChunk);
        for (std::size_t i = c * kChunk; i < last; ++i) {
          if (i + 1 < last) prefetch(lean_[i + 1]);
          step_lean(i, bypass, periods);
        }
      });
      return;
    }
    pool_.run(chunks(), [&](std::uint32_t c) {
      const std::size_t last = std::min(n_, (c + 1) * kChunk);
      for (std::size_t i = c * kChunk; i < last; ++i) {
        if (i + 1 < last) prefetch(*vehicles_[i + 1].sim);
        step_vehicle(i, bypass, periods);
      }
    });
  }

  /// Back to t = 0 for `indices` (all when empty) with new seeds and vehicle keys where given.
  void reset(const std::optional<std::vector<long long>>& indices,
             const std::optional<std::vector<std::uint64_t>>& seeds,
             const std::optional<std::vector<std::string>>& vehicle_keys) {
    std::vector<std::size_t> which;
    if (indices) {
      std::vector<bool> seen(n_, false);
      for (const long long i : *indices) {
        if (i < 0 || i >= static_cast<long long>(n_)) {
          throw py::index_error("Batch.reset: vehicle index " + std::to_string(i) + " out of range [0, " +
                                std::to_string(n_ - 1) + "]; nothing was reset");
        }
        if (seen[static_cast<std::size_t>(i)]) {
          throw py::value_error("Batch.reset: vehicle index " + std::to_string(i) + " given twice; nothing was reset");
        }
        seen[static_cast<std::size_t>(i)] = true;
        which.push_back(static_cast<std::size_t>(i));
      }
    } else {
      for (std::size_t i = 0; i < n_; ++i) which.push_back(i);
    }
    std::vector<std::uint64_t> s;
    std::vector<std::string> k;
    {
      std::lock_guard lock(mutex_);
      for (const std::size_t i : which) {
        s.push_back(vehicles_[i].seed);
        k.push_back(vehicles_[i].keys);
      }
    }
    if (seeds) {
      if (seeds->size() != which.size()) {
        throw py::value_error("Batch.reset: " + std::to_string(seeds->size()) + " seeds for " +
                              std::to_string(which.size()) + " vehicles; nothing was reset");
      }
      s = *seeds;
    }
    if (vehicle_keys) {
      if (vehicle_keys->size() != which.size()) {
        throw py::value_error("Batch.reset: vehicle parameters for " + std::to_string(vehicle_keys->size()) +
                              " vehicles, " + std::to_string(which.size()) + " reset; nothing was reset");
      }
      k = *vehicle_keys;
    }
    reset_vehicles(which, s, k);
  }

  /// Sets setpoints of `indices` (all when None) by keyword: a value for all or one per vehicle.
  void set_setpoints(const std::optional<std::vector<long long>>& indices, const py::kwargs& values) {
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
        throw py::value_error("Batch.set_setpoints: vehicle " + std::to_string(which[j]) + ": " + columns[c].key +
                              " = " + shown + ": " + why + "; no setpoint was changed");
      }
    }
  }

  py::dict setpoints() {
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

  /// What each vehicle's controller is asked to reach at its current time: the trajectory's flat
  /// outputs when the scenario has one, else the setpoint (at rest).
  py::dict reference() {
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

  bool tracks_trajectory() {
    std::lock_guard lock(mutex_);
    return static_cast<bool>(vehicles_[0].scenario->controller.trajectory);
  }

  /// Every numeric vehicle parameter (model::vehicle_parameters(), by its YAML path) and the hover
  /// speed, one value per vehicle.
  py::dict vehicle_params() {
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
    return d;
  }

  py::array_t<double> get(const std::string& name) {
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
    if (it != arrays.end()) return to_array(this->*(it->second.first), n_, it->second.second);
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

  /// The extra sensors the scenario configures and their columns ({"barometer": ["pressure", "altitude"]}).
  py::dict sensor_columns() {
    py::dict d;
    sensors::for_each_kind([&]<class Kind>() {
      if (!sensor_rows_[sensors::kind_index<Kind>()]) return;
      py::list names;
      for (const auto& c : Kind::kColumns) names.append(std::string(c.name));
      d[py::str(std::string(Kind::kName))] = names;
    });
    return d;
  }

  py::array_t<std::int64_t> ticks() {
    std::lock_guard lock(mutex_);
    py::array_t<std::int64_t> a(static_cast<py::ssize_t>(n_));
    for (std::size_t i = 0; i < n_; ++i) a.mutable_data()[i] = static_cast<std::int64_t>(vehicles_[i].next_tick);
    return a;
  }

  py::array_t<std::uint64_t> seeds() {
    std::lock_guard lock(mutex_);
    py::array_t<std::uint64_t> a(static_cast<py::ssize_t>(n_));
    for (std::size_t i = 0; i < n_; ++i) a.mutable_data()[i] = vehicles_[i].seed;
    return a;
  }

  double dt() {
    std::lock_guard lock(mutex_);
    const auto& s = vehicles_[0].scenario->simulation;
    return s.plant.clock.period_s() * s.controller_divider;
  }
  int ticks_per_step() {
    std::lock_guard lock(mutex_);
    return vehicles_[0].scenario->simulation.controller_divider;
  }
  double plant_period_s() {
    std::lock_guard lock(mutex_);
    return vehicles_[0].scenario->simulation.plant.clock.period_s();
  }

 private:
  struct Vehicle {
    std::shared_ptr<const io::Scenario> scenario;
    std::string keys;  ///< its vehicle keys as given ("" none)
    std::uint64_t seed = 0;
    std::unique_ptr<sim::Simulation> sim;
    sim::Tick next_tick = 0;  ///< the next plant tick to run
  };

  /// A vehicle without a bus: its plant's PlantCore (what PlantNode steps) and, unless plant_only, its
  /// controller node's ControllerCore and the scenario's schedule of parameter changes.
  struct LeanVehicle {
    LeanVehicle() = default;
    LeanVehicle(const io::Scenario& s, std::uint64_t seed, bool with_controller) {
      const sim::Topics topics = sim::Topics::for_namespace(s.simulation.ns);
      sim::RealismConfig realism = s.simulation.plant.realism;
      realism.seed = seed;
      // The noise streams named as PlantNode names them: by the vehicle's namespace.
      plant = sim::PlantCore(s.vehicle, realism, s.simulation.plant.clock, io::initial_state(s), topics.ns);
      if (with_controller) {
        controller.emplace(s.controller, topics, realism.extra_sensors);
        if (!s.schedule.empty()) schedule.emplace(s.schedule, s.simulation.plant.clock);
      }
    }
    sim::PlantCore plant;
    std::optional<sim::ControllerCore> controller;   ///< none: plant_only
    std::optional<sim::ParameterSchedule> schedule;  ///< the scenario's, when it has one
  };

  const control::Setpoint& setpoint_of(std::size_t i) const {
    const Vehicle& v = vehicles_[i];
    if (v.sim) return v.sim->controller().settings().setpoint;
    return plant_only_ ? v.scenario->controller.node.setpoint : lean_[i].controller->settings().setpoint;
  }
  /// Vehicle i's controller (not plant_only).
  sim::ControllerCore& controller_of(std::size_t i) {
    return vehicles_[i].sim ? vehicles_[i].sim->controller().core() : *lean_[i].controller;
  }

  /// Vehicles per chunk of work (a few microseconds of stepping).
  static constexpr std::size_t kChunk = 16;
  std::uint32_t chunks() const { return static_cast<std::uint32_t>((n_ + kChunk - 1) / kChunk); }

  /// The scenario with `keys` set in its vehicle section, validated as the file would be (the same
  /// keys give the same shared scenario).
  std::shared_ptr<const io::Scenario> load(const std::string& keys, std::size_t index) {
    if (keys.empty()) return base_;
    if (const auto it = loaded_.find(keys); it != loaded_.end()) return it->second;
    const std::string who = "vehicle " + std::to_string(index) + ": ";
    YAML::Node root = YAML::Clone(root_);
    if (!keys.empty()) {
      YAML::Node given;
      try {
        given = YAML::Load(keys);
      } catch (const YAML::Exception& e) {
        throw io::ConfigError(who + "vehicle keys " + keys + " are not a mapping: " + e.what());
      }
      if (!given.IsMap()) throw io::ConfigError(who + "vehicle keys " + keys + " are not a mapping");
      if (!root["vehicle"].IsMap()) root["vehicle"] = YAML::Node(YAML::NodeType::Map);
      merge(root["vehicle"], given);
    }
    const std::shared_ptr<const io::Scenario> sc = load_checked(root, who);
    loaded_.emplace(keys, sc);
    return sc;
  }

  /// io::load_scenario on `root`, its errors prefixed by `who`.
  std::shared_ptr<const io::Scenario> load_checked(const YAML::Node& root, const std::string& who) const {
    try {
      return std::make_shared<const io::Scenario>(io::load_scenario(
          root, source_, module_resolvers(), nominal_controller_ && base_ ? &base_->vehicle : nullptr));
    } catch (const control::CareError& e) {
      throw io::ConfigError(who + source_ + ": controller design failed: " + e.what());
    } catch (const io::ConfigError& e) {
      throw io::ConfigError(who + e.what());
    } catch (const std::invalid_argument& e) {
      throw io::ConfigError(who + source_ + ": " + e.what());
    }
  }

  /// Vehicle i's simulation as quadcosim.Simulation builds it (sim/simulation.hpp), its seed for
  /// the realism and the injected faults, stepped for as long as the caller likes.
  std::unique_ptr<sim::Simulation> build(const io::Scenario& s, std::uint64_t seed, std::size_t i) {
    sim::SimulationConfig cfg = s.simulation;
    cfg.plant.realism.seed = seed;
    cfg.faults.seed = seed;
    cfg.duration_ticks = std::numeric_limits<sim::Tick>::max() / 4;
    // Nobody can subscribe to a vehicle's bus but this class: /clock and /tf (and /tf_static and the
    // robot description), which feed no number, would only cost every tick memory and time.
    cfg.plant.publish_clock = false;
    cfg.plant.publish_tf = false;
    std::unique_ptr<sim::Simulation> sim;
    try {
      sim = std::make_unique<sim::Simulation>(cfg, s.vehicle, io::initial_state(s), s.controller, s.schedule);
    } catch (const std::invalid_argument& e) {
      throw io::ConfigError("vehicle " + std::to_string(i) + ": " + s.path + ": " + e.what());
    }
    // The sensor readings, written into row i as the plant publishes them (on the stepping thread).
    const sim::Topics topics = sim::Topics::for_namespace(cfg.ns);
    auto& t = sim->transport();
    t.subscribe<msg::PoseStamped>(topics.pose, [this, i](const msg::PoseStamped& m) {
      write_pose(i, stamp_s(m.header.stamp), m.position, m.orientation);
    });
    t.subscribe<msg::TwistStamped>(topics.velocity, [this, i](const msg::TwistStamped& m) {
      write_velocity(i, stamp_s(m.header.stamp), m.linear, m.angular);
    });
    t.subscribe<msg::Imu>(topics.imu, [this, i](const msg::Imu& m) {
      write_imu(i, stamp_s(m.header.stamp), m.orientation, m.angular_velocity, m.linear_acceleration);
    });
    return sim;
  }

  /// Rebuilds vehicles `which` at t = 0; all are built before any is replaced, so an error changes nothing.
  void reset_vehicles(const std::vector<std::size_t>& which, const std::vector<std::uint64_t>& seeds,
                      const std::vector<std::string>& keys) {
    std::lock_guard lock(mutex_);
    std::vector<std::shared_ptr<const io::Scenario>> scenarios;
    scenarios.reserve(which.size());
    for (std::size_t j = 0; j < which.size(); ++j) scenarios.push_back(load(keys[j], which[j]));
    std::vector<std::unique_ptr<sim::Simulation>> sims(which.size());
    std::vector<LeanVehicle> lean(lean_vehicles_ ? which.size() : 0);
    for (std::size_t j = 0; j < which.size(); ++j) {
      if (lean_vehicles_) {
        try {
          lean[j] = LeanVehicle(*scenarios[j], seeds[j], !plant_only_);
        } catch (const std::invalid_argument& e) {
          throw io::ConfigError("vehicle " + std::to_string(which[j]) + ": " + scenarios[j]->path + ": " + e.what());
        }
      } else {
        sims[j] = build(*scenarios[j], seeds[j], which[j]);
      }
    }
    for (std::size_t j = 0; j < which.size(); ++j) {
      const std::size_t i = which[j];
      Vehicle& v = vehicles_[i];
      v.scenario = std::move(scenarios[j]);
      v.keys = keys[j];
      v.seed = seeds[j];
      v.sim = std::move(sims[j]);
      if (lean_vehicles_) lean_[i] = std::move(lean[j]);
      v.next_tick = 0;
      pose_t_[i] = velocity_t_[i] = imu_t_[i] = kNaN;
      set3(pose_p_, i, kNaN, kNaN, kNaN);
      set4(pose_q_, i, kNaN, kNaN, kNaN, kNaN);
      set3(velocity_v_, i, kNaN, kNaN, kNaN);
      set3(velocity_w_, i, kNaN, kNaN, kNaN);
      set4(imu_q_, i, kNaN, kNaN, kNaN, kNaN);
      set3(imu_w_, i, kNaN, kNaN, kNaN);
      set3(imu_a_, i, kNaN, kNaN, kNaN);
      for (std::optional<SensorRows>& rows : sensor_rows_) {
        if (!rows) continue;
        rows->t[i] = kNaN;
        std::fill_n(&rows->values[i * static_cast<std::size_t>(rows->width)], rows->width, kNaN);
      }
      fill_state(i);
    }
    // Scenarios no vehicle flies any more are dropped (domain randomisation loads a new one per reset).
    std::map<const io::Scenario*, bool> used;
    for (const Vehicle& v : vehicles_) used[v.scenario.get()] = true;
    for (auto it = loaded_.begin(); it != loaded_.end();)
      it = used.count(it->second.get()) ? std::next(it) : loaded_.erase(it);
  }

  /// Asks the CPU to load the next vehicle's simulation object (plant, controller node and bus are
  /// members of it) while this one steps: with many vehicles their state no longer fits the core's
  /// cache between two steps, and this object is where each tick starts.
  static void prefetch(const sim::Simulation& s) { prefetch_bytes(&s, sizeof(sim::Simulation)); }
  /// The same for a lean vehicle: its object, and its controller's (a heap block of its own; what a
  /// controller's object holds is its business, so the first kilobyte: a paper controller's size).
  static void prefetch(const LeanVehicle& v) {
    prefetch_bytes(&v, sizeof(LeanVehicle));
    v.plant.prefetch();
    if (v.controller) prefetch_bytes(&v.controller->controller(), 1024);
  }
  static void prefetch_bytes(const void* at, std::size_t bytes) {
    const char* p = static_cast<const char*>(at);
    for (std::size_t b = 0; b < bytes; b += 64) __builtin_prefetch(p + b);
  }

  void step_vehicle(std::size_t i, bool bypass, int periods) {
    Vehicle& v = vehicles_[i];
    if (bypass) {
      const double* c = &omega_cmd_[4 * i];
      v.sim->override_command(model::Vector4(c[0], c[1], c[2], c[3]));
    }
    const int ticks = v.scenario->simulation.controller_divider * periods;
    const sensors::Suite* extra = v.sim->plant().extra_sensors();
    const sim::TickClock& clock = v.scenario->simulation.plant.clock;
    for (int j = 0; j < ticks; ++j) {
      const sim::Tick k = v.next_tick++;
      v.sim->tick(k);
      if (extra) write_sensors(i, *extra, k, stamp_s(msg::Time::from_ns(clock.ns(k))));
    }
    if (bypass) v.sim->override_command(std::nullopt);
    fill_state(i);
  }

  /// Lean vehicle i over `periods` control periods: per tick k what Simulation::tick(k) does to its
  /// nodes (sim/simulation.hpp, sim/plant_node.cpp, sim/controller_node.cpp), each model, realism and
  /// controller call the same and in the same order: the scheduled parameter changes due; the outputs
  /// of x(t_k) and the sensor samples due, taken in by the controller and written into the rows as
  /// the full vehicle's subscriptions write them; on control ticks the controller's step (or, with
  /// `bypass`, the row of omega_cmd_ as Simulation::override_command sends it), its command checked
  /// and queued for its delay; the newest due one latched (or the watchdog's); the integration to
  /// t_k+1.
  void step_lean(std::size_t i, bool bypass, int periods) {
    Vehicle& v = vehicles_[i];
    LeanVehicle& L = lean_[i];
    const io::Scenario& s = *v.scenario;
    const sim::PlantOptions& o = s.simulation.plant;
    const int divider = s.simulation.controller_divider;
    const double control_dt_s = o.clock.period_s() * divider;  // as Simulation's
    const std::int64_t watchdog_ns = o.watchdog_ticks > 0 ? o.clock.ns(o.watchdog_ticks) : 0;
    sim::ControllerCore* const controller = L.controller ? &*L.controller : nullptr;
    thread_local msg::Float64MultiArray command;  // the command message, as the controller node or Simulation sends it
    if (bypass) {
      command.data.assign(&omega_cmd_[4 * i], &omega_cmd_[4 * i] + 4);
    } else {
      command.data.resize(4);
    }
    thread_local msg::PoseStamped pose;  // the samples, as the plant node publishes them
    thread_local msg::TwistStamped twist;
    thread_local msg::Imu imu;
    const sim::Tick end = v.next_tick + static_cast<sim::Tick>(divider) * periods;
    for (sim::Tick k = v.next_tick; k < end; ++k) {
      v.next_tick = k + 1;  // as step_vehicle counts a tick begun (one whose controller threw, say)
      // Scheduled parameter changes (Simulation's before_outputs).
      if (L.schedule) L.schedule->apply(*controller, o.clock.ns(k));
      // Outputs and sensors (PlantNode::publish_outputs), taken in by the controller node's core and
      // written into the rows as the whole vehicle's subscriptions write them.
      const model::Outputs y = L.plant.outputs(o.clock, k);
      const msg::Time time = msg::Time::from_ns(o.clock.ns(k));
      const double stamp = stamp_s(time);
      if (controller || L.plant.has_realism()) {
        const sim::PlantRealism::Due due = L.plant.sense(k, y, time, pose, twist, imu);
        if (due.pose) {
          if (controller) controller->take_pose(pose);
          write_pose(i, stamp, pose.position, pose.orientation);
        }
        if (due.velocity) {
          if (controller) controller->take_velocity(twist);
          write_velocity(i, stamp, twist.linear, twist.angular);
        }
        if (due.imu) {
          if (controller) controller->take_imu(imu);
          write_imu(i, stamp, imu.orientation, imu.angular_velocity, imu.linear_acceleration);
        }
      } else {  // plant_only, exact sensors: the rows straight from the outputs (no messages to make)
        pose_t_[i] = velocity_t_[i] = imu_t_[i] = stamp;
        set3(pose_p_, i, y.p_W.x(), y.p_W.y(), y.p_W.z());
        set4(pose_q_, i, y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z());
        set3(velocity_v_, i, y.v_W.x(), y.v_W.y(), y.v_W.z());
        set3(velocity_w_, i, y.w_B.x(), y.w_B.y(), y.w_B.z());
        set4(imu_q_, i, y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z());
        set3(imu_w_, i, y.w_B.x(), y.w_B.y(), y.w_B.z());
        set3(imu_a_, i, y.specific_force_B.x(), y.specific_force_B.y(), y.specific_force_B.z());
      }
      if (L.plant.sense_extra(k, y)) {
        const sensors::Suite& extra = *L.plant.extra_sensors();
        write_sensors(i, extra, k, stamp);
        // Taken in by the controller as the node takes them from the channels' messages.
        if (controller) {
          sensors::for_each_configured(o.realism.extra_sensors, [&]<class Kind>(const typename Kind::Config& c) {
            if (extra.due<Kind>(k)) controller->take<Kind>(sim::as_read<Kind>(extra.slot<Kind>()->sample, c), time);
          });
        }
      }
      // On control ticks the controller's step or the command given (Simulation's after_outputs), taken
      // in as PlantNode::on_command takes it (every command answers its own tick).
      if (k % divider == 0) {
        if (!bypass) {
          const sim::ControllerCore::Begun begun = controller->begin_step(o.clock.ns(k));
          controller->decide(begun.safety, control_dt_s);
          const model::Vector4& omega = controller->output().omega_rad_s;
          for (int r = 0; r < 4; ++r) command.data[r] = omega[r];
        }
        L.plant.take_command(k, o.command_delay_ticks, command);
      }
      // The latch (PlantNode::latch_command): the newest due command, then the watchdog.
      L.plant.latch(k, L.plant.command_age_ns(o.clock, k), watchdog_ns, o.watchdog_policy);
      // The integration to t_k+1 (PlantNode::integrate).
      L.plant.integrate(o.clock, k, o.substeps);
    }
    fill_state(i);
  }

  /// Row i of each extra sensor that published at tick k (stamp: that tick's time [s]).
  void write_sensors(std::size_t i, const sensors::Suite& suite, sim::Tick k, double stamp) {
    sensors::for_each_kind([&]<class Kind>() {
      std::optional<SensorRows>& rows = sensor_rows_[sensors::kind_index<Kind>()];
      if (!rows || !suite.due<Kind>(k)) return;
      rows->t[i] = stamp;
      sensors::write_sample<Kind>(suite.slot<Kind>()->sample, &rows->values[i * static_cast<std::size_t>(rows->width)]);
    });
  }

  void write_pose(std::size_t i, double t, const msg::Vector3& p, const msg::Quaternion& q) {
    pose_t_[i] = t;
    set3(pose_p_, i, p.x, p.y, p.z);
    set4(pose_q_, i, q.w, q.x, q.y, q.z);
  }
  void write_velocity(std::size_t i, double t, const msg::Vector3& v, const msg::Vector3& w) {
    velocity_t_[i] = t;
    set3(velocity_v_, i, v.x, v.y, v.z);
    set3(velocity_w_, i, w.x, w.y, w.z);
  }
  void write_imu(std::size_t i, double t, const msg::Quaternion& q, const msg::Vector3& w, const msg::Vector3& a) {
    imu_t_[i] = t;
    set4(imu_q_, i, q.w, q.x, q.y, q.z);
    set3(imu_w_, i, w.x, w.y, w.z);
    set3(imu_a_, i, a.x, a.y, a.z);
  }

  void fill_state(std::size_t i) {
    const Vehicle& v = vehicles_[i];
    const model::State& x = v.sim ? v.sim->plant().state() : lean_[i].plant.state();
    set3(p_, i, x.p_W.x(), x.p_W.y(), x.p_W.z());
    set3(v_, i, x.v_W.x(), x.v_W.y(), x.v_W.z());
    set4(q_, i, x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z());
    set3(w_, i, x.w_B.x(), x.w_B.y(), x.w_B.z());
    set4(omega_, i, x.omega_rad_s[0], x.omega_rad_s[1], x.omega_rad_s[2], x.omega_rad_s[3]);
    const model::Vector4& c = v.sim ? v.sim->plant().latched_command() : lean_[i].plant.latched();
    set4(command_, i, c[0], c[1], c[2], c[3]);
    t_[i] = v.scenario->simulation.plant.clock.seconds(v.next_tick);
  }

  static void set3(std::vector<double>& a, std::size_t i, double x, double y, double z) {
    double* r = &a[3 * i];
    r[0] = x;
    r[1] = y;
    r[2] = z;
  }
  static void set4(std::vector<double>& a, std::size_t i, double w, double x, double y, double z) {
    double* r = &a[4 * i];
    r[0] = w;
    r[1] = x;
    r[2] = y;
    r[3] = z;
  }

  std::string source_;
  bool nominal_controller_ = false;
  bool plant_only_ = false;
  bool lean_vehicles_ = false;                ///< vehicles are LeanVehicles in lean_ (else whole Simulations)
  std::shared_ptr<const io::Scenario> base_;  ///< the scenario itself (vehicles without keys fly it)
  YAML::Node root_;
  std::size_t n_ = 0;
  std::map<std::string, std::shared_ptr<const io::Scenario>> loaded_;
  std::vector<Vehicle> vehicles_;
  std::vector<LeanVehicle> lean_;  ///< lean_vehicles_: the vehicles (else empty)
  // (N, k) row-major: state after the last step, the command latched in its last tick, the newest
  // sensor messages (NaN before the first), and each vehicle's time.
  std::vector<double> p_, v_, q_, w_, omega_, command_, omega_cmd_, t_;
  std::vector<double> pose_t_, pose_p_, pose_q_, velocity_t_, velocity_v_, velocity_w_, imu_t_, imu_q_, imu_w_, imu_a_;
  /// One configured extra sensor's rows: its stamps t (N) and its columns packed (N, width).
  struct SensorRows {
    std::string name;
    int width = 0;
    std::vector<double> t, values;
  };
  std::array<std::optional<SensorRows>, std::tuple_size_v<sensors::Kinds>> sensor_rows_;  ///< by kind
  WorkerPool pool_;
  std::mutex mutex_;  ///< one thread steps, resets or reads at a time (stepping runs without the GIL)
};

/// The in-process swarm's stepping (sim::Swarm::run_ticks as `quadcosim bench --only swarm_inproc`
/// runs it: the scenario's swarm layout with n vehicles, blocks of `block_ticks`) for `ticks` plant
/// ticks after a warm-up of `warmup_ticks`; the wall seconds of the timed part.
double swarm_wall_s(const std::string& yaml, const std::string& source, int n, long long ticks, int threads,
                    long long block_ticks, long long warmup_ticks) {
  const io::Scenario sc = io::load_scenario(YAML::Load(yaml), source, module_resolvers());
  py::gil_scoped_release release;
  sim::SwarmLayout layout = sc.swarm ? sc.swarm->layout : sim::SwarmLayout{};
  layout.vehicles = n;
  sim::SimulationConfig cfg = sc.simulation;
  cfg.duration_ticks = static_cast<sim::Tick>(warmup_ticks + ticks);
  sim::Swarm swarm(cfg, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule, layout);
  if (warmup_ticks > 0) swarm.run_ticks(0, static_cast<sim::Tick>(warmup_ticks - 1), threads, block_ticks);
  const auto t0 = std::chrono::steady_clock::now();
  swarm.run_ticks(static_cast<sim::Tick>(warmup_ticks), static_cast<sim::Tick>(warmup_ticks + ticks - 1), threads,
                  block_ticks);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// `yaml` with the top-level sections of `sections` (a mapping) replacing its own.
std::string replace_sections(const std::string& yaml, const std::string& sections) {
  YAML::Node root = YAML::Load(yaml);
  const YAML::Node given = YAML::Load(sections);
  if (!root.IsMap() || !given.IsMap()) throw py::value_error("replace_sections: expected two mappings");
  for (const auto& kv : given) root[kv.first.Scalar()] = YAML::Clone(kv.second);
  YAML::Emitter e;
  e << root;
  return e.c_str();
}

}  // namespace

void bind_batch(py::module_& m) {
  py::class_<Batch>(m, "_Batch", "N vehicles of one scenario; use quadcosim.Batch.")
      .def(py::init<const std::string&, const std::string&, const std::vector<std::string>&,
                    const std::vector<std::uint64_t>&, int, bool, bool>(),
           py::arg("yaml"), py::arg("source"), py::arg("vehicle_keys"), py::arg("seeds"), py::arg("threads"),
           py::arg("nominal_controller"), py::arg("plant_only") = false)
      .def("step", &Batch::step, py::arg("omega_cmd") = py::none(), py::arg("periods") = 1)
      .def("reset", &Batch::reset, py::arg("indices") = py::none(), py::arg("seeds") = py::none(),
           py::arg("vehicle_keys") = py::none())
      .def("set_setpoints", &Batch::set_setpoints, py::arg("indices") = py::none())
      .def("setpoints", &Batch::setpoints)
      .def("reference", &Batch::reference)
      .def("tracks_trajectory", &Batch::tracks_trajectory)
      .def("vehicle_params", &Batch::vehicle_params)
      .def("get", &Batch::get, py::arg("name"))
      .def("sensor_columns", &Batch::sensor_columns)
      .def("ticks", &Batch::ticks)
      .def("seeds", &Batch::seeds)
      .def("dt", &Batch::dt)
      .def("ticks_per_step", &Batch::ticks_per_step)
      .def("plant_period_s", &Batch::plant_period_s)
      .def("size", &Batch::size)
      .def("threads", &Batch::threads)
      .def("plant_only", &Batch::plant_only)
      .def("lean_vehicles", &Batch::lean_vehicles);
  m.def("_swarm_wall_s", &swarm_wall_s, py::arg("yaml"), py::arg("source"), py::arg("n"), py::arg("ticks"),
        py::arg("threads"), py::arg("block_ticks"), py::arg("warmup_ticks"),
        "Wall seconds of n vehicles of the in-process swarm (sim::Swarm) over `ticks` plant ticks.");
  m.def("_replace_sections", &replace_sections, py::arg("yaml"), py::arg("sections"),
        "A scenario document with some top-level sections replaced.");
}

}  // namespace quadcosim::python
