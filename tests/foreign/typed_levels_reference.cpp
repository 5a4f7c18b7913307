// The in-process reference for foreign_levels (quadcosim's own code, unlike foreign_levels): the law
// foreign_levels flies over DDS, flown by a controller at the same command level on the in-process bus
// (sim::Simulation; the command named by its layout label on motor_commands), its states written tick by
// tick as `quadcosim plant --record` writes them.
//
// Usage: typed_levels_reference SCENARIO ctbr|velocity OUT.csv
// Writes t, x, y, z, vx, vy, vz, qw, qx, qy, qz, w1..w4 (shortest round-trip decimals) for every tick
// of the scenario's duration, the state at t_k.
#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>

#include "control/controller.hpp"
#include "io/scenario.hpp"
#include "io/scenario_resolvers.hpp"
#include "sim/simulation.hpp"

namespace {

using namespace quadcosim;

// The same numbers and the same expressions as foreign_levels.
constexpr double kMass = 1.96;
constexpr double kGravity = 9.81;
constexpr double kZDes = 2.0;
constexpr double kKp = 4.0;
constexpr double kKd = 2.7;
constexpr double kKv = 1.2;

class LawController : public control::Controller {
 public:
  explicit LawController(control::CommandLevel level) : level_(level) {}
  std::string_view type() const override { return "typed_levels_reference"; }
  std::unique_ptr<control::Controller> clone() const override { return std::make_unique<LawController>(*this); }
  std::span<const control::ParameterSpec> parameters() const override { return {}; }
  std::optional<control::ParameterValue> get_parameter(std::string_view) const override { return std::nullopt; }
  std::string set_parameters(std::span<const control::Setting> s) override {
    return s.empty() ? "" : control::unknown_parameter(s.front().name);
  }
  std::span<const std::string> output_names() const override { return {}; }
  void reset() override {}
  void step(const control::Observation& o, const control::Reference&, double, control::ControllerOutput& out) override {
    const double z = o.p_W.z(), vz = o.v_W.z();
    out.level = level_;
    out.omega_rad_s.setZero();
    if (level_ == control::CommandLevel::kCtbr) {
      out.setpoint = {kMass * kGravity + kKp * (kZDes - z) - kKd * vz, 0.0, 0.0, 0.0};
    } else {
      out.setpoint = {0.0, 0.0, kKv * (kZDes - z), 0.0};
    }
    out.U = out.setpoint;
  }

 private:
  control::CommandLevel level_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s SCENARIO ctbr|velocity OUT.csv\n", argv[0]);
    return 2;
  }
  try {
    const std::string level_name = argv[2];
    if (level_name != "ctbr" && level_name != "velocity") throw std::invalid_argument("level: ctbr or velocity");
    io::Scenario sc = io::load_scenario(argv[1], io::ScenarioResolvers{});
    sc.controller.controller = std::make_shared<LawController>(*control::command_level_from_string(level_name));
    sim::Simulation s(sc.simulation, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule);
    std::FILE* f = std::fopen(argv[3], "w");
    if (f == nullptr) throw std::runtime_error(std::string("cannot write ") + argv[3]);
    std::fputs("t,x,y,z,vx,vy,vz,qw,qx,qy,qz,w1,w2,w3,w4\n", f);
    const sim::TickClock& clock = sc.simulation.plant.clock;
    for (sim::Tick k = 0; k <= sc.simulation.duration_ticks; ++k) {
      const model::State& x = s.plant().state();  // at t_k: tick(k) ends with the state at t_k+1
      fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", clock.seconds(k), x.p_W.x(), x.p_W.y(), x.p_W.z(),
                 x.v_W.x(), x.v_W.y(), x.v_W.z(), x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z(), x.omega_rad_s[0],
                 x.omega_rad_s[1], x.omega_rad_s[2], x.omega_rad_s[3]);
      s.tick(k);
    }
    std::fclose(f);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "typed_levels_reference: %s\n", e.what());
    return 1;
  }
  return 0;
}
