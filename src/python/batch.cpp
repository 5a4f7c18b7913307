// python/batch_class.hpp: making and resetting the vehicles of a Batch, and the module's _Batch.
#include "batch.hpp"

#include <pybind11/stl.h>
#include <yaml-cpp/yaml.h>

#include <chrono>

#include "control/care.hpp"
#include "python/batch_class.hpp"
#include "python/module_resolvers.hpp"

namespace py = pybind11;

namespace quadcosim::python {

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

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

}  // namespace

Batch::Batch(const std::string& yaml, const std::string& source, const std::vector<std::string>& vehicle_keys,
             const std::vector<std::uint64_t>& seeds, int threads, bool nominal_controller, bool plant_only,
             const std::string& action)
    : source_(source),
      nominal_controller_(nominal_controller),
      plant_only_(plant_only),
      pool_(std::max(1, std::min<int>(threads, static_cast<int>(vehicle_keys.size())))) {
  if (vehicle_keys.empty()) throw py::value_error("Batch: n must be at least 1");
  const std::optional<control::CommandLevel> level = control::command_level_from_string(action);
  if (!level) throw py::value_error("Batch: action: " + control::unknown_command_level(action));
  level_ = *level;
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
  rotors_ = static_cast<std::size_t>(base_->vehicle.rotor_count);
  if (level_ == control::CommandLevel::kRotorThrusts && rotors_ != 4) {
    throw py::value_error("Batch: action: rotor_thrusts is a four-rotor level; the scenario's vehicle has " +
                          std::to_string(rotors_) + " rotors (use rotor_speeds or a level above)");
  }
  command_width_ = level_ == control::CommandLevel::kRotorSpeeds ? rotors_ : 4;
  lean_vehicles_ = !c.plant.external && !c.faults.active();
  if (lean_vehicles_) lean_.resize(n_);
  p_.assign(3 * n_, 0.0);
  v_.assign(3 * n_, 0.0);
  q_.assign(4 * n_, 0.0);
  w_.assign(3 * n_, 0.0);
  omega_.assign(rotors_ * n_, 0.0);
  command_.assign(rotors_ * n_, 0.0);
  omega_cmd_.assign(command_width_ * n_, 0.0);
  t_.assign(n_, 0.0);
  state_rows_.reserve(n_);  // recorders_ points into it
  for (std::size_t i = 0; i < n_; ++i) state_rows_.emplace_back(*this, i);
  for (StateRow& row : state_rows_) recorders_.push_back(&row);
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

void Batch::reset(const std::optional<std::vector<long long>>& indices,
                  const std::optional<std::vector<std::uint64_t>>& seeds,
                  const std::optional<std::vector<std::string>>& vehicle_keys,
                  const std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>& states) {
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
  const double* rows = nullptr;
  if (states) {
    if (states->ndim() != 2 || states->shape(0) != static_cast<py::ssize_t>(which.size()) ||
        states->shape(1) != kStateColumns) {
      throw py::value_error("Batch.reset: states: expected an array of shape (" + std::to_string(which.size()) + ", " +
                            std::to_string(kStateColumns) + "); nothing was reset");
    }
    rows = states->data();
  }
  reset_vehicles(which, s, k, rows);
}

model::State Batch::start_state(const io::Scenario& s, const double* row) {
  model::State x = io::initial_state(s);
  if (row == nullptr) return x;
  const auto given = [row](int from) { return !std::isnan(row[from]); };
  if (given(0)) x.p_W = Eigen::Vector3d(row[0], row[1], row[2]);
  if (given(3)) x.v_W = Eigen::Vector3d(row[3], row[4], row[5]);
  if (given(6)) x.q_WB = Eigen::Quaterniond(row[6], row[7], row[8], row[9]);  // unit (Batch.reset)
  if (given(10)) x.w_B = Eigen::Vector3d(row[10], row[11], row[12]);
  return x;
}

std::shared_ptr<const io::Scenario> Batch::load(const std::string& keys, std::size_t index) {
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
  if (static_cast<std::size_t>(sc->vehicle.rotor_count) != rotors_) {
    throw io::ConfigError(who + "vehicle keys " + keys + " give " + std::to_string(sc->vehicle.rotor_count) +
                          " rotors; every vehicle of a batch has the scenario's " + std::to_string(rotors_));
  }
  loaded_.emplace(keys, sc);
  return sc;
}

std::shared_ptr<const io::Scenario> Batch::load_checked(const YAML::Node& root, const std::string& who) const {
  try {
    return std::make_shared<const io::Scenario>(
        io::load_scenario(root, source_, module_resolvers(), nominal_controller_ && base_ ? &base_->vehicle : nullptr));
  } catch (const control::CareError& e) {
    throw io::ConfigError(who + source_ + ": controller design failed: " + e.what());
  } catch (const io::ConfigError& e) {
    throw io::ConfigError(who + e.what());
  } catch (const std::invalid_argument& e) {
    throw io::ConfigError(who + source_ + ": " + e.what());
  }
}

std::unique_ptr<sim::Simulation> Batch::build(const io::Scenario& s, std::uint64_t seed, std::size_t i,
                                              const model::State& initial) {
  sim::SimulationConfig cfg = s.simulation;
  cfg.plant.realism.seed = seed;
  cfg.faults.seed = seed;
  cfg.duration_ticks = std::numeric_limits<sim::Tick>::max() / 4;
  // Nobody can subscribe to a vehicle's bus but this class: /clock and /tf (and /tf_static and the
  // robot description), which feed no number, would only cost every tick memory and time.
  cfg.plant.publish_clock = false;
  cfg.plant.publish_tf = false;
  cfg.plant.typed_command_topics = false;  // nobody publishes a typed command on it either
  std::unique_ptr<sim::Simulation> sim;
  try {
    sim = std::make_unique<sim::Simulation>(cfg, s.vehicle, initial, s.controller, s.schedule);
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

void Batch::reset_vehicles(const std::vector<std::size_t>& which, const std::vector<std::uint64_t>& seeds,
                           const std::vector<std::string>& keys, const double* states) {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<const io::Scenario>> scenarios;
  scenarios.reserve(which.size());
  for (std::size_t j = 0; j < which.size(); ++j) scenarios.push_back(load(keys[j], which[j]));
  std::vector<std::unique_ptr<sim::Simulation>> sims(which.size());
  std::vector<LeanVehicle> lean(lean_vehicles_ ? which.size() : 0);
  for (std::size_t j = 0; j < which.size(); ++j) {
    const model::State initial =
        start_state(*scenarios[j], states == nullptr ? nullptr : states + j * static_cast<std::size_t>(kStateColumns));
    if (lean_vehicles_) {
      try {
        lean[j] = LeanVehicle(*scenarios[j], seeds[j], !plant_only_, initial);
      } catch (const std::invalid_argument& e) {
        throw io::ConfigError("vehicle " + std::to_string(which[j]) + ": " + scenarios[j]->path + ": " + e.what());
      }
    } else {
      sims[j] = build(*scenarios[j], seeds[j], which[j], initial);
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

namespace {

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
                    const std::vector<std::uint64_t>&, int, bool, bool, const std::string&>(),
           py::arg("yaml"), py::arg("source"), py::arg("vehicle_keys"), py::arg("seeds"), py::arg("threads"),
           py::arg("nominal_controller"), py::arg("plant_only") = false, py::arg("action") = "rotor_speeds")
      .def("action", &Batch::action)
      .def("step", &Batch::step, py::arg("omega_cmd") = py::none(), py::arg("periods") = 1)
      .def("reset", &Batch::reset, py::arg("indices") = py::none(), py::arg("seeds") = py::none(),
           py::arg("vehicle_keys") = py::none(), py::arg("states") = py::none())
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
      .def("lean_vehicles", &Batch::lean_vehicles)
      .def(
          "env_terms",
          [](Batch& b, const Array& p_ref, const std::optional<Array>& v_ref, const Array& action,
             const Array& hover_action, const Array& obs_bound, const py::dict& weights, const py::dict& limits) {
            Batch::EnvWeights w;
            w.position = weights["position"].cast<double>();
            w.velocity = weights["velocity"].cast<double>();
            w.rate = weights["rate"].cast<double>();
            w.action = weights["action"].cast<double>();
            Batch::EnvLimits l;
            l.crash_altitude_m = limits["crash_altitude_m"].cast<double>();
            l.cos_max_tilt = limits["cos_max_tilt"].cast<double>();
            l.max_position_error_m = limits["max_position_error_m"].cast<double>();
            l.termination_penalty = limits["termination_penalty"].cast<double>();
            return b.env_terms(p_ref, v_ref, action, hover_action, obs_bound, w, l);
          },
          py::arg("p_ref"), py::arg("v_ref"), py::arg("action"), py::arg("hover_action"), py::arg("obs_bound"),
          py::arg("weights"), py::arg("limits"));
  m.def("_swarm_wall_s", &swarm_wall_s, py::arg("yaml"), py::arg("source"), py::arg("n"), py::arg("ticks"),
        py::arg("threads"), py::arg("block_ticks"), py::arg("warmup_ticks"),
        "Wall seconds of n vehicles of the in-process swarm (sim::Swarm) over `ticks` plant ticks.");
  m.def("_replace_sections", &replace_sections, py::arg("yaml"), py::arg("sections"),
        "A scenario document with some top-level sections replaced.");
}

}  // namespace quadcosim::python