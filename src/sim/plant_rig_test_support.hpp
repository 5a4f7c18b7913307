// Test support: a plant node alone on an in-process bus, stepped tick by tick. The test plays the
// controller (it publishes on motor_commands, or on a typed command topic through level_publisher)
// and watches what the plant says: its status messages and its log lines.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "control/command_level.hpp"
#include "model/quadrotor.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"
#include "sim/realism.hpp"
#include "sim/topics.hpp"

namespace quadcosim::sim::test {

struct PlantRig {
  InProcessTransport bus;
  Topics topics = Topics::for_namespace("/drone");
  model::VehicleParams vehicle;
  std::vector<msg::PlantStatus> statuses;
  std::vector<std::string> log;
  Publisher<msg::Float64MultiArray> cmd = bus.advertise<msg::Float64MultiArray>(topics.motor_commands);
  PlantNode plant;

  /// The plant with `options` as given.
  PlantRig(const PlantOptions& options, const model::State& x0, model::VehicleParams v = {})
      : vehicle(v), plant(bus, topics, vehicle, options, x0) {
    bus.subscribe<msg::PlantStatus>(topics.plant_status, [this](const msg::PlantStatus& m) { statuses.push_back(m); });
    plant.set_log([this](const std::string& line) { log.push_back(line); });
  }
  /// The plant with realism `r` and no watchdog.
  PlantRig(const RealismConfig& r, const model::State& x0, model::VehicleParams v = {})
      : PlantRig(without_watchdog(options(r)), x0, v) {}
  static PlantOptions options(const RealismConfig& r) {
    PlantOptions o;
    o.realism = r;
    return o;
  }
  /// For rigs that go long without commands: the watchdog has its own tests.
  static PlantOptions without_watchdog(PlantOptions o) {
    o.watchdog_ticks = 0;
    return o;
  }
  /// Hovering thrust at 5 m, climbing at 1 m/s, level, yaw 0: z = 5 + t exactly while the hover speeds
  /// hold (thrust balances gravity, no drag).
  static model::State climbing() {
    model::State x = model::Quadrotor(model::VehicleParams{}).initial_state({0, 0, 5}, 0.0, true);
    x.v_W = {0, 0, 1};
    return x;
  }
  /// A publisher on the typed command topic of `level` (/drone/cmd/<level>).
  template <class M>
  Publisher<M> level_publisher(control::CommandLevel level) {
    return bus.advertise<M>(topics.level_commands[static_cast<std::size_t>(level)]);
  }
  /// Rotor speeds on motor_commands.
  void send(std::vector<double> omega_rad_s) {
    msg::Float64MultiArray m;
    m.data = std::move(omega_rad_s);
    cmd.publish(m);
  }
  /// The plant's half of tick k after its outputs: the command latched, the state integrated.
  void latch_and_integrate(Tick k) {
    plant.latch_command(k);
    plant.integrate(k);
  }
  /// Ticks 0 .. ticks - 1; with repeat_each every tick's outputs are published twice (a lockstep repeat).
  void run(Tick ticks, bool repeat_each = false) {
    for (Tick k = 0; k < ticks; ++k) {
      plant.publish_outputs(k);
      if (repeat_each) plant.publish_outputs(k);
      latch_and_integrate(k);
    }
  }
};

}  // namespace quadcosim::sim::test
