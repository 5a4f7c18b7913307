// hosts/fmu_export.hpp: quadcosim's plant or controller packed as an FMU, and what an FMU declares.
#include "hosts/fmu_export.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <stdexcept>

#include "controllers/registry.hpp"
#include "fmi/unzip.hpp"
#include "fmi/zip_writer.hpp"
#include "io/scenario.hpp"

namespace quadcosim::hosts {

namespace fs = std::filesystem;

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

/// The FMU's configuration from the scenario (or the defaults: the paper's vehicle and controller).
fmi::FmuConfig fmu_config_from(const FmuExportOptions& o, std::vector<std::string>& notes,
                               const io::ScenarioResolvers& resolvers) {
  io::Scenario sc;
  if (!o.controller.empty() && io::parse_controller_choice(o.controller).kind != io::ControllerChoice::Kind::kType) {
    throw io::ConfigError("--controller " + o.controller + ": fmu export packs one of quadcosim's controller types (" +
                          controllers::controller_type_names() +
                          "); a class written in Python or an FMU is not packed");
  }
  if (!o.scenario.empty()) {
    sc = io::load_scenario(o.scenario, o.controller, resolvers);
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

FmuExport export_fmu(const FmuExportOptions& o, const std::function<fs::path()>& find_library,
                     const io::ScenarioResolvers& resolvers) {
  if (fs::path(o.out).extension() != ".fmu")
    throw std::invalid_argument(fmt::format("--out: '{}' must end in .fmu", o.out));
  FmuExport r;
  fmi::FmuConfig& config = r.config;
  config = fmu_config_from(o, r.notes, resolvers);
  r.platform = platform_folder(config.fmi_version);
  if (r.platform.empty())
    throw std::invalid_argument(
        fmt::format("--fmi {}: FMI {} names no binaries folder for this machine's architecture", o.fmi, o.fmi));
  config.guid = fmi::make_guid(config);

  fmi::ModelDescription& md = r.description;
  try {
    md = fmi::describe(config);
  } catch (const fmi::FmuError& e) {  // a controller or realism setting an FMU cannot express
    throw std::invalid_argument(e.what());
  }
  md.generation_tool = o.generation_tool;
  const std::string xml = fmi::write_model_description(md);  // FmuError: a bug, not the user's input
  r.library = find_library();

  fmi::write_zip(
      o.out,
      {
          fmi::ZipEntry::from_bytes("modelDescription.xml", xml),
          fmi::ZipEntry::from_file("binaries/" + r.platform + "/" + md.model_identifier + ".so", r.library, true),
          fmi::ZipEntry::from_bytes("resources/" + std::string(fmi::kConfigFileName), fmi::to_json(config)),
      });
  return r;
}

FmuInfo read_fmu_info(const std::string& path) {
  std::unique_ptr<fmi::TempDir> dir;
  FmuInfo r;
  fmi::ModelDescription& md = r.description;
  try {
    dir = fmi::unpack(path);
    const fs::path xml_path = fs::path(dir->path()) / "modelDescription.xml";
    std::ifstream in(xml_path, std::ios::binary);
    if (!in) throw fmi::FmuError(path + ": no modelDescription.xml at the top of the archive");
    const std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    md = fmi::parse_model_description(xml, path + ": modelDescription.xml");
  } catch (const fmi::FmuError& e) {
    throw std::invalid_argument(e.what());
  }

  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(fs::path(dir->path()) / "binaries", ec)) {
    if (e.is_directory()) r.platforms.push_back(e.path().filename().string());
  }
  std::sort(r.platforms.begin(), r.platforms.end());
  r.here = platform_folder(md.version);
  r.runs_here = std::find(r.platforms.begin(), r.platforms.end(), r.here) != r.platforms.end() &&
                fs::is_regular_file(fs::path(dir->path()) / "binaries" / r.here / (md.model_identifier + ".so"));
  return r;
}

}  // namespace quadcosim::hosts
