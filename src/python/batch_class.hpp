// quadcosim.Batch's compiled part (the class _Batch: batch.cpp makes, resets and binds it,
// batch_stepping.cpp steps it, batch_arrays.cpp holds what Python reads and sets): N vehicles of one
// scenario, each with its own seed, vehicle parameters and setpoint, flying the numbers
// quadcosim.Simulation flies (plant node, controller node, in-process bus). C++ keeps their state and the sensor
// readings their controllers see in preallocated row-major (N, k) buffers, written by the thread that steps the
// vehicle; Python gets copies as numpy arrays. Stepping releases the GIL and splits the vehicles over a pool of threads
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
#pragma once

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
#include "python/worker_pool.hpp"
#include "sensors/suite.hpp"
#include "sim/controller_core.hpp"
#include "sim/parameter_schedule.hpp"
#include "sim/plant_node.hpp"
#include "sim/realism.hpp"
#include "sim/recorder.hpp"
#include "sim/sensor_wire.hpp"
#include "sim/simulation.hpp"
#include "sim/swarm.hpp"
#include "sim/topics.hpp"
#include "sim/validation.hpp"

namespace quadcosim::python {

/// A message stamp in seconds.
inline double stamp_s(const msg::Time& t) { return t.sec + t.nanosec * 1e-9; }

/// N vehicles of one scenario (the class _Batch; quadcosim.Batch in __init__ wraps it).
class Batch {
 public:
  /// yaml, source: the scenario's document and where it came from (relative paths in it resolve
  /// against source's folder, as for the file itself). vehicle_keys[i]: vehicle i's keys of the
  /// `vehicle:` section as a JSON/YAML mapping ("" for none). seeds[i]: its seed.
  /// nominal_controller: every controller is designed for the scenario's own vehicle (as a sweep's
  /// runs are) instead of for its vehicle's parameters.
  Batch(const std::string& yaml, const std::string& source, const std::vector<std::string>& vehicle_keys,
        const std::vector<std::uint64_t>& seeds, int threads, bool nominal_controller, bool plant_only,
        const std::string& action = "rotor_speeds");

  std::size_t size() const { return n_; }
  int threads() const { return pool_.size(); }
  bool plant_only() const { return plant_only_; }
  /// The command level of step()'s commands (control/command_level.hpp): "rotor_speeds", "ctbr", ...
  std::string action() const { return std::string(control::to_string(level_)); }
  /// The vehicles are LeanVehicles (no bus), not whole Simulations.
  bool lean_vehicles() const { return lean_vehicles_; }

  /// Advances every vehicle `periods` control periods (back to back, each vehicle's data staying in
  /// the cache); with omega_cmd ((N, 4) rotor speeds [rad/s]) the controllers are bypassed and the
  /// command held for them, as Simulation.step(omega_cmd=). With an action level above rotor speeds
  /// the rows are that level's setpoints, which each plant's inner loops fly every tick.
  void step(
      const std::optional<pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>>& omega_cmd,
      int periods);

  /// Back to t = 0 for `indices` (all when empty) with new seeds and vehicle keys where given.
  /// states: one row of kStateColumns per index (p, v, q as w x y z, w), the vehicle's start in place
  /// of the scenario's initial state; a NaN part (all its entries) keeps the scenario's. The rotor
  /// speeds are always the scenario's (stopped, or hover with `initial: hover: true`).
  void reset(
      const std::optional<std::vector<long long>>& indices, const std::optional<std::vector<std::uint64_t>>& seeds,
      const std::optional<std::vector<std::string>>& vehicle_keys,
      const std::optional<pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>>& states);

  /// Columns of a row of reset's states: p (3), v (3), q (4: w, x, y, z), w (3).
  static constexpr int kStateColumns = 13;

  /// Sets setpoints of `indices` (all when None) by keyword: a value for all or one per vehicle.
  void set_setpoints(const std::optional<std::vector<long long>>& indices, const pybind11::kwargs& values);

  pybind11::dict setpoints();

  /// What each vehicle's controller is asked to reach at its current time: the trajectory's flat
  /// outputs when the scenario has one, else the setpoint (at rest).
  pybind11::dict reference();

  bool tracks_trajectory();

