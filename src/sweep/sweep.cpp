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
#include "io/mcap_recorder.hpp"
#include "io/output_folder.hpp"
#include "io/provenance.hpp"
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
  std::optional<io::TrajectoryWriter> writer;
  if (csv) writer.emplace(csv->string());
  std::optional<io::McapRecorder> mcap;
  if (mcap_dir) {
    mcap.emplace((*mcap_dir / "run.mcap").string(), simulation.transport(),
                 sim::Topics::for_namespace(sc.simulation.ns));
    if (sc.simulation.plant.publish_tf)
      mcap->record_vehicle(sc.vehicle, sc.simulation.ns, sc.simulation.plant.clock.ns(0));
    mcap->record_sensors(simulation.transport(), sc.simulation.ns, sc.simulation.plant.realism.extra_sensors);
  }
  series.clear(static_cast<std::size_t>(sc.simulation.duration_ticks + 1));
  simulation.run([&](const sim::TickRecord& r) {
    const io::ControlColumns c = io::ControlColumns::from(r.status);
    const bool watchdog = simulation.plant().watchdog_active();
    series.add(r.t_s, r.state, r.latched_command, c, watchdog);  // the numbers trajectory.csv holds
    if (writer) writer->write(r.t_s, r.state, r.latched_command, c, watchdog);
    if (mcap) mcap->flush_settled(sc.simulation.plant.clock.ns(r.tick));
  });
  if (writer) writer->close();
  if (mcap) {
    mcap->close();
    mcap->write_bag_metadata(mcap_dir->string(), "run.mcap");
  }
  return series.series();
}

void judge(const io::Scenario& sc, const io::Series& series, io::Judge set, RunResult& r) {
  r.steps = io::evaluate_steps(sc.steps, series, set);
  if (sc.hold) r.hold = io::evaluate_hold(*sc.hold, series, set);
  r.saturation = io::evaluate_saturation(sc, series, set);
  if (sc.tracking) r.tracking = io::evaluate_tracking(*sc.tracking, series, set);
  r.passed = io::passed_overall(r.steps, r.hold, r.saturation, r.tracking);
}

// Figure name in summary.json: "<channel>.<figure>" for steps ("roll.overshoot_pct"; a second step
// of the same channel gets "roll#2.overshoot_pct"), "hold.<figure>" for the hold, "saturation.<figure>" for
// the rotor and tilt saturation (every run has them; null when the run could not be flown), "tracking.<figure>"
// for the tracking figures of a scenario with a trajectory or analysis.tracking.
std::vector<std::pair<std::string, std::optional<double>>> figures_of(const RunResult& r, const io::Scenario& sc) {
  std::vector<std::pair<std::string, std::optional<double>>> out;
  std::map<std::string, int> seen;
  const bool ok = r.error.empty();
  for (std::size_t i = 0; i < sc.steps.size(); ++i) {
    const std::string& ch = sc.steps[i].channel;
    const int n = ++seen[ch];
    const std::string prefix = n == 1 ? ch : fmt::format("{}#{}", ch, n);
    for (const auto& name : analysis::figure_names()) {
      out.emplace_back(prefix + "." + name,
                       ok && i < r.steps.size() ? analysis::figure(r.steps[i].figures, name) : std::nullopt);
    }
  }
  // Every figure of `names` as "<group>.<name>": the result's value, or null when the run was not
  // flown or the result lacks it.
  const auto add = [&](const char* group, const std::vector<std::string>& names, const auto& result) {
    for (const auto& name : names) {
      std::optional<double> v;
      if (ok && result) {
        if (auto it = result->figures.find(name); it != result->figures.end()) v = it->second;
      }
      out.emplace_back(std::string(group) + "." + name, v);
    }
  };
  if (sc.hold) add("hold", io::hold_figure_names(), r.hold);
  add("saturation", io::saturation_figure_names(), r.saturation);
  if (sc.tracking) add("tracking", analysis::tracking_figure_names(), r.tracking);
  return out;
}

