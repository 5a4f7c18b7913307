// `quadcosim fmu export plant|controller [--scenario FILE] [--controller TYPE] [--fmi 2|3] --out NAME.fmu`
// and `quadcosim fmu info FILE.fmu`: the flags, where the FMU library is, and what is printed; packing
// and reading FMUs is hosts/fmu_export.hpp's.
//
// Where export finds the FMU library (quadcosim_fmu.so), first match wins: $QUADCOSIM_FMU_LIBRARY (a
// file); beside the quadcosim executable; for an executable in <prefix>/bin/, <prefix>/lib/ (the build
// tree: bin/ and lib/) and <prefix>/lib/quadcosim/ (an installed quadcosim); the path the build tree
// that built this executable put it at.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/resources.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "hosts/fmu_export.hpp"

namespace quadcosim::app {

namespace {

namespace fs = std::filesystem;

/// The FMU library to pack, or an error naming every place looked at.
fs::path find_fmu_library() {
  const std::string file = QUADCOSIM_FMU_LIBRARY_NAME;
  if (const char* env = std::getenv("QUADCOSIM_FMU_LIBRARY"); env != nullptr && *env != '\0') {
    if (fs::is_regular_file(env)) return env;
    throw std::runtime_error(fmt::format("the FMU library {} named by QUADCOSIM_FMU_LIBRARY does not exist", env));
  }
  std::vector<fs::path> candidates;
  if (const fs::path dir = executable_dir(); !dir.empty()) {
    candidates.push_back(dir / file);
    candidates.push_back(dir.parent_path() / "lib" / file);  // the build tree: bin/ and lib/
    candidates.push_back(dir.parent_path() / "lib" / "quadcosim" / file);
  }
  candidates.emplace_back(QUADCOSIM_FMU_LIBRARY_BUILD_PATH);
  std::string looked;
  std::vector<fs::path> seen;
  for (const fs::path& c : candidates) {
    if (fs::is_regular_file(c)) return c;
    const fs::path normal = c.lexically_normal();
    if (std::find(seen.begin(), seen.end(), normal) != seen.end()) continue;
    seen.push_back(normal);
    looked += "\n  " + normal.string();
  }
  throw std::runtime_error(fmt::format(
      "the FMU library {} was not found; looked at:{}\nbuild it (cmake --build BUILD --target quadcosim_fmu) or set "
      "QUADCOSIM_FMU_LIBRARY to its path",
      file, looked));
}

int export_fmu(const FmuOptions& o, const io::ScenarioResolvers& resolvers) {
  const hosts::FmuExport r = hosts::export_fmu({.kind = o.kind,
                                                .scenario = o.scenario,
                                                .controller = o.controller,
                                                .fmi = o.fmi,
                                                .out = o.out,
                                                .generation_tool = std::string("quadcosim ") + QUADCOSIM_VERSION},
                                               find_fmu_library, resolvers);
  const fmi::ModelDescription& md = r.description;
  int inputs = 0, outputs = 0, parameters = 0;
  for (const fmi::Variable& v : md.variables) {
    inputs += v.causality == fmi::Causality::kInput;
    outputs += v.causality == fmi::Causality::kOutput;
    parameters += v.causality == fmi::Causality::kParameter;
  }
  std::cout << fmt::format("wrote {}: FMI {} co-simulation FMU '{}' ({}), {} {}\n", o.out, md.fmi_version,
                           md.model_name, md.model_identifier,
                           r.config.fmi_version == fmi::FmiVersion::k2 ? "guid" : "instantiationToken", md.guid);
  std::cout << fmt::format("  {} inputs, {} outputs, {} parameters; communication step {} s (doStep: {})\n", inputs,
                           outputs, parameters, md.step_size.value_or(0.0),
                           md.can_handle_variable_step ? "any step" : "whole multiples of it");
  std::cout << fmt::format("  binary binaries/{}/{}.so from {}\n", r.platform, md.model_identifier, r.library.string());
  if (r.config.trajectory)
    std::cout << fmt::format("  reference: {} (carried in the FMU; {} = true takes the ref.* inputs instead)\n",
                             trajectory::make_trajectory(*r.config.trajectory)->describe(), fmi::names::kRefExternal);
  for (const std::string& n : r.notes) std::cout << "  note: " << n << '\n';
  return exit_code::kOk;
}

// ---- info -----------------------------------------------------------------------------------------

std::string type_name(fmi::VariableType t, fmi::FmiVersion v) {
  if (v == fmi::FmiVersion::k3) {
    if (t == fmi::VariableType::kReal) return "Float64";
    if (t == fmi::VariableType::kInteger) return "Int32";
  }
  return std::string(fmi::to_string(t));
}

int info(const FmuOptions& o) {
  const hosts::FmuInfo fmu = hosts::read_fmu_info(o.fmu);
  const fmi::ModelDescription& md = fmu.description;
  const std::string& here = fmu.here;
  const bool runs_here = fmu.runs_here;
  std::string binaries;
  for (const std::string& p : fmu.platforms) binaries += (binaries.empty() ? "" : ", ") + p;

  const auto row = [](std::string_view key, const std::string& value) {
    std::cout << fmt::format("{:<19} {}\n", key, value);
  };
  row("FMU", o.fmu);
  row("FMI version", md.fmi_version + " co-simulation");
  row("model", md.model_name + (md.description.empty() ? "" : " (" + md.description + ")"));
  row(md.version == fmi::FmiVersion::k2 ? "guid" : "instantiationToken", md.guid);
  if (!md.generation_tool.empty()) row("generated by", md.generation_tool);
  row("modelIdentifier", md.model_identifier);
  row("binaries", (binaries.empty() ? std::string("none") : binaries) +
                      (runs_here ? fmt::format(" (runs here: {}/{}.so)", here, md.model_identifier)
                                 : fmt::format(" (no {}/{}.so: not for this machine)", here.empty() ? "binary" : here,
                                               md.model_identifier)));
  row("variable step", md.can_handle_variable_step ? "yes (canHandleVariableCommunicationStepSize)" : "no");
  if (md.start_time || md.stop_time || md.step_size) {
    std::string e;
    if (md.start_time) e += fmt::format("start {} s", *md.start_time);
    if (md.stop_time) e += fmt::format("{}stop {} s", e.empty() ? "" : ", ", *md.stop_time);
    if (md.step_size) e += fmt::format("{}step {} s", e.empty() ? "" : ", ", *md.step_size);
    row("default experiment", e);
  }
  std::map<fmi::Causality, int> count;
  for (const fmi::Variable& v : md.variables) ++count[v.causality];
  row("variables",
      fmt::format("{} ({} inputs, {} outputs, {} parameters)", md.variables.size(), count[fmi::Causality::kInput],
                  count[fmi::Causality::kOutput], count[fmi::Causality::kParameter]));

  std::size_t name_w = 4, unit_w = 4, start_w = 5;
  for (const fmi::Variable& v : md.variables) {
    name_w = std::max(name_w, v.name.size());
    unit_w = std::max(unit_w, v.unit.size());
    start_w = std::min<std::size_t>(24, std::max(start_w, v.start.value_or("").size()));
  }
  std::cout << '\n'
            << fmt::format("{:<{}}  {:>5}  {:<19}  {:<11}  {:<7}  {:<{}}  {:<{}}  {}\n", "name", name_w, "vr",
                           "causality", "variability", "type", "unit", unit_w, "start", start_w, "description");
  for (const fmi::Variable& v : md.variables) {
    std::cout << fmt::format("{:<{}}  {:>5}  {:<19}  {:<11}  {:<7}  {:<{}}  {:<{}}  {}\n", v.name, name_w, v.vr,
                             fmi::to_string(v.causality), fmi::to_string(v.variability), type_name(v.type, md.version),
                             v.unit.empty() ? "-" : v.unit, unit_w, v.start.value_or("-"), start_w, v.description);
  }
  return exit_code::kOk;
}

}  // namespace

CLI::App* add_fmu_subcommand(CLI::App& app, FmuOptions& o) {
  auto* fmu = app.add_subcommand("fmu", "FMI co-simulation: export the plant or controller as an FMU, inspect an FMU");
  fmu->require_subcommand(1);

  auto* exp = fmu->add_subcommand(
      "export",
      "write quadcosim's plant or controller as an FMI 2.0 (or 3.0) co-simulation FMU, configured from a scenario");
  exp->add_option("kind", o.kind, "plant or controller")->required()->check(CLI::IsMember({"plant", "controller"}));
  exp->add_option("--scenario", o.scenario,
                  "scenario YAML: vehicle, initial state, rates, realism, controller and setpoint (default: the "
                  "paper's vehicle and controller at rest)")
      ->check(CLI::ExistingFile);
  add_controller_type_option(*exp, o.controller);
  exp->add_option("--fmi", o.fmi, "FMI version: 2 (FMI 2.0) or 3 (FMI 3.0)")->check(CLI::IsMember({2, 3}));
  exp->add_option("--out", o.out,
                  "the .fmu file to write (replaced if it exists). The FMU library quadcosim_fmu.so is taken from "
                  "$QUADCOSIM_FMU_LIBRARY, else beside the quadcosim executable, in <prefix>/lib/ or "
                  "<prefix>/lib/quadcosim/ (quadcosim in <prefix>/bin/), else where this build put it")
      ->required();
  exp->parse_complete_callback([exp, &o] {
    o.verb = "export";
    refuse_idle_flags(*exp, {{"--controller", o.kind == "controller", "plant; it chooses the controller FMU's type"}});
  });

  auto* inf = fmu->add_subcommand(
      "info", "what an FMU declares: FMI version, model, GUID, binaries, variables with causality, unit and start");
  inf->add_option("fmu", o.fmu, ".fmu file")->required()->check(CLI::ExistingFile);
  inf->parse_complete_callback([&o] { o.verb = "info"; });
  return fmu;
}

int fmu_command(const FmuOptions& o, const io::ScenarioResolvers& resolvers) {
  return o.verb == "export" ? export_fmu(o, resolvers) : info(o);
}

}  // namespace quadcosim::app
