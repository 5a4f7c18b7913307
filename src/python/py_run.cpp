// python/py_run.hpp: a run from Python, recorded and judged as `quadcosim run` does it.
#include "python/py_run.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <yaml-cpp/yaml.h>

#include <stdlib.h>

#include <atomic>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "control/care.hpp"
#include "hosts/inprocess_run.hpp"
#include "hosts/swarm_inprocess.hpp"
#include "io/output_folder.hpp"
#include "io/provenance.hpp"
#include "io/scenario.hpp"
#include "io/scenario_limits.hpp"
#include "io/trajectory_csv.hpp"
#include "io/yaml_reader.hpp"
#include "python/module_resolvers.hpp"
#include "python/py_controller.hpp"
#include "python/py_scenario.hpp"
#include "sensors/suite.hpp"
#include "sim/simulation.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace quadcosim::python {

namespace {

/// trajectory.csv as columns of doubles (every column of the file, by its header name).
std::vector<std::pair<std::string, std::vector<double>>> read_csv_columns(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open for reading");
  std::string line;
  std::getline(in, line);
  std::vector<std::pair<std::string, std::vector<double>>> columns;
  for (std::size_t b = 0;;) {
    const std::size_t e = line.find(',', b);
    columns.push_back({line.substr(b, e - b), {}});
    if (e == std::string::npos) break;
    b = e + 1;
  }
  for (std::size_t row = 2; std::getline(in, line); ++row) {
    const char* p = line.data();
    const char* end = line.data() + line.size();
    for (std::size_t c = 0; c < columns.size(); ++c) {
      double v = 0.0;
      const auto [next, ec] = std::from_chars(p, end, v);
      if (ec != std::errc() || (next != end && *next != ',')) {
        throw std::runtime_error(path.string() + ": line " + std::to_string(row) + ": column " + columns[c].first +
                                 " is not a number");
      }
      columns[c].second.push_back(v);
      p = next == end ? end : next + 1;
    }
  }
  return columns;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A temporary folder, removed with everything in it when this goes.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "quadcosim-run-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temporary folder in " + pattern);
    path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

/// The scenario as flown, as `quadcosim run` writes it: the file, or with the controller applied.
std::string flown_scenario_text(const PyScenario& s) {
  if (s.from_file && s.controller_override != "python") {
    return io::effective_scenario_text(s.source, s.controller_override);
  }
  const std::string comment =
      s.controller_override.empty()
          ? ""
          : "The scenario as flown: " + s.source + " with its controller replaced by the Python class " +
                io::python_target_of(s.root) +
                ".\n(Written by quadcosim from the parsed document; its comments are not kept.)";
  return io::scenario_text(s.root, comment);
}

py::dict columns_dict(std::vector<std::pair<std::string, std::vector<double>>>& columns) {
  py::dict d;
  for (auto& [name, values] : columns) {
    py::array_t<double> a(static_cast<py::ssize_t>(values.size()));
    std::copy(values.begin(), values.end(), a.mutable_data());
    d[py::str(name)] = std::move(a);
  }
  return d;
}

/// Flies `s` as `quadcosim run` does in process; the parts the Python RunResult (or, for a swarm: a
/// scenario with a swarm section or vehicles > 0, the SwarmResult) is made of.
py::dict run(const PyScenario& s, const std::optional<std::string>& out, bool force, const std::string& judge_name,
             int vehicles, int threads) {
  const std::optional<io::Judge> judge = io::parse_judge(judge_name);
  if (!judge) {
    throw py::value_error("judge: got '" + judge_name + "', expected 'spec', 'paper' or 'none'");
  }
  const bool swarm = vehicles > 0 || s.scenario.swarm.has_value();
  const io::SwarmSpec spec = hosts::swarm_spec(s.scenario, vehicles, threads);
  if (swarm) io::check_swarm_fits(spec.layout.vehicles);
  std::optional<TempDir> temp;
  std::optional<io::OutputFolder> folder;
  fs::path dir;
  std::ostringstream notes, info, warn;
  hosts::RunJudgement judged;
  hosts::SwarmJudgement swarm_judged;
  std::vector<std::pair<std::string, std::vector<double>>> columns;
  std::vector<std::string> recorded_dirs;
  std::vector<std::vector<std::pair<std::string, std::vector<double>>>> recorded_columns;
  std::vector<std::string> recorded_metrics, recorded_tables;
  std::string metrics, vehicles_csv;
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    if (out) {
      folder.emplace(io::OutputFolder::claim(*out, "run", {.force = force}, notes));
      dir = *out;
    } else {
      temp.emplace();
      dir = temp->path;
    }
    try {
      const std::string flown = flown_scenario_text(s);
      io::write_file_atomically(dir / "scenario.yaml", flown);
      // Ctrl-C (or any pending Python signal handler's exception) ends the run as it ends the CLI's:
      // what ran stays recorded. Checked every 4096 ticks (~50 µs of simulation) of one vehicle, after
      // each block of ticks of a swarm.
      const auto signalled = [] {
        py::gil_scoped_acquire acquire;
        return PyErr_CheckSignals() != 0;  // the exception stays set for the caller
      };
      const nlohmann::json provenance =
          io::describe_run(s.scenario, {.controller_override = s.controller_override,
                                        .python_target = io::python_target_of(s.root),
                                        .python_module = module_resolvers().python_module});
      if (swarm) {
        recorded_dirs = hosts::make_recorded_dirs(dir, spec, flown);
        interrupted = !hosts::fly_swarm_inprocess(s.scenario, spec, dir, info, [&](double) { return signalled(); });
        if (!interrupted) swarm_judged = hosts::judge_swarm(s.scenario, spec, dir, *judge, provenance);
      } else {
        sim::Tick ticks = 0;
        const auto on_tick = [&](double) { return ++ticks % 4096 == 0 && signalled(); };
        interrupted = !hosts::fly_inprocess(s.scenario, dir, info, warn, on_tick);
        io::add_provenance_to_bag_metadata(dir, provenance);
        if (!interrupted) judged = hosts::judge_run(s.scenario, dir, *judge, provenance);
      }
    } catch (const control::CareError& e) {
      throw io::ConfigError(s.source + ": controller design failed: " + e.what());
    } catch (const std::invalid_argument& e) {
      throw io::ConfigError(s.source + ": " + e.what());
    }
    if (!interrupted && swarm) {
      for (const std::string& d : recorded_dirs) {
        recorded_columns.push_back(read_csv_columns(dir / d / "trajectory.csv"));
        recorded_metrics.push_back(read_text(dir / d / "metrics.json"));
        recorded_tables.push_back(read_text(dir / d / "metrics.txt"));
      }
      metrics = read_text(dir / "summary.json");
      vehicles_csv = read_text(dir / "vehicles.csv");
      for (const std::string& w : swarm_judged.warnings) warn << w << '\n';
    } else if (!interrupted) {
      columns = read_csv_columns(dir / "trajectory.csv");
      metrics = read_text(dir / "metrics.json");
    }
  }
  if (interrupted) throw py::error_already_set();
  py::dict r;
  r["judged"] = io::to_string(*judge);
  r["messages"] = notes.str() + warn.str() + info.str();
  r["out"] = out ? py::object(py::str(*out)) : py::object(py::none());
  if (swarm) {
    py::list recorded;
    for (std::size_t i = 0; i < recorded_dirs.size(); ++i) {
      py::dict v;
      v["namespace"] = "/" + recorded_dirs[i];
      v["trajectory"] = columns_dict(recorded_columns[i]);
      v["metrics_json"] = recorded_metrics[i];
      v["table"] = recorded_tables[i];
      recorded.append(v);
    }
    r["swarm"] = true;
    r["summary_json"] = metrics;
    r["vehicles_csv"] = vehicles_csv;
    r["recorded"] = recorded;
    r["passed"] = *judge == io::Judge::kNone ? py::object(py::none()) : py::object(py::bool_(swarm_judged.passed));
    return r;
  }
  r["swarm"] = false;
  r["trajectory"] = columns_dict(columns);
  r["metrics_json"] = metrics;
  // No verdict under judge="none" (metrics.json's "passed" is null there too).
  r["passed"] = *judge == io::Judge::kNone ? py::object(py::none()) : py::object(py::bool_(judged.passed));
  r["judged_note"] = judged.nothing_note;
  r["table"] = judged.table;
  return r;
}

}  // namespace

void bind_run(py::module_& m) {
  m.def("_run", &run, py::arg("scenario"), py::arg("out"), py::arg("force") = false, py::arg("judge") = "spec",
        py::arg("vehicles") = 0, py::arg("threads") = 0,
        "Runs a scenario in process as `quadcosim run` does; the parts of a RunResult (a SwarmResult for a swarm).");
}

}  // namespace quadcosim::python
