// The closed loop the fuzz targets drive between their injected inputs: a PlantNode and a
// ControllerNode on an in-process bus, the controller holding 1 m and the plant starting there, logs
// silenced. A tick is begin(k) (the plant publishes its sensor data of tick k; a target injects its
// input after it) then end(k) (the controller steps on even ticks, the plant latches and integrates).
// end() aborts the fuzzer, naming the target and the tick, when a command or the state is not finite.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "controllers/registry.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"

namespace quadcosim::fuzz {

inline control::ControllerConfig hold_one_metre() {
  control::ControllerConfig c = controllers::make_config("paper", model::VehicleParams{});
  c.node.setpoint.p_des_W.z() = 1.0;
  return c;
}

inline model::State at_one_metre(double omega_rad_s) {
  model::State x;
  x.p_W.z() = 1.0;
  x.omega_rad_s.setConstant(omega_rad_s);
  return x;
}

class ClosedLoop {
 public:
  static constexpr double kPeriod_s = 0.01;  ///< plant tick; the controller runs every second one

  /// `target` names the fuzzer in abort messages; the rotors start at `omega0_rad_s`.
  ClosedLoop(const char* target, double omega0_rad_s)
      : target_(target), plant_(bus_, topics_, config_.vehicle, {}, at_one_metre(omega0_rad_s)) {
    controller_.set_log([](const std::string&) {});
    plant_.set_log([](const std::string&) {});
  }

  sim::InProcessTransport& bus() { return bus_; }
  const sim::Topics& topics() const { return topics_; }
  sim::ControllerNode& controller() { return controller_; }

  void begin(sim::Tick k) { plant_.publish_outputs(k); }

  void end(sim::Tick k) {
    if (k % 2 == 0) {
      const control::ControllerOutput& c = controller_.step(k * 10'000'000, 2 * kPeriod_s);
      for (int i = 0; i < 4; ++i) {
        if (!std::isfinite(c.omega_rad_s[i])) fail("the controller sent a non-finite rotor speed", k);
      }
    }
    plant_.latch_command(k);
    plant_.integrate(k);
    const model::State& x = plant_.state();
    if (!(x.p_W.allFinite() && x.v_W.allFinite() && x.q_WB.coeffs().allFinite() && x.w_B.allFinite() &&
          x.omega_rad_s.allFinite())) {
      fail("the plant state is not finite", k);
    }
  }

 private:
  [[noreturn]] void fail(const char* what, sim::Tick k) const {
    std::fprintf(stderr, "%s: %s at tick %lld\n", target_, what, static_cast<long long>(k));
    std::abort();
  }

  const char* target_;
  sim::InProcessTransport bus_;
  sim::Topics topics_ = sim::Topics::for_namespace("/drone");
  control::ControllerConfig config_ = hold_one_metre();
  sim::ControllerNode controller_{bus_, topics_, config_};
  sim::PlantNode plant_;
};

}  // namespace quadcosim::fuzz