nlohmann::json values_json(const Sample& s) {
  nlohmann::json v = nlohmann::json::object();
  for (const auto& [k, x] : s.values) v[k] = x;
  return v;
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

nlohmann::json header_json(const Plan& plan) {
  nlohmann::json j;
  j["scenario"] = plan.nominal.name;
  j["scenario_file"] = plan.scenario_file;
  j["seed"] = plan.seed;
  j["runs"] = plan.runs;
  j["runs_per_point"] = plan.repeats;
  j["sampler"] = to_string(plan.sampler);
  // Written only when not the default, so the header of a sweep judged against its spec is that of a
  // sweep from before --judge existed (--resume and merge compare headers).
  if (plan.judge != io::Judge::kSpec) j["judge"] = io::to_string(plan.judge);
  j["vary"] = nlohmann::json::array();
  for (const Vary& v : plan.vary) {
    nlohmann::json keys = nlohmann::json::array();
    nlohmann::json fields = nlohmann::json::array();
    for (const Key& k : v.keys) {
      nlohmann::json kj = {{"path", k.path}, {"stream", k.stream}, {"applies_to", k.is_vehicle ? "plant" : "scenario"}};
      kj["nominal"] = k.nominal ? nlohmann::json(*k.nominal) : nlohmann::json();
      kj["declared_range"] = k.declared ? nlohmann::json::array({k.declared->min, k.declared->max}) : nlohmann::json();
      keys.push_back(kj);
      fields.push_back(k.stream);
    }
    nlohmann::json vj = {{"spec", v.spec},
                         {"key", v.name},
                         {"distribution", to_string(v.distribution)},
                         {"keys", keys},
                         {"fields", fields}};
    switch (v.distribution) {
      case Distribution::kPercent: vj["percent"] = v.a * 100.0; break;
      case Distribution::kUniform:
        vj["min"] = v.a;
        vj["max"] = v.b;
        break;
      case Distribution::kNormal:
        vj["mean"] = v.a;
        vj["sigma"] = v.b;
        break;
      case Distribution::kGrid: vj["values"] = v.values; break;
    }
    j["vary"].push_back(vj);
  }
  return j;
}

nlohmann::json per_run_json(const Plan& plan, const RunResult& r) {
  nlohmann::json run = {{"index", r.sample.index}, {"seed", r.sample.seed}, {"passed", r.passed}};
  run["values"] = values_json(r.sample);
  run["factors"] = r.sample.factors;
  nlohmann::json figs = nlohmann::json::object();
  for (const auto& [name, v] : figures_of(r, plan.nominal)) figs[name] = v ? nlohmann::json(*v) : nlohmann::json();
  run["figures"] = figs;
  if (!r.error.empty()) run["error"] = r.error;
  if (r.controller_failed) run["error_cause"] = "controller";
  if (!r.passed) run["failed_criteria"] = r.failed_criteria;
  return run;
}

namespace {

void sort_by_index(std::vector<nlohmann::json>& per_run) {
  std::sort(per_run.begin(), per_run.end(), [](const auto& a, const auto& b) {
    return a.at("index").template get<int>() < b.at("index").template get<int>();
  });
}

// The summary of the runs of `per_run` (sorted, checked): header, passed, pass_rate over them, per_run
// and the figures' statistics.
nlohmann::json summarise(const nlohmann::json& header, std::vector<nlohmann::json> per_run) {
  const auto flown = static_cast<std::ptrdiff_t>(per_run.size());
  nlohmann::json j = header;
  const auto passed =
      std::count_if(per_run.begin(), per_run.end(), [](const auto& r) { return r.at("passed").template get<bool>(); });
  j["passed"] = passed;
  j["pass_rate"] = flown > 0 ? static_cast<double>(passed) / static_cast<double>(flown) : 0.0;
  std::map<std::string, std::vector<std::optional<double>>> values;
  for (const auto& r : per_run) {
    for (const auto& [name, v] : r.at("figures").items()) {
      values[name].push_back(v.is_null() ? std::nullopt : std::optional<double>(v.get<double>()));
    }
  }
  nlohmann::json dist = nlohmann::json::object();
  for (const auto& [name, list] : values) {
    const FigureStats d = figure_stats(list);
    nlohmann::json f = {{"count", d.count}, {"missing", d.missing}};
    if (d.count > 0) {
      f.update({{"min", d.min},
                {"max", d.max},
                {"mean", d.mean},
                {"std", d.std},
                {"p5", d.p5},
                {"p25", d.p25},
                {"p50", d.p50},
                {"p75", d.p75},
                {"p95", d.p95}});
    }
    dist[name] = f;
  }
  j["per_run"] = std::move(per_run);
  j["figures"] = dist;
  return j;
}

}  // namespace

nlohmann::json summary_json(const nlohmann::json& header, std::vector<nlohmann::json> per_run) {
  const int runs = header.at("runs").get<int>();
  sort_by_index(per_run);
  for (std::size_t i = 0; i < per_run.size(); ++i) {
    const int index = per_run[i].at("index").get<int>();
    if (index != static_cast<int>(i)) {
      throw std::invalid_argument(index < static_cast<int>(i) ? fmt::format("run {} appears twice", index)
                                                              : fmt::format("run {} is missing", i));
    }
  }
  if (static_cast<int>(per_run.size()) != runs) {
    throw std::invalid_argument(per_run.size() < static_cast<std::size_t>(runs)
                                    ? fmt::format("run {} is missing", per_run.size())
                                    : fmt::format("{} runs for a sweep of {}", per_run.size(), runs));
  }
  return summarise(header, std::move(per_run));
}

nlohmann::json partial_summary_json(const nlohmann::json& header, std::vector<nlohmann::json> per_run) {
  const int runs = header.at("runs").get<int>();
  sort_by_index(per_run);
  for (std::size_t i = 0; i < per_run.size(); ++i) {
    const int index = per_run[i].at("index").get<int>();
    if (index < 0 || index >= runs)
      throw std::invalid_argument(fmt::format("run {} is not in a sweep of {}", index, runs));
    if (i > 0 && per_run[i - 1].at("index").get<int>() == index) {
      throw std::invalid_argument(fmt::format("run {} appears twice", index));
    }
  }
  const std::size_t finished = per_run.size();
  nlohmann::json j = summarise(header, std::move(per_run));
  j["partial"] = {{"finished", finished}, {"runs", runs}};
  return j;
}

std::vector<nlohmann::json> finished_runs(const fs::path& dir, const nlohmann::json& header, const std::string& shard,
                                          bool& complete) {
  const fs::path file = dir / (shard.empty() ? "summary.json" : "shard.json");
  std::ifstream in(file);
  if (!in) {
    throw std::invalid_argument(fmt::format(
        "{}: not found, so which runs finished is unknown (was the sweep killed before it could write it?); "
        "start the sweep again with --force instead of --resume",
        file.string()));
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
    // summary.json holds the header's keys at its top; shard.json under "header".
    nlohmann::json as_shard =
        shard.empty() ? nlohmann::json{{"header", j}, {"per_run", j.value("per_run", nlohmann::json())}} : j;
    check_shard_json(as_shard);
    nlohmann::json theirs = as_shard.at("header");
    if (shard.empty()) {
      for (const char* k : {"passed", "pass_rate", "per_run", "figures", "partial"}) theirs.erase(k);
    }
    if (theirs != header) {
      std::string differ;
      for (const auto& [k, v] : header.items()) {
        if (!theirs.contains(k) || theirs.at(k) != v) differ += (differ.empty() ? "" : ", ") + k;
      }
      throw std::invalid_argument(
          fmt::format("the sweep there is another one ({} differ{}); resume it with the options it was started with, "
                      "or start this one in another folder",
                      differ.empty() ? "its header" : differ, differ.find(',') == std::string::npos ? "s" : ""));
    }
    if (!shard.empty() && j.value("shard", std::string()) != shard) {
      throw std::invalid_argument(
          fmt::format("it is shard {}, not shard {}", j.value("shard", std::string("?")), shard));
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(
        fmt::format("{}: not a sweep's results (cut short? {}); start the sweep again with "
                    "--force",
                    file.string(), e.what()));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{}: {}", file.string(), e.what()));
  }
  complete = !j.contains("partial");
  std::vector<nlohmann::json> per_run = j.at("per_run").get<std::vector<nlohmann::json>>();
  const int runs = header.at("runs").get<int>();
  std::set<int> seen;
  for (const auto& r : per_run) {
    const int index = r.at("index").get<int>();
    if (index < 0 || index >= runs || !seen.insert(index).second) {
      throw std::invalid_argument(fmt::format("{}: run {} is out of range or appears twice", file.string(), index));
    }
  }
  return per_run;
}

void check_shard_json(const nlohmann::json& shard) {
  const auto got = [](const nlohmann::json& v) {
    if (v.is_object()) return std::string("an object");
    if (v.is_array()) return std::string("an array");
    const std::string text = v.dump();
    return text.size() > 40 ? text.substr(0, 37) + "..." : text;
  };
  const auto object = [&](const nlohmann::json& v, const std::string& where) {
    if (!v.is_object()) throw std::invalid_argument(where + ": expected an object, got " + got(v));
  };
  const auto field = [&](const nlohmann::json& v, const std::string& where, const char* key) -> const nlohmann::json& {
    if (!v.contains(key)) {
      throw std::invalid_argument(fmt::format("{}'{}' is missing", where.empty() ? "" : where + ": ", key));
    }
    return v.at(key);
  };
  const auto whole = [&](const nlohmann::json& v, const std::string& where) {
    if (!v.is_number_integer()) throw std::invalid_argument(where + ": expected a whole number, got " + got(v));
  };
  object(shard, "shard.json");
  const nlohmann::json& header = field(shard, "", "header");
  object(header, "header");
  whole(field(header, "header", "runs"), "header.runs");
  const nlohmann::json& per_run = field(shard, "", "per_run");
  if (!per_run.is_array()) throw std::invalid_argument("per_run: expected an array, got " + got(per_run));
  for (std::size_t i = 0; i < per_run.size(); ++i) {
    const std::string where = fmt::format("per_run[{}]", i);
    const nlohmann::json& r = per_run[i];
    object(r, where);
    whole(field(r, where, "index"), where + ".index");
    if (!field(r, where, "passed").is_boolean()) {
      throw std::invalid_argument(where + ".passed: expected true or false, got " + got(r.at("passed")));
    }
    const nlohmann::json& figures = field(r, where, "figures");
    object(figures, where + ".figures");
    for (const auto& [name, v] : figures.items()) {
      if (!v.is_number() && !v.is_null()) {
        throw std::invalid_argument(
            fmt::format("{}.figures[\"{}\"]: expected a number or null, got {}", where, name, got(v)));
      }
    }
  }
}

Origin origin_of(const std::string& scenario_file, const fs::path& cwd, const char* python_path_env) {
  Origin o;
  const auto absolute = [&](const fs::path& p) { return (p.is_absolute() ? p : cwd / p).lexically_normal(); };
  o.scenario_file = absolute(scenario_file).string();
  const auto add = [&](const fs::path& folder) {
    std::string text = absolute(folder).string();
    while (text.size() > 1 && text.back() == '/') text.pop_back();  // "a/b/" and "a/b" are one folder
    if (std::find(o.python_path.begin(), o.python_path.end(), text) == o.python_path.end())
      o.python_path.push_back(text);
  };
  o.cwd = absolute(".").string();
  while (o.cwd.size() > 1 && o.cwd.back() == '/') o.cwd.pop_back();
  // As the Python controller loader searches: the scenario's folder, the current directory, PYTHONPATH.
  add(fs::path(o.scenario_file).parent_path());
  add(cwd);
  const std::string env = python_path_env ? python_path_env : "";
  std::size_t b = 0;
  while (b <= env.size() && !env.empty()) {
    const std::size_t e = std::min(env.find(':', b), env.size());
    add(env.substr(b, e - b).empty() ? fs::path(".") : fs::path(env.substr(b, e - b)));  // "" is the cwd
    b = e + 1;
  }
  return o;
}

nlohmann::json origin_json(const Origin& o) {
  return {{"scenario_file", o.scenario_file}, {"cwd", o.cwd}, {"python_path", o.python_path}};
}

std::optional<Origin> read_origin(const fs::path& dir) {
  const fs::path file = dir / kOriginFile;
  if (!fs::exists(file)) return std::nullopt;
  std::ifstream in(file);
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    Origin o;
    o.scenario_file = j.at("scenario_file").get<std::string>();
    o.cwd = j.at("cwd").get<std::string>();
    o.python_path = j.at("python_path").get<std::vector<std::string>>();
    if (!fs::path(o.scenario_file).is_absolute()) throw std::invalid_argument("scenario_file is not an absolute path");
    return o;
  } catch (const std::exception& e) {
    throw io::ConfigError(
        fmt::format("{}: not a sweep's origin record ({}); remove it to continue without it", file.string(), e.what()));
  }
}

std::string python_path_env(const Origin& o, const char* current) {
  std::vector<std::string> entries = o.python_path;
  const std::string env = current ? current : "";
  std::size_t b = 0;
  while (!env.empty() && b <= env.size()) {
    const std::size_t e = std::min(env.find(':', b), env.size());
    const std::string entry = env.substr(b, e - b);
    if (!entry.empty() && std::find(entries.begin(), entries.end(), entry) == entries.end()) entries.push_back(entry);
    b = e + 1;
  }
  std::string out;
  for (const auto& entry : entries) out += (out.empty() ? "" : ":") + entry;
  return out;
}

std::string scenario_source_of(const Origin& o) {
  std::error_code ec;
  return fs::is_directory(fs::path(o.scenario_file).parent_path(), ec) ? o.scenario_file : std::string();
}

Plan plan_of(const fs::path& dir) {
  nlohmann::json h;
  fs::path file = dir / "summary.json";
  if (!fs::exists(file)) file = dir / "shard.json";
  std::ifstream in(file);
  if (!in)
    throw std::runtime_error((dir / "summary.json").string() + ": not found (nor shard.json): not a sweep folder");
  try {
    in >> h;
    if (h.contains("header")) h = h.at("header");
    std::vector<std::string> specs;
    for (const auto& v : h.at("vary")) specs.push_back(v.at("spec").get<std::string>());
    const fs::path scenario = dir / "scenario.yaml";
    if (!fs::exists(scenario)) throw std::runtime_error(scenario.string() + ": not found");
    // Loaded as if where the sweep's scenario file is, so that what it names relative to its folder
    // (a Python controller's module, ...) is found from any current directory.
    const std::optional<Origin> origin = read_origin(dir);
    Plan p = make_plan(scenario.string(), specs, h.at("seed").get<std::uint64_t>(), h.at("runs_per_point").get<int>(),
                       h.at("sampler").get<std::string>() == "lhs" ? Sampler::kLhs : Sampler::kRandom,
                       origin ? scenario_source_of(*origin) : std::string());
    if (p.runs != h.at("runs").get<int>()) throw std::runtime_error("the plan gives another number of runs");
    const std::string judge = h.value("judge", std::string("spec"));
    const auto set = io::parse_judge(judge);
    if (!set) throw std::runtime_error("judge: got '" + judge + "', expected spec, paper or none");
    p.judge = *set;
    return p;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(file.string() + ": not a sweep's summary (" + e.what() + ")");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  } catch (const io::ConfigError& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace quadcosim::sweep
