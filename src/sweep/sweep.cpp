#include "sweep/sweep.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

#include "analysis/step_metrics.hpp"
#include "analysis/tracking.hpp"
#include "control/care.hpp"
#include "io/output_folder.hpp"
#include "io/provenance.hpp"
#include "io/recording.hpp"
#include "io/trajectory_csv.hpp"
#include "sim/simulation.hpp"
#include "sim/topics.hpp"
#include "sweep/statistics.hpp"

namespace quadcosim::sweep {

namespace fs = std::filesystem;

namespace {

// Simulates `sc` (plant: sc.vehicle; controller: sc.controller) and returns the signals judged, the
// same numbers trajectory.csv holds. With `csv` it writes trajectory.csv there, with `mcap_dir` also
// run.mcap and metadata.yaml.
// Flies the scenario into `series` (emptied first), writing trajectory.csv and run.mcap when asked.
const io::Series& simulate(const io::Scenario& sc, io::SeriesRecorder& series, const fs::path* csv,
                           const fs::path* mcap_dir) {
  sim::Simulation simulation(sc.simulation, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule);
  series.clear(static_cast<std::size_t>(sc.simulation.duration_ticks + 1));
  io::RecordingOptions ro = io::RecordingOptions::for_run(sc);
  ro.series = &series;  // the numbers trajectory.csv holds
  if (csv) ro.csv = csv->string();
  if (mcap_dir) ro.mcap = (*mcap_dir / "run.mcap").string();
  io::Recording recording = io::make_recording(ro, &simulation.transport());
  simulation.run([&](const sim::TickRecord& r) {
    recording.tick({r.tick, r.t_s, sc.simulation.plant.clock.ns(r.tick), r.state, r.latched_command, &r.status,
                    simulation.plant().watchdog_active()});
  });
  recording.finish(true);
  return series.series();
}

void judge(const io::Scenario& sc, const io::Series& series, io::Judge set, RunResult& r) {
  r.steps = io::evaluate_steps(sc.steps, series, set);
  if (sc.hold) r.hold = io::evaluate_hold(*sc.hold, series, set);
  r.saturation = io::evaluate_saturation(sc, series, set);
  if (sc.tracking) r.tracking = io::evaluate_tracking(*sc.tracking, series, set);
  r.passed = io::passed_overall(r.steps, r.hold, r.saturation, r.tracking);
}

}  // namespace

nlohmann::json run_metrics_json(const Plan& plan, const io::Scenario& flown, const RunResult& r) {
  nlohmann::json j = io::metrics_json(flown, r.steps, r.hold, r.saturation, r.tracking, plan.judge);
  nlohmann::json s;
  s["index"] = r.sample.index;
  s["seed"] = r.sample.seed;
  s["sweep_seed"] = plan.seed;
  s["values"] = values_json(r.sample);
  s["factors"] = r.sample.factors;
  // What the controller was designed for against what flew, for every varied vehicle key (other keys
  // reach the controller and the plant alike: the controller flies its varied gains).
  nlohmann::json vehicle = nlohmann::json::object();
  for (const Vary& v : plan.vary) {
    for (const Key& k : v.keys) {
      if (!k.is_vehicle) continue;
      const auto it = std::find_if(r.sample.values.begin(), r.sample.values.end(),
                                   [&](const auto& p) { return p.first == k.path; });
      vehicle[k.path] = {{"controller_designed_for", *k.nominal}, {"flown", it->second}};
    }
  }
  s["vehicle"] = vehicle;
  j["sweep"] = s;
  // What flew, as every run folder records it (io/provenance.hpp).
  // The run context's defaults (in-process, lockstep, no override) are how a sweep flies.
  io::RunContext context;
  context.python_target = io::python_target_of(plan.root);
  context.python_module = plan.resolvers.python_module;
  j["provenance"] = io::describe_run(flown, context);
  return j;
}

nlohmann::json failed_criteria(const nlohmann::json& metrics) {
  nlohmann::json out = nlohmann::json::array();
  const auto add_failed = [&](const std::string& channel, const nlohmann::json& section) {
    if (!section.is_object() || !section.contains("criteria") || !section.at("criteria").is_array()) return;
    for (const auto& c : section.at("criteria")) {
      if (!c.is_object() || c.value("passed", true) != false) continue;
      if (c.value("judged", true) == false) continue;  // the other set's band (--judge): no verdict
      nlohmann::json f = c;
      f.erase("passed");
      f.erase("figure");
      f["channel"] = channel;
      f["name"] = c.value("figure", std::string());
      const nlohmann::json value = c.value("value", nlohmann::json());
      const nlohmann::json min = c.value("min", nlohmann::json()), max = c.value("max", nlohmann::json());
      f["value"] = value;
      f["min"] = min;
      f["max"] = max;
      f["bound"] = nlohmann::json();
      f["side"] = nlohmann::json();
      if (!f.contains("note")) f["note"] = nlohmann::json();
      // The bound the value is outside; a value inside both failed for its note (not settled, ...).
      if (value.is_number()) {
        if (min.is_number() && value.get<double>() < min.get<double>()) {
          f["bound"] = min;
          f["side"] = "min";
        } else if (max.is_number() && value.get<double>() > max.get<double>()) {
          f["bound"] = max;
          f["side"] = "max";
        }
      }
      out.push_back(f);
    }
  };
  std::map<std::string, int> seen;  // a channel's second step is "<channel>#2", as in summary.json
  if (metrics.contains("steps") && metrics.at("steps").is_array()) {
    for (const auto& step : metrics.at("steps")) {
      if (!step.is_object()) continue;
      const std::string channel = step.value("channel", std::string("?"));
      const int n = ++seen[channel];
      add_failed(n == 1 ? channel : fmt::format("{}#{}", channel, n), step);
    }
  }
  for (const auto& [key, section] : metrics.items()) {
    if (key != "steps") add_failed(key, section);
  }
  return out;
}

namespace {
// run_one, recording into `series` (a worker's, reused run after run).
RunResult run_into(const Plan& plan, int index, const fs::path& run_dir, Keep keep, io::SeriesRecorder& series) {
  RunResult r;
  r.sample = sample(plan, index);
  io::Scenario sc;
  try {
    sc = scenario_for(plan, r.sample);
    if (!run_dir.empty()) fs::create_directories(run_dir);
    const fs::path csv = run_dir / "trajectory.csv";
    const bool record_now = keep == Keep::kAll && !run_dir.empty();
    judge(sc, simulate(sc, series, record_now ? &csv : nullptr, nullptr), plan.judge, r);
    if (keep == Keep::kFailing && !r.passed && !run_dir.empty()) (void)simulate(sc, series, &csv, nullptr);
    const nlohmann::json metrics = run_metrics_json(plan, sc, r);
    if (!run_dir.empty()) write_json(run_dir / "metrics.json", metrics);
    // From the metrics written, so what the criteria layer puts there is what summary.json names.
    if (!r.passed) r.failed_criteria = failed_criteria(metrics);
  } catch (const control::CareError& e) {
    r.error = std::string("controller design failed: ") + e.what();
  } catch (const control::ControllerFailure& e) {
    r.error = e.what();
    r.controller_failed = true;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  if (!r.error.empty()) {
    r.passed = false;
    r.failed_criteria = nlohmann::json::array();  // the error says why
  }
  return r;
}
}  // namespace

RunResult run_one(const Plan& plan, int index, const fs::path& run_dir, Keep keep) {
  io::SeriesRecorder series;
  return run_into(plan, index, run_dir, keep, series);
}

std::vector<RunResult> run_many(const Plan& plan, const std::vector<int>& indices, int jobs, const fs::path& runs_dir,
                                Keep keep, const RunControl& control) {
  std::vector<RunResult> results(indices.size());
  std::vector<char> cut(indices.size(), 0);  // runs the stop cut short: not finished
  std::atomic<std::size_t> next{0};
  std::mutex finished_mutex;  // one `finished` call at a time
  auto worker = [&] {
    io::SeriesRecorder series;  // one per thread, reused run after run
    for (;;) {
      // Asked before an index is taken, so the runs started are always indices[0 .. next).
      if (control.stop && control.stop()) return;
      const std::size_t i = next.fetch_add(1);
      if (i >= indices.size()) return;
      const int index = indices[i];
      const fs::path run_dir = runs_dir.empty() ? fs::path() : runs_dir / fmt::format("{:04d}", index);
      results[i] = run_into(plan, index, run_dir, keep, series);
      // A run that failed once the stop was asked for failed of it (a controller in a process of its
      // own is killed on Ctrl-C): it did not finish, so --resume flies it again. What it wrote goes.
      if (!results[i].error.empty() && control.stop && control.stop()) {
        cut[i] = 1;
        if (!run_dir.empty()) {
          std::error_code ec;
          for (const char* f : {"trajectory.csv", "metrics.json"}) fs::remove(run_dir / f, ec);
          fs::remove(run_dir, ec);  // only when empty
        }
        continue;
      }
      if (control.finished) {
        const std::lock_guard lock(finished_mutex);
        control.finished(results[i]);
      }
    }
  };
  std::vector<std::thread> pool;
  const int threads = std::max(1, std::min<int>(jobs, static_cast<int>(indices.size())));
  for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  const std::size_t started = std::min(next.load(), indices.size());
  std::vector<RunResult> finished;
  finished.reserve(started);
  for (std::size_t i = 0; i < started; ++i) {
    if (!cut[i]) finished.push_back(std::move(results[i]));
  }
  return finished;
}

void write_json(const fs::path& path, const nlohmann::json& j) { io::write_file_atomically(path, j.dump(2) + "\n"); }

int passes_needed(double rate, int runs) {
  if (!(rate >= 0.0 && rate <= 1.0) || runs < 0) {
    throw std::invalid_argument(fmt::format("pass rate {} of {} runs: expected a rate in [0, 1]", rate, runs));
  }
  // A rate written in decimal is not exact in binary, nor is its product with runs: 1e-12 relative
  // covers both (a few units in the last place) and is far below one run in 10^7.
  const double needed = std::ceil(rate * runs * (1.0 - 1e-12));
  return std::clamp(static_cast<int>(needed), 0, runs);
}

std::vector<int> shard_indices(int runs, int shard, int count) {
  std::vector<int> out;
  for (int i = shard - 1; i < runs; i += count) out.push_back(i);
  return out;
}

RunResult rerun(const Plan& plan, int index, const fs::path& dir) {
  if (index < 0 || index >= plan.runs) {
    throw std::invalid_argument(fmt::format("run {} is not in the sweep (runs 0..{})", index, plan.runs - 1));
  }
  RunResult r;
  r.sample = sample(plan, index);
  const io::Scenario sc = scenario_for(plan, r.sample);
  fs::create_directories(dir);
  const fs::path csv = dir / "trajectory.csv";
  io::SeriesRecorder series;
  (void)simulate(sc, series, &csv, &dir);
  judge(sc, io::read_series(csv.string()), plan.judge, r);  // as `run` does: from the recorded doubles
  const nlohmann::json metrics = run_metrics_json(plan, sc, r);
  io::add_provenance_to_bag_metadata(dir, metrics["provenance"]);
  write_json(dir / "metrics.json", metrics);
  if (!r.passed) r.failed_criteria = failed_criteria(metrics);
  io::write_file_atomically(dir / "metrics.txt",
                            io::format_step_table(sc, r.steps, r.hold, r.saturation, r.tracking, plan.judge));
  return r;
}

}  // namespace quadcosim::sweep
