// `quadcosim margins [SCENARIO] [--controller TYPE] [--measure] [--out DIR] [--json] [--no-plots]`: gain,
// phase and delay margins of every loop of the scenario's controller about level hover, analytic for
// the paper controller and measured in simulation for any (hosts/margins_report.hpp, docs/margins.md).
// This file reads the flags, prints the report and writes its files.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "hosts/margins_report.hpp"
#include "io/output_folder.hpp"

namespace quadcosim::app {

namespace {

bool write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
  f.close();
  if (!f) {
    std::cerr << "error: cannot write " << p.string() << '\n';
    return false;
  }
  return true;
}
}  // namespace

CLI::App* add_margins_subcommand(CLI::App& app, MarginsOptions& o) {
  auto* cmd =
      app.add_subcommand("margins", "gain, phase and delay margins of each control loop about hover (docs/margins.md)");
  cmd->add_option("scenario", o.scenario, "scenario YAML (default: the paper's vehicle and controller)")
      ->check(CLI::ExistingFile);
  add_controller_type_option(*cmd, o.controller);  // any but the paper's is measured
  cmd->add_flag("--measure", o.measure,
                "the paper controller: measure its margins in simulation too, beside the analytic ones (other "
                "controllers are always measured)");
  cmd->add_option("--amplitude", o.amplitude, "measured: injected sinusoid, as a fraction of the hover rotor speed")
      ->check(CLI::Range(1e-7, 0.1));
  cmd->add_option("--frequencies", o.frequencies, "measured: log-spaced frequencies up to the Nyquist frequency")
      ->check(CLI::Range(4, 400));
  cmd->add_option("--min-frequency", o.min_frequency, "measured: the lowest frequency [rad/s]")
      ->check(CLI::Range(1e-3, 1e4));
  cmd->add_option(
      "--out", o.out_dir,
      "write margins.json, margins.txt, the analytic and/or measured response CSV and Bode/Nyquist PNGs here: a "
      "new or empty folder");
  cmd->add_flag("--force", o.force,
                "--out holds a previous command's outputs or other files: remove exactly the outputs its manifest "
                "lists first (files quadcosim did not write are kept)");
  cmd->add_flag("--json", o.json, "print the margins as one JSON object instead of the table");
  cmd->add_flag("!--no-plots", o.plots, "with --out: skip the PNGs");
  return cmd;
}

int margins_command(const MarginsOptions& o, const io::ScenarioResolvers& resolvers) {
  if (!o.plots && o.out_dir.empty()) {
    std::cerr << "error: --no-plots needs --out (plots are only written into an output directory)\n";
    return exit_code::kBadInput;
  }
  if (o.force && o.out_dir.empty()) {
    std::cerr << "error: --force needs --out (it concerns the output folder)\n";
    return exit_code::kBadInput;
  }
  // A bad file (io::ConfigError), a failed LQR design (control::CareError) or a vehicle that cannot
  // hover: bad input (run_guarded).
  const hosts::MarginsPlan plan = hosts::plan_margins(o.scenario, o.controller, o.measure, resolvers);
  if (!plan.measured && (o.amplitude != MarginsOptions{}.amplitude || o.frequencies != MarginsOptions{}.frequencies ||
                         o.min_frequency != MarginsOptions{}.min_frequency)) {
    std::cerr << "error: --amplitude, --frequencies and --min-frequency set the measurement; the paper controller's "
                 "margins are analytic unless --measure\n";
    return exit_code::kBadInput;
  }
  std::optional<io::OutputFolder> folder;
  if (!o.out_dir.empty()) folder.emplace(io::OutputFolder::claim(o.out_dir, "margins", {.force = o.force}, std::cerr));

  analysis::MeasurementOptions measurement;
  measurement.amplitude = o.amplitude;
  measurement.points = o.frequencies;
  measurement.omega_min_rad_s = o.min_frequency;
  const hosts::MarginsReport r = hosts::margins_report(plan, measurement, folder.has_value(), std::cerr);

  if (o.json)
    std::cout << r.doc.dump(2) << '\n';
  else
    std::cout << r.table;

  if (folder) {
    const std::filesystem::path out(o.out_dir);
    if (plan.analytic && !write_file(out / "frequency_response.csv", r.frequency_response_csv))
      return exit_code::kOutput;
    if (plan.measured && !write_file(out / "measured_response.csv", r.measured_response_csv)) return exit_code::kOutput;
    if (!write_file(out / "margins.json", r.doc.dump(2) + "\n") || !write_file(out / "margins.txt", r.table))
      return exit_code::kOutput;
    if (o.plots && !run_tool("plot_margins.py", {o.out_dir})) return exit_code::kOutput;
    folder->record("outputs");
  }
  return r.all_stable ? exit_code::kOk : exit_code::kFailed;
}

}  // namespace quadcosim::app
