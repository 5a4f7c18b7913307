// Test support: a plant node alone on an in-process bus, stepped tick by tick with no controller (and
// so no watchdog: the rig sends no commands), for tests of what the plant publishes.
#pragma once

#include "model/quadrotor.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"
#include "sim/realism.hpp"
#include "sim/topics.hpp"

namespace quadcosim::sim::test {

struct PlantRig {
  InProcessTransport bus;
  PlantNode plant;
  PlantRig(const RealismConfig& r, const model::State& x0, model::VehicleParams v = {})
      : plant(bus, Topics::for_namespace("/drone"), v, options(r), x0) {}
  static PlantOptions options(const RealismConfig& r) {
    PlantOptions o;
    o.watchdog_ticks = 0;  // no commands come; the watchdog has its own tests
    o.realism = r;
    return o;
  }
  /// Hovering thrust at 5 m, climbing at 1 m/s, level, yaw 0: z = 5 + t exactly while the hover speeds
  /// hold (thrust balances gravity, no drag).
  static model::State climbing() {
    model::State x = model::Quadrotor(model::VehicleParams{}).initial_state({0, 0, 5}, 0.0, true);
    x.v_W = {0, 0, 1};
    return x;
  }
  /// Ticks 0 .. ticks - 1; with repeat_each every tick's outputs are published twice (a lockstep repeat).
  void run(Tick ticks, bool repeat_each = false) {
    for (Tick k = 0; k < ticks; ++k) {
      plant.publish_outputs(k);
      if (repeat_each) plant.publish_outputs(k);
      plant.latch_command(k);
      plant.integrate(k);
    }
  }
};

}  // namespace quadcosim::sim::test
