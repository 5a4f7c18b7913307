// `quadcosim fmu export plant|controller [--scenario FILE] [--controller TYPE] [--fmi 2|3] --out NAME.fmu`:
// quadcosim's plant or controller as an FMI co-simulation FMU (fmi/export/fmu_config.hpp says what
// it holds): modelDescription.xml (describe() through write_model_description), the FMU library
// (quadcosim_fmu) as binaries/<platform>/<modelIdentifier>.so and the configuration as
// resources/quadcosim.json, zipped. `quadcosim fmu info FILE.fmu`: what an FMU (any tool's) declares.
//
// Where export finds the FMU library (quadcosim_fmu.so), first match wins: $QUADCOSIM_FMU_LIBRARY (a
// file); beside the quadcosim executable; for an executable in <prefix>/bin/, <prefix>/lib/ (the build
// tree: bin/ and lib/) and <prefix>/lib/quadcosim/ (an installed quadcosim); the path the build tree
// that built this executable put it at.
#include <fmt/format.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/resources.hpp"
#include "controllers/registry.hpp"
#include "fmi/export/fmu_config.hpp"
#include "fmi/model_description.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "fmi/unzip.hpp"
#include "fmi/zip_writer.hpp"
#include "hosts/node_common.hpp"
#include "io/scenario.hpp"