  /// Every numeric vehicle parameter (model::vehicle_parameters(), by its YAML path) and the hover
  /// speed, one value per vehicle.
  pybind11::dict vehicle_params();

  pybind11::array_t<double> get(const std::string& name);

  /// The extra sensors the scenario configures and their columns ({"barometer": ["pressure", "altitude"]}).
  pybind11::dict sensor_columns();

  pybind11::array_t<std::int64_t> ticks();

  pybind11::array_t<std::uint64_t> seeds();

  double dt();
  int ticks_per_step();
  double plant_period_s();

  /// The environments' reward weights (quadcosim/envs.py, _REWARD_WEIGHTS).
  struct EnvWeights {
    double position = 1.0, velocity = 0.1, rate = 0.01, action = 0.01;
  };
  /// The environments' termination limits and penalty; cos_max_tilt is cos(max_tilt_rad).
  struct EnvLimits {
    double crash_altitude_m = 0.0, cos_max_tilt = 0.0, max_position_error_m = 0.0, termination_penalty = 0.0;
  };
  /// Entries of an environment's observation: position error, velocity error, rotation matrix, body rates.
  static constexpr std::size_t kEnvObservationSize = 18;
  /// One environment step's terms for every vehicle as it stands (batch_env.cpp): the observation
  /// [p - p_ref, v - v_ref (v_ref none: 0), R_WB row by row, w_B] clipped to +-obs_bound, as float32
  /// (n, 18); the reward 1 - (w_p |e_p|^2 + w_v |e_v|^2 + w_w |w|^2 + w_a |action - hover_action|^2)
  /// - penalty on termination (n,); terminated = crashed | out (n,), crashed (z below the crash altitude
  /// or R_WB[2,2] below cos_max_tilt) and out (|e_p| beyond the limit on an axis). p_ref, v_ref: (n, 3);
  /// action, hover_action: (n, k), k the env's action size (4, or the rotor count at rotor speeds; action
  /// already clipped to [-1, 1]); obs_bound: (18,). A wrong shape
  /// raises ValueError naming the argument.
  pybind11::tuple env_terms(
      const pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>& p_ref,
      const std::optional<pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>>& v_ref,
      const pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>& action,
      const pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>& hover_action,
      const pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>& obs_bound,
      const EnvWeights& weights, const EnvLimits& limits);

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
    LeanVehicle(const io::Scenario& s, std::uint64_t seed, bool with_controller, const model::State& initial) {
      const sim::Topics topics = sim::Topics::for_namespace(s.simulation.ns);
      sim::RealismConfig realism = s.simulation.plant.realism;
      realism.seed = seed;
      // The noise streams named as PlantNode names them: by the vehicle's namespace.
      plant = sim::PlantCore(s.vehicle, realism, s.simulation.plant.clock, initial, topics.ns);
      if (s.simulation.plant.inner_loops) plant.set_inner_loops(*s.simulation.plant.inner_loops);
      if (with_controller) {
        controller.emplace(s.controller, topics, realism.extra_sensors);
        if (!s.schedule.empty()) schedule.emplace(s.schedule, s.simulation.plant.clock);
      }
    }
    sim::PlantCore plant;
    std::optional<sim::ControllerCore> controller;   ///< none: plant_only
    std::optional<sim::ParameterSchedule> schedule;  ///< the scenario's, when it has one
    bool watchdog = false;                           ///< the watchdog held the motors in the last tick
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
  std::shared_ptr<const io::Scenario> load(const std::string& keys, std::size_t index);

  /// io::load_scenario on `root`, its errors prefixed by `who`.
  std::shared_ptr<const io::Scenario> load_checked(const YAML::Node& root, const std::string& who) const;

  /// Vehicle i's simulation as quadcosim.Simulation builds it (sim/simulation.hpp), its seed for
  /// the realism and the injected faults, stepped for as long as the caller likes.
  std::unique_ptr<sim::Simulation> build(const io::Scenario& s, std::uint64_t seed, std::size_t i,
                                         const model::State& initial);

  /// The scenario's initial state with the parts of `row` (kStateColumns values, or none) that are
  /// not NaN in its place.
  static model::State start_state(const io::Scenario& s, const double* row);

