// `quadcosim openloop --commands FILE --out FILE [--vehicle FILE]`: the plant alone.
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <cmath>
#include <iostream>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "hosts/recording.hpp"
#include "io/scenario.hpp"
#include "io/trajectory_csv.hpp"
#include "model/quadrotor.hpp"
#include "sim/clock.hpp"

namespace quadcosim::app {

CLI::App* add_openloop_subcommand(CLI::App& app, OpenloopOptions& ol) {
  auto* ol_cmd = app.add_subcommand("openloop", "the plant alone under a rotor speed schedule");
  ol_cmd->add_option("--commands", ol.commands, "CSV with header t,w1,w2,w3,w4 [s, rad/s]")
      ->required()
      ->check(CLI::ExistingFile);
  ol_cmd->add_option("--out", ol.out, "trajectory CSV to write")->required();
  ol_cmd->add_option("--vehicle", ol.vehicle, "vehicle YAML (default: the paper's Table 1)")->check(CLI::ExistingFile);
  ol_cmd->add_option("--rate-hz", ol.rate_hz, "plant rate [Hz]")->check(CLI::Range(1e-3, 1e6));
  ol_cmd->add_option("--substeps", ol.substeps, "RK4 steps per plant tick")->check(CLI::Range(1, 10000));
  ol_cmd->add_option("--duration", ol.duration_s, "simulated time [s] (default: last command time)")
      ->check(CLI::Range(0.0, 1e7));
  ol_cmd->add_option("--initial-z", ol.initial_z_m, "start at rest at this height [m]")->check(CLI::Range(0.0, 1e6));
  return ol_cmd;
}

int openloop_command(const OpenloopOptions& opt) {
  model::VehicleParams vehicle;
  std::vector<io::CommandRow> rows;
  if (!opt.vehicle.empty()) vehicle = io::load_vehicle(opt.vehicle);
  if (vehicle.rotor_count != 4) {  // the schedule's columns are t,w1,w2,w3,w4
    throw io::ConfigError(
        fmt::format("--vehicle {}: openloop's command schedule holds four rotor speeds; the vehicle "
                    "has {} rotors (layout {})",
                    opt.vehicle, vehicle.rotor_count, model::to_string(vehicle.layout)));
  }
  try {
    rows = io::read_command_schedule(opt.commands);
  } catch (const std::runtime_error& e) {  // the file is input: a bad one is a bad input
    throw io::ConfigError(e.what());
  }
  const double period_ns = 1e9 / opt.rate_hz;
  if (std::abs(period_ns - std::round(period_ns)) > 1e-6) {
    std::cerr << "error: --rate-hz " << opt.rate_hz << ": the period must be a whole number of ns\n";
    return exit_code::kBadInput;
  }
  const sim::TickClock clock{static_cast<std::int64_t>(std::round(period_ns))};
  if (std::string err = model::validate_step(vehicle, clock.period_s(), opt.substeps); !err.empty()) {
    std::cerr << "error: --substeps " << opt.substeps << ": " << err << '\n';
    return exit_code::kBadInput;
  }
  const double duration = opt.duration_s >= 0.0 ? opt.duration_s : rows.back().t_s;
  const auto last_tick = static_cast<sim::Tick>(std::floor(duration / clock.period_s() + 1e-9));

  const model::Quadrotor plant(vehicle);
  const model::Environment idle;
  const model::Environment* still_air = vehicle.aero.active() ? &idle : nullptr;
  model::State x = plant.initial_state({0.0, 0.0, opt.initial_z_m}, 0.0, false);
  try {
    hosts::RecordingOptions ro;
    ro.csv = opt.out;
    io::Recording recording = hosts::make_recording(ro, nullptr);
    std::size_t next = 0;
    model::RotorVector cmd = model::RotorVector::Zero(4);  // rotors stopped until the first row
    for (sim::Tick k = 0; k <= last_tick; ++k) {
      const double t = clock.seconds(k);
      while (next < rows.size() && rows[next].t_s <= t + 1e-12) cmd = rows[next++].omega_rad_s;
      recording.tick({k, t, clock.ns(k), x, cmd, nullptr, false});
      // Still air; the vehicle file's drag (vehicle.aero) acts on the motion through it.
      if (k < last_tick) plant.step(x, t, cmd, clock.period_s(), opt.substeps, still_air);
    }
    recording.finish(true);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return exit_code::kOutput;
  }
  std::cout << "wrote " << opt.out << " (" << last_tick + 1 << " rows)\n";
  return exit_code::kOk;
}

}  // namespace quadcosim::app
