// What flew in a run, and how it was started: the provenance record every run folder carries
// (docs/outputs.md, "Provenance"). One record is made per run by describe_run() and written, the same
// facts each time, into metrics.json ("provenance"), metadata.yaml (`quadcosim_provenance:`) and, as
// the effective scenario, scenario.yaml; report.html, the plots, `summary` and `compare` read it back
// from metrics.json, so the controller a run is labelled with is computed in one place.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/scenario.hpp"

namespace YAML {
class Node;
}

namespace quadcosim::io {

/// How the run was hosted and started: what describe_run() cannot read from the scenario.
struct RunContext {
  std::string transport = "inproc";  ///< "inproc" or "dds" (plant and controller as two processes)
  std::string clock = "lockstep";    ///< "lockstep" or "realtime"
  /// The controller type the run was told to fly instead of the file's (`--controller`, the Python
  /// module's controller="..."); "python" for a Python object given to quadcosim.run(); "" for none.
  std::string controller_override;
  /// A Python controller's "module:Class" (the effective scenario's controller.python), else "".
  std::string python_target;
  /// What finds python_target's module file (the host's ScenarioResolvers::python_module); empty: the
  /// record's module file and hash are null.
  PythonModuleLocator python_module;
};

/// The provenance record of a run flying `flown` (the effective scenario: the override already
/// applied), as JSON (its schema in docs/outputs.md): controller (label, type, the file's type,
/// parameter values, a Python class's module:Class with its module file and SHA-256, an FMU's path
/// and SHA-256), transport, clock, command line (this process's argv), quadcosim version, git commit
/// ("unknown" outside a git checkout), host name, and the scenario file with its SHA-256. A file that
/// cannot be read gets a null hash rather than an error: the run itself has already read it.
nlohmann::json describe_run(const Scenario& flown, const RunContext& context);

/// controller.python of a scenario document ("" when it has none).
std::string python_target_of(const YAML::Node& root);

/// The label a run's controller goes by in reports, plots, `summary` and `compare`: its registry type
/// ("se3"), "python module:Class" or "fmu NAME.fmu".
std::string controller_label(const nlohmann::json& provenance);

/// The scenario as flown, as the text of a scenario file: the file's bytes when nothing replaced its
/// controller, else the parsed file with `controller_override` applied (io::set_controller_type),
/// after a comment that says so (the file's comments are not kept).
std::string effective_scenario_text(const std::string& scenario_file, const std::string& controller_override);

/// `root` (a scenario document) as a scenario file's text, after `comment` lines (each prefixed "# ").
std::string scenario_text(const YAML::Node& root, const std::string& comment);

/// Adds the record to `dir`/metadata.yaml as a top-level `quadcosim_provenance:` mapping beside
/// `rosbag2_bagfile_information:` (which ros2 bag reads alone), replacing a previous one; written
/// atomically. Does nothing when there is no metadata.yaml (a run stopped before recording).
void add_provenance_to_bag_metadata(const std::filesystem::path& dir, const nlohmann::json& provenance);

/// `metrics` with the record under "provenance", written to `path` as write_metrics_json writes.
void write_metrics_with_provenance(const std::filesystem::path& path, nlohmann::json metrics,
                                   const nlohmann::json& provenance);

/// SHA-256 of the file's bytes as 64 lowercase hex digits; "" when it cannot be read.
std::string file_sha256(const std::filesystem::path& path);

/// This process's command line (/proc/self/cmdline), one entry per argument.
std::vector<std::string> process_command_line();

}  // namespace quadcosim::io