  /// Rebuilds vehicles `which` at t = 0; all are built before any is replaced, so an error changes nothing.
  void reset_vehicles(const std::vector<std::size_t>& which, const std::vector<std::uint64_t>& seeds,
                      const std::vector<std::string>& keys, const double* states = nullptr);

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

  void step_vehicle(std::size_t i, bool bypass, int periods);
  /// step()'s commands at level_ (above rotor speeds): shape (n, 4), finite; else ValueError naming
  /// the level, the row and the field.
  void check_level_commands(
      const pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>& cmd) const;

  /// Lean vehicle i over `periods` control periods: per tick k what Simulation::tick(k) does to its
  /// nodes (sim/simulation.hpp, sim/plant_node.cpp, sim/controller_node.cpp), each model, realism and
  /// controller call the same and in the same order: the scheduled parameter changes due; the outputs
  /// of x(t_k) and the sensor samples due, taken in by the controller and written into the rows as
  /// the full vehicle's subscriptions write them; on control ticks the controller's step (or, with
  /// `bypass`, the row of omega_cmd_ as Simulation::override_command sends it), its command checked
  /// and queued for its delay; the newest due one latched (or the watchdog's); the integration to
  /// t_k+1.
  void step_lean(std::size_t i, bool bypass, int periods);

  /// Row i of each extra sensor that published at tick k (stamp: that tick's time [s]).
  void write_sensors(std::size_t i, const sensors::Suite& suite, sim::Tick k, double stamp);

  void write_pose(std::size_t i, double t, const msg::Vector3& p, const msg::Quaternion& q);
  void write_velocity(std::size_t i, double t, const msg::Vector3& v, const msg::Vector3& w);
  void write_imu(std::size_t i, double t, const msg::Quaternion& q, const msg::Vector3& w, const msg::Vector3& a);

  /// Vehicle i's row of the state arrays (p, v, q, w, omega, command, t) as a recorder of its run
  /// (sim/recorder.hpp). The batch's tick, as Python sees it, is a step: recorders_[i] is fed once per
  /// reset and per step() (after its last plant tick), not per plant tick, with the vehicle as it
  /// stands then: the ticks run, their time, the state there and the command it flew over the last
  /// tick (the latched one; no status). Fed per plant tick it cost 1.7-3 % more instructions per
  /// vehicle-tick for rows of which Python reads only the last (docs/performance.md).
  class StateRow final : public sim::Recorder {
   public:
    StateRow(Batch& batch, std::size_t i) : b_(&batch), i_(i) {}
    void tick(const sim::RecordedTick& t) override;
    void finish(bool) override {}

   private:
    Batch* b_;
    std::size_t i_;
  };

  /// Feeds vehicle i's recorder with its state and command after `ticks` ticks (`watchdog`: the
  /// watchdog held the motors in the last of them).
  void record(std::size_t i, sim::Tick ticks, const model::State& x, const model::RotorVector& command, bool watchdog) {
    const sim::TickClock& clock = vehicles_[i].scenario->simulation.plant.clock;
    recorders_[i]->tick({ticks, clock.seconds(ticks), clock.ns(ticks), x, command, nullptr, watchdog});
  }

  /// Feeds vehicle i's recorder with where it stands now (after a reset or a step): the one place
  /// the state rows are written.
  void fill_state(std::size_t i);

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
  control::CommandLevel level_ = control::CommandLevel::kRotorSpeeds;  ///< what step()'s commands are
  bool lean_vehicles_ = false;                ///< vehicles are LeanVehicles in lean_ (else whole Simulations)
  std::shared_ptr<const io::Scenario> base_;  ///< the scenario itself (vehicles without keys fly it)
  YAML::Node root_;
  std::size_t n_ = 0;
  std::size_t rotors_ = 4;         ///< the vehicles' rotor count (the scenario's: every vehicle has it)
  std::size_t command_width_ = 4;  ///< values per vehicle in a step's commands: rotors_ at rotor_speeds, else 4
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
  std::vector<StateRow> state_rows_;       ///< vehicle i's row of p_, ..., t_
  std::vector<sim::Recorder*> recorders_;  ///< vehicle i's recorder: its StateRow
  WorkerPool pool_;
  std::mutex mutex_;  ///< one thread steps, resets or reads at a time (stepping runs without the GIL)
};

}  // namespace quadcosim::python