namespace quadcosim::app {

namespace {

namespace fs = std::filesystem;

/// The platform folder of binaries/ for this machine in FMI `version`, or "" when the standard
/// names none (FMI 2 defines Linux folders for x86 only).
std::string platform_folder(fmi::FmiVersion version) {
#if defined(__x86_64__)
  return version == fmi::FmiVersion::k2 ? "linux64" : "x86_64-linux";
#elif defined(__aarch64__)
  return version == fmi::FmiVersion::k2 ? "" : "aarch64-linux";
#else
  (void)version;
  return "";
#endif
}

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

/// The FMU's configuration from the scenario (or the defaults: the paper's vehicle and controller).
fmi::FmuConfig config_from(const FmuOptions& o, std::vector<std::string>& notes) {
  io::Scenario sc;
  if (!o.controller.empty() && io::parse_controller_choice(o.controller).kind != io::ControllerChoice::Kind::kType) {
    throw io::ConfigError("--controller " + o.controller + ": fmu export packs one of quadcosim's controller types (" +
                          controllers::controller_type_names() +
                          "); a class written in Python or an FMU is not packed");
  }
  if (!o.scenario.empty()) {
    sc = io::load_scenario(o.scenario, o.controller);
  } else if (!o.controller.empty()) {
    sc.controller = controllers::make_config(o.controller, sc.vehicle);
  }
  fmi::FmuConfig c;
  c.kind = o.kind == "plant" ? fmi::FmuKind::kPlant : fmi::FmuKind::kController;
  c.fmi_version = o.fmi == 3 ? fmi::FmiVersion::k3 : fmi::FmiVersion::k2;
  const sim::SimulationConfig& sim = sc.simulation;
  c.plant_period_ns = sim.plant.clock.period_ns;
  c.substeps = sim.plant.substeps;
  c.controller_divider = sim.controller_divider;
  if (!o.scenario.empty()) c.stop_time_s = sim.plant.clock.seconds(sim.duration_ticks);
  c.vehicle = sc.vehicle;
  c.initial = io::initial_state(sc);
  c.realism = sim.plant.realism;
  c.realism_namespace = sim.ns;
  // Schedule entries due at t = 0 act before the first control step: they are part of the start.
  control::ControllerConfig cc = sc.controller;
  std::size_t later = 0;
  for (const sim::ScheduledParameter& p : sc.schedule) {
    if (p.tick != 0) {
      ++later;
      continue;
    }
    if (std::string why = control::set_parameter(cc, p.name, p.value); !why.empty())
      throw std::invalid_argument(fmt::format("{}: schedule: {}", o.scenario, why));
  }
  c.controller_type = std::string(cc.type());
  c.setpoint = cc.node.setpoint;
  // The values the scenario changed from the type's defaults for its vehicle.
  const control::ControllerConfig defaults = controllers::make_config(c.controller_type, sc.vehicle);
  for (const control::ParameterSpec& p : cc.controller->parameters()) {
    const std::optional<control::ParameterValue> value = cc.controller->get_parameter(p.name);
    if (value && value != defaults.controller->get_parameter(p.name))
      c.controller_parameters.push_back({std::string(p.name), *value});
  }

  // The trajectory travels inside a controller FMU (its configuration) and is its reference by
  // default: an FMU that flew the setpoint instead would fly a different experiment without a word.
  if (cc.trajectory && c.kind == fmi::FmuKind::kController) {
    if (!sc.trajectory_spec)
      throw io::ConfigError(o.scenario +
                            ": trajectory: this trajectory has no description the FMU can carry, so the controller "
                            "FMU would not fly it; export from a scenario whose trajectory: section describes it");
    c.trajectory = sc.trajectory_spec;
  }

  // What a scenario can say that an FMU does not carry.
  if (later > 0 && c.kind == fmi::FmuKind::kController)
    notes.push_back(
        fmt::format("the scenario's schedule after t = 0 ({} change{}) is not part of the FMU: set the "
                    "controller.* parameters or ref.* inputs from the importer instead",
                    later, later == 1 ? "" : "s"));
  if (sim.plant.command_delay_ticks > 0 && c.kind == fmi::FmuKind::kPlant)
    notes.push_back("simulation.command_delay_ticks is not part of the FMU: the importer decides when commands act");
  if (sim.faults.active()) notes.push_back("the scenario's message faults act on DDS topics, not in the FMU");
  return c;
}

int export_fmu(const FmuOptions& o) {
  if (fs::path(o.out).extension() != ".fmu")
    throw std::invalid_argument(fmt::format("--out: '{}' must end in .fmu", o.out));
  std::vector<std::string> notes;
  fmi::FmuConfig config = config_from(o, notes);
  const std::string platform = platform_folder(config.fmi_version);
  if (platform.empty())
    throw std::invalid_argument(
        fmt::format("--fmi {}: FMI {} names no binaries folder for this machine's architecture", o.fmi, o.fmi));
  config.guid = fmi::make_guid(config);

  fmi::ModelDescription md;
  try {
    md = fmi::describe(config);
  } catch (const fmi::FmuError& e) {  // a controller or realism setting an FMU cannot express
    throw std::invalid_argument(e.what());
  }
  md.generation_tool = std::string("quadcosim ") + QUADCOSIM_VERSION;
  const std::string xml = fmi::write_model_description(md);  // FmuError: a bug, not the user's input
  const fs::path library = find_fmu_library();

  fmi::write_zip(
      o.out, {
                 fmi::ZipEntry::from_bytes("modelDescription.xml", xml),
                 fmi::ZipEntry::from_file("binaries/" + platform + "/" + md.model_identifier + ".so", library, true),
                 fmi::ZipEntry::from_bytes("resources/" + std::string(fmi::kConfigFileName), fmi::to_json(config)),
             });

  int inputs = 0, outputs = 0, parameters = 0;
  for (const fmi::Variable& v : md.variables) {
    inputs += v.causality == fmi::Causality::kInput;
    outputs += v.causality == fmi::Causality::kOutput;
    parameters += v.causality == fmi::Causality::kParameter;
  }
  std::cout << fmt::format("wrote {}: FMI {} co-simulation FMU '{}' ({}), {} {}\n", o.out, md.fmi_version,
                           md.model_name, md.model_identifier,
                           config.fmi_version == fmi::FmiVersion::k2 ? "guid" : "instantiationToken", md.guid);
  std::cout << fmt::format("  {} inputs, {} outputs, {} parameters; communication step {} s (doStep: {})\n", inputs,
                           outputs, parameters, md.step_size.value_or(0.0),
                           md.can_handle_variable_step ? "any step" : "whole multiples of it");
  std::cout << fmt::format("  binary binaries/{}/{}.so from {}\n", platform, md.model_identifier, library.string());
  if (config.trajectory)
    std::cout << fmt::format("  reference: {} (carried in the FMU; {} = true takes the ref.* inputs instead)\n",
                             trajectory::make_trajectory(*config.trajectory)->describe(), fmi::names::kRefExternal);
  for (const std::string& n : notes) std::cout << "  note: " << n << '\n';
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
  std::unique_ptr<fmi::TempDir> dir;
  fmi::ModelDescription md;
  try {
    dir = fmi::unpack(o.fmu);
    const fs::path xml_path = fs::path(dir->path()) / "modelDescription.xml";
    std::ifstream in(xml_path, std::ios::binary);
    if (!in) throw fmi::FmuError(o.fmu + ": no modelDescription.xml at the top of the archive");
    const std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    md = fmi::parse_model_description(xml, o.fmu + ": modelDescription.xml");
  } catch (const fmi::FmuError& e) {
    throw std::invalid_argument(e.what());
  }

  std::vector<std::string> platforms;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(fs::path(dir->path()) / "binaries", ec)) {
    if (e.is_directory()) platforms.push_back(e.path().filename().string());
  }
  std::sort(platforms.begin(), platforms.end());
  const std::string here = platform_folder(md.version);
  const bool runs_here = std::find(platforms.begin(), platforms.end(), here) != platforms.end() &&
                         fs::is_regular_file(fs::path(dir->path()) / "binaries" / here / (md.model_identifier + ".so"));
  std::string binaries;
  for (const std::string& p : platforms) binaries += (binaries.empty() ? "" : ", ") + p;

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

int fmu_command(const FmuOptions& o) { return o.verb == "export" ? export_fmu(o) : info(o); }

}  // namespace quadcosim::app
