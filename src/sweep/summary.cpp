// sweep/sweep.hpp: what a sweep's folder holds about its runs: the header, each run's entry, the
// summaries and their statistics, the shards' files and the runs a resumed sweep already has.
#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include "analysis/step_metrics.hpp"
#include "analysis/tracking.hpp"
#include "sweep/statistics.hpp"
#include "sweep/sweep.hpp"

namespace quadcosim::sweep {

namespace fs = std::filesystem;

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
  add("saturation", io::saturation_figure_names(sc.vehicle.rotor_count), r.saturation);
  if (sc.tracking) add("tracking", analysis::tracking_figure_names(), r.tracking);
  return out;
}

nlohmann::json values_json(const Sample& s) {
  nlohmann::json v = nlohmann::json::object();
  for (const auto& [k, x] : s.values) v[k] = x;
  return v;
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

}  // namespace quadcosim::sweep
