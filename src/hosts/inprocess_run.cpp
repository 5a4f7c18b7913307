#include "hosts/inprocess_run.hpp"

#include <fmt/format.h>

#include <fstream>

#include "hosts/recording.hpp"
#include "hosts/signals.hpp"
#include "io/provenance.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::hosts {

namespace fs = std::filesystem;

bool fly_inprocess(const io::Scenario& sc, const fs::path& out, std::ostream& info, std::ostream& warn,
                   const std::function<bool(double t_s)>& on_tick, const std::function<void()>& on_end,
                   const FoxgloveOptions& foxglove) {
  struct Stopped {};
  sim::Simulation simulation(sc.simulation, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule);
  RecordingOptions ro(io::RecordingOptions::for_run(sc));
  ro.csv = (out / "trajectory.csv").string();
  ro.mcap = (out / "run.mcap").string();
  ro.foxglove = foxglove;
  io::Recording recording = make_recording(ro, &simulation.transport());
  bool watchdog = false;
  bool completed = true;
  std::exception_ptr failure;  // a step that failed (a foreign one crashed): rethrown once the files are finished
  try {
    simulation.run([&](const sim::TickRecord& r) {
      const sim::PlantNode& plant = simulation.plant();
      if (plant.watchdog_active() != watchdog) {
        watchdog = plant.watchdog_active();
        warn << (watchdog ? fmt::format("run: plant watchdog: no valid motor command for {:g} s at t = {:g} s; "
                                        "policy {}\n",
                                        static_cast<double>(plant.command_age_ns()) / 1e9, r.t_s,
                                        sim::to_string(plant.options().watchdog_policy))
                          : fmt::format("run: plant watchdog: commands are back at t = {:g} s\n", r.t_s));
      }
      recording.tick(
          {r.tick, r.t_s, sc.simulation.plant.clock.ns(r.tick), r.state, r.latched_command, &r.status, watchdog});
      if (on_tick && on_tick(r.t_s)) throw Stopped{};
    });
  } catch (const Stopped&) {
    completed = false;
  } catch (const std::exception&) {
    // A foreign step given up on a stop request (Ctrl-C, SIGTERM while an FMU's step hung) is an
    // interruption, not a failure: what ran is recorded below like any interrupted run's.
    completed = false;
    if (!stop_requested()) failure = std::current_exception();
  }
  if (completed && on_end) on_end();
  recording.finish(true);  // an interrupted or failed run's recording is described as far as it ran
  if (failure) std::rethrow_exception(failure);  // the outputs hold every tick up to the failed one
  if (!completed) return false;

  const auto& st = simulation.plant().stats();
  if (st.watchdog_trips > 0) {
    info << fmt::format("plant watchdog took over {} times, for {} ticks\n", st.watchdog_trips, st.watchdog_ticks);
  }
  const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);
  if (sc.simulation.faults.active()) {
    info << fmt::format("injected faults dropped: {} motor commands, {} Pose, {} Velocity, {} Imu\n",
                        simulation.dropped(topics.motor_commands), simulation.dropped(topics.pose),
                        simulation.dropped(topics.velocity), simulation.dropped(topics.imu));
  }
  if (st.commands_rejected > 0 || st.commands_clamped > 0) {
    info << fmt::format("plant rejected {} and clamped {} of {} motor commands (last: {})\n", st.commands_rejected,
                        st.commands_clamped, st.commands_received, st.last_problem);
  }
  return true;
}

RunJudgement judge_run(const io::Scenario& sc, const fs::path& out, io::Judge judge, const nlohmann::json& provenance) {
  RunJudgement j;
  j.judge = judge;
  const io::Series series = io::read_series((out / "trajectory.csv").string());
  j.steps = io::evaluate_steps(sc.steps, series, judge);
  if (sc.hold) j.hold = io::evaluate_hold(*sc.hold, series, judge);
  j.saturation = io::evaluate_saturation(sc, series, judge);
  if (sc.tracking) j.tracking = io::evaluate_tracking(*sc.tracking, series, judge);
  if (provenance.is_null()) {
    io::write_metrics_json((out / "metrics.json").string(), sc, j.steps, j.hold, j.saturation, j.tracking, judge);
  } else {
    io::write_metrics_with_provenance(
        out / "metrics.json", io::metrics_json(sc, j.steps, j.hold, j.saturation, j.tracking, judge), provenance);
  }
  j.table = io::format_step_table(sc, j.steps, j.hold, j.saturation, j.tracking, judge);
  std::ofstream((out / "metrics.txt").string()) << j.table;
  j.nothing_note = io::nothing_judged_note(sc, judge);
  j.passed = io::passed_overall(j.steps, j.hold, j.saturation, j.tracking);
  return j;
}

}  // namespace quadcosim::hosts
