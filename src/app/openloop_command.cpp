// `quadcosim openloop --commands FILE --out FILE [--vehicle FILE]`: the plant alone.
#include <cmath>
#include <iostream>

#include "app/commands.hpp"
#include "io/scenario.hpp"
#include "io/trajectory_csv.hpp"
#include "model/quadrotor.hpp"
#include "sim/clock.hpp"

namespace quadcosim::app {

int openloop_command(const OpenloopOptions& opt) {
  model::VehicleParams vehicle;
  std::vector<io::CommandRow> rows;
  try {
    if (!opt.vehicle.empty()) vehicle = io::load_vehicle(opt.vehicle);
    rows = io::read_command_schedule(opt.commands);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  }
  const double period_ns = 1e9 / opt.rate_hz;
  if (std::abs(period_ns - std::round(period_ns)) > 1e-6) {
    std::cerr << "error: --rate-hz " << opt.rate_hz << ": the period must be a whole number of ns\n";
    return 2;
  }
  const sim::TickClock clock{static_cast<std::int64_t>(std::round(period_ns))};
  if (std::string err = model::validate_step(vehicle, clock.period_s(), opt.substeps); !err.empty()) {
    std::cerr << "error: --substeps " << opt.substeps << ": " << err << '\n';
    return 2;
  }
  const double duration = opt.duration_s >= 0.0 ? opt.duration_s : rows.back().t_s;
  const auto last_tick = static_cast<sim::Tick>(std::floor(duration / clock.period_s() + 1e-9));

  const model::Quadrotor plant(vehicle);
  const model::Environment idle;
  const model::Environment* still_air = vehicle.aero.active() ? &idle : nullptr;
  model::State x = plant.initial_state({0.0, 0.0, opt.initial_z_m}, 0.0, false);
  try {
    io::TrajectoryWriter csv(opt.out);
    std::size_t next = 0;
    Eigen::Vector4d cmd = Eigen::Vector4d::Zero();  // rotors stopped until the first row
    for (sim::Tick k = 0; k <= last_tick; ++k) {
      const double t = clock.seconds(k);
      while (next < rows.size() && rows[next].t_s <= t + 1e-12) cmd = rows[next++].omega_rad_s;
      csv.write(t, x, cmd, io::ControlColumns::none());
      // Still air; the vehicle file's drag (vehicle.aero) acts on the motion through it.
      if (k < last_tick) plant.step(x, t, cmd, clock.period_s(), opt.substeps, still_air);
    }
    csv.close();
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 3;
  }
  std::cout << "wrote " << opt.out << " (" << last_tick + 1 << " rows)\n";
  return 0;
}

}  // namespace quadcosim::app
