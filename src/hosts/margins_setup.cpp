#include "hosts/margins_setup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "controllers/registry.hpp"
#include "io/scenario.hpp"
#include "sim/topics.hpp"

namespace quadcosim::hosts {

namespace {

int delay_of(const sim::FaultConfig& f, const std::string& topic) {
  const auto it = f.topics.find(topic);
  return it == f.topics.end() ? 0 : static_cast<int>(it->second.delay_ticks);
}

// The scenario's plant and timing for the measurement: its simulation without what is not part of
// the small-signal loops (each named in a note when the scenario has it).
sim::SimulationConfig measured_simulation(const sim::SimulationConfig& scenario) {
  sim::SimulationConfig m = scenario;
  const sim::RealismConfig& r = scenario.plant.realism;
  m.plant.realism = sim::RealismConfig{};
  m.plant.realism.imu.timing = r.imu.timing;
  m.plant.realism.pose.timing = r.pose.timing;
  m.plant.realism.velocity.timing = r.velocity.timing;
  for (auto& [topic, f] : m.faults.topics) f.drop_probability = 0.0;
  return m;
}

// Where the measurement trims: the setpoint position, level, heading 0 (translation and heading do
// not change the loops), lifted to 10 m when the setpoint is within 1 m of the ground (ground contact
// and ground effect are not part of the loops).
Eigen::Vector3d trim_position(const control::ControllerConfig& c, std::vector<std::string>& notes) {
  Eigen::Vector3d p = c.node.setpoint.p_des_W;
  if (c.trajectory) notes.push_back("the trajectory is not flown: the measurement hovers at the step setpoints");
  if (p.z() < 1.0) {
    notes.push_back(fmt::format("z_des {:g} m is within 1 m of the ground: trimmed at 10 m instead", p.z()));
    p.z() = 10.0;
  }
  return p;
}

}  // namespace

MarginsSetup margins_setup(const std::string& path, const std::string& controller_type,
                           const io::ScenarioResolvers& resolvers) {
  MarginsSetup s;
  if (path.empty()) {
    s.controller = io::defaults_flown_by(controller_type, resolvers).controller;
    s.source = fmt::format("defaults (the paper's vehicle, {} controller, plant 100 Hz, controller 50 Hz)",
                           s.controller.type());
    s.measured.vehicle = s.plant;
    s.measured.controller = s.controller;
    s.measured.trim_p_W = trim_position(s.controller, s.measured_notes);
    return s;
  }
  const io::Scenario sc = io::load_scenario(path, controller_type, resolvers);
  if (sc.vehicle.rotor_count != 4) {
    throw io::ConfigError(
        fmt::format("{}: margins linearise a four-rotor vehicle's loops; this one has {} rotors "
                    "(layout {})",
                    path, sc.vehicle.rotor_count, model::to_string(sc.vehicle.layout)));
  }
  s.source = path;
  s.plant = sc.vehicle;
  s.controller = sc.controller;
  bool later_design_change = false;
  std::vector<sim::ScheduledParameter> schedule = sc.schedule;
  std::stable_sort(schedule.begin(), schedule.end(), [](const auto& a, const auto& b) { return a.tick < b.tick; });
  for (const sim::ScheduledParameter& p : schedule) {
    if (std::string why = control::set_parameter(s.controller, p.name, p.value); !why.empty())
      throw std::invalid_argument(fmt::format("{}: schedule: {}", path, why));
    const control::ParameterSpec* spec = control::find_parameter(s.controller, p.name);
    if (p.tick > 0 && spec != nullptr && (spec->affects_design || p.name == "mode")) later_design_change = true;
  }
  if (later_design_change)
    s.notes.push_back(
        "the schedule changes gains or mode after t = 0: these are the margins of the configuration "
        "after its last change");

  const sim::SimulationConfig& sim = sc.simulation;
  const sim::Topics topics = sim::Topics::for_namespace(sim.ns);
  s.timing.tick_s = sim.plant.clock.period_s();
  s.timing.controller_divider = sim.controller_divider;
  s.timing.command_delay_ticks = sim.plant.command_delay_ticks + delay_of(sim.faults, topics.motor_commands);
  s.timing.imu_latency_ticks = sim.plant.realism.imu.timing.latency_ticks + delay_of(sim.faults, topics.imu);
  s.timing.pose_latency_ticks = sim.plant.realism.pose.timing.latency_ticks + delay_of(sim.faults, topics.pose);
  s.timing.velocity_latency_ticks =
      sim.plant.realism.velocity.timing.latency_ticks + delay_of(sim.faults, topics.velocity);

  const sim::RealismConfig& r = sim.plant.realism;
  const bool noise = r.imu.gyro_noise_density > 0 || r.imu.accel_noise_density > 0 || r.imu.orientation_sigma_rad > 0 ||
                     r.imu.gyro_bias_random_walk > 0 || r.imu.gyro_bias_initial > 0 || r.pose.position_sigma_m > 0 ||
                     r.pose.orientation_sigma_rad > 0 || r.velocity.linear_sigma_m_s > 0 ||
                     r.velocity.angular_sigma_rad_s > 0;
  if (noise) s.notes.push_back("sensor noise and bias are not part of the linear loops");
  if (r.wind.active()) s.notes.push_back("wind is not part of the linearisation (still air)");
  if (!r.faults.empty()) s.notes.push_back("rotor faults are not part of the linearisation (all rotors nominal)");
  for (const auto& [topic, f] : sim.faults.topics) {
    if (f.drop_probability > 0.0) {
      s.notes.push_back("message drops are not part of the linear loops (" + topic + ")");
    }
  }
  if (s.plant.aero.quadratic_drag_N_s2_m2.squaredNorm() > 0.0)
    s.notes.push_back("quadratic drag vanishes at hover in still air");
  if (s.plant.aero.ground_effect_rotor_radius_m > 0.0)
    s.notes.push_back("ground effect is not part of the linearisation (out of ground effect)");
  if (s.plant.aero.rotor_aero_active())
    s.notes.push_back("per-rotor aerodynamics (aero.rotor_aero) are not part of the linearisation");
  if (s.plant.motor.model == model::MotorModel::kFirstOrder && s.plant.motor.tau_up_s != s.plant.motor.tau_down_s)
    s.notes.push_back(fmt::format("motor lag linearised with the larger time constant, {:g} s",
                                  std::max(s.plant.motor.tau_up_s, s.plant.motor.tau_down_s)));
  const double worst_age_s = s.timing.tick_s * std::max({s.timing.imu_latency_ticks, s.timing.pose_latency_ticks,
                                                         s.timing.velocity_latency_ticks});
  if (worst_age_s > s.controller.node.stale_limit_s)
    s.notes.push_back(
        fmt::format("sensor latency {:g} s exceeds stale_limit {:g} s: the controller would command "
                    "its safety mode, which these loops do not model",
                    worst_age_s, s.controller.node.stale_limit_s));

  s.measured.simulation = measured_simulation(sim);
  s.measured.vehicle = s.plant;
  s.measured.controller = s.controller;
  s.measured.trim_p_W = trim_position(s.controller, s.measured_notes);
  // Left out of the measurement: what would swamp or bias a small sinusoid.
  if (noise) s.measured_notes.push_back("sensor noise and bias are left out of the measurement");
  if (r.wind.active()) s.measured_notes.push_back("wind is left out of the measurement (still air)");
  if (!r.faults.empty()) s.measured_notes.push_back("rotor faults are left out of the measurement");
  for (const auto& [topic, f] : sim.faults.topics) {
    if (f.drop_probability > 0.0)
      s.measured_notes.push_back("message drops are left out of the measurement (" + topic + ")");
  }
  if (later_design_change) s.measured_notes.push_back(s.notes.front());
  if (worst_age_s > s.controller.node.stale_limit_s) s.measured_notes.push_back(s.notes.back());
  return s;
}

}  // namespace quadcosim::hosts
