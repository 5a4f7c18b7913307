// `quadcosim lqr` and `quadcosim params [--vehicle] [--controller TYPE|python:MODULE:CLASS|fmu:PATH]`.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <iostream>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "control/parameters.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "controllers/registry.hpp"
#include "io/scenario.hpp"
#include "model/vehicle_presets.hpp"

namespace quadcosim::app {

namespace {
std::string complex_str(const std::complex<double>& c) {
  if (c.imag() == 0.0) return fmt::format("{:.6g}", c.real());
  return fmt::format("{:.6g} {} {:.6g}i", c.real(), c.imag() < 0 ? '-' : '+', std::abs(c.imag()));
}
}  // namespace

CLI::App* add_lqr_subcommand(CLI::App& app, LqrOptions& lqr) {
  auto* lqr_cmd = app.add_subcommand(
      "lqr", "the paper controller's LQR designs: each attitude axis's A, B, Q, R, gain K and closed-loop poles");
  lqr_cmd->add_option("--params", lqr.params, "controller parameter YAML")->check(CLI::ExistingFile);
  lqr_cmd->add_option("--vehicle", lqr.vehicle, "vehicle YAML")->check(CLI::ExistingFile);
  return lqr_cmd;
}

CLI::App* add_params_subcommand(CLI::App& app, ParamsOptions& params) {
  auto* params_cmd = app.add_subcommand(
      "params", "list the controller node's and a controller's parameters (or the vehicle's), and the controllers");
  check_controller_choice(*params_cmd->add_option(
      "--controller", params.controller,
      fmt::format("the controller whose parameters follow the node's: a type (default {}; see "
                  "--list), python:MODULE:CLASS (a class's declared parameters) or fmu:PATH (an FMU's)",
                  controllers::kDefaultControllerType)));
  params_cmd->add_flag("--list", params.list,
                       "list the registered controller types instead (with --vehicle: the vehicle presets)");
  params_cmd->add_flag("--vehicle", params.vehicle, "the vehicle's parameters (scenario `vehicle:`, vehicle files)");
  params_cmd->add_flag("--markdown", params.markdown, "the vehicle table as Markdown, as docs/model.md shows it")
      ->needs(params_cmd->get_option("--vehicle"));
  params_cmd
      ->add_option("--preset", params.preset,
                   "with --vehicle: the values of a ready vehicle (" + model::vehicle_preset_names() + ")")
      ->check(CLI::IsMember(model::vehicle_preset_list()))
      ->needs(params_cmd->get_option("--vehicle"));
  return params_cmd;
}

int lqr_command(const LqrOptions& opt, const io::ScenarioResolvers& resolvers) {
  model::VehicleParams vehicle;
  if (!opt.vehicle.empty()) vehicle = io::load_vehicle(opt.vehicle);
  const control::ControllerConfig cfg = opt.params.empty()
                                            ? controllers::make_config(controllers::kDefaultControllerType, vehicle)
                                            : io::load_controller(opt.params, vehicle, resolvers);
  const controllers::PaperController* paper = controllers::paper_controller(cfg);
  if (!paper) {
    // Only the paper controller's attitude loops are LQR designs; other controllers have no A, B,
    // Q, R, K to print.
    const std::string type(cfg.type());
    throw std::invalid_argument(fmt::format(
        "{}: `quadcosim lqr` prints the paper controller's LQR designs, and this file configures controller type "
        "'{}', which has none; for it use `quadcosim params --controller {}` (its parameters) and "
        "`quadcosim margins SCENARIO --controller {}` (its loop margins, measured)",
        opt.params, type, type, type));
  }
  const controllers::PaperController& fc = *paper;
  const char* names[3] = {"roll", "pitch", "yaw"};
  const double inertia[3] = {vehicle.Ixx_kg_m2, vehicle.Iyy_kg_m2, vehicle.Izz_kg_m2};
  for (int i = 0; i < 3; ++i) {
    const control::AxisLqr& a = fc.axis(i);
    std::cout << fmt::format("{} axis (I = {:g} kg m^2), state [e, rate], U = -K x\n", names[i], inertia[i]);
    std::cout << fmt::format("  A = [[{:g}, {:g}], [{:g}, {:g}]]\n", a.A(0, 0), a.A(0, 1), a.A(1, 0), a.A(1, 1));
    std::cout << fmt::format("  B = [{:g}, {:.6g}]\n", a.B(0), a.B(1));
    std::cout << fmt::format("  Q = diag({:g}, {:g})   R = {:g}\n", a.Q(0, 0), a.Q(1, 1), a.R);
    std::cout << fmt::format("  K = [{:.6g}, {:.6g}]   (Algorithm 1: k1 = {:.6g}, k2 = {:.6g})\n", a.K(0), a.K(1),
                             -a.K(0), a.K(1));
    std::cout << fmt::format("  closed-loop poles: {}, {}\n", complex_str(a.closed_loop_poles(0)),
                             complex_str(a.closed_loop_poles(1)));
  }
  return exit_code::kOk;
}

namespace {

// The vehicle presets: name, vehicle, sources.
int vehicle_presets_table() {
  std::cout << fmt::format("{:<12} {}\n", "preset", "vehicle (sources)");
  for (const model::VehiclePreset& p : model::vehicle_presets()) {
    std::cout << fmt::format("{:<12} {}\n{:<12} ({})\n", p.name, p.description, "", p.sources);
  }
  return exit_code::kOk;
}

// The vehicle parameter table (model::vehicle_parameters()): as aligned text, or as the Markdown
// table docs/model.md carries (tests/cli checks the two agree); with a preset, its values in the
// "default" column.
int vehicle_params_table(bool markdown, const std::string& preset) {
  const model::VehiclePreset* chosen = preset.empty() ? nullptr : model::find_vehicle_preset(preset);
  const model::VehicleParams defaults = chosen ? chosen->params : model::VehicleParams{};
  constexpr const char* text_row = "{:<34} {:<18} {:<18} {:<14} {}\n";
  constexpr const char* md_row = "| {} | {} | {} | {} | {} |\n";
  if (markdown) {
    std::cout << fmt::format(md_row, "key", "unit", "range", "default", "meaning");
    std::cout << "|---|---|---|---|---|\n";
  } else {
    if (chosen) std::cout << "preset " << chosen->name << ": " << chosen->description << "\n";
    std::cout << fmt::format(text_row, "name", "unit", "range", chosen ? "value" : "default", "meaning");
  }
  for (const auto& p : model::vehicle_parameters()) {
    std::string range;
    switch (p.kind) {
      case model::VehicleParameter::Kind::kNumber: range = p.range.text(); break;
      case model::VehicleParameter::Kind::kChoice:
        for (auto c : p.choices) {
          if (!range.empty()) range += markdown ? " \\| " : "|";
          range.append(c);
        }
        break;
      case model::VehicleParameter::Kind::kSigns: range = "+1 or -1 each, one per rotor"; break;
      case model::VehicleParameter::Kind::kRotors: range = "4 to 8 {position_m, spin}"; break;
    }
    if (markdown) {
      std::cout << fmt::format(md_row, fmt::format("`{}`", p.name), p.unit, range, p.text(defaults), p.meaning);
    } else {
      std::cout << fmt::format(text_row, p.name, p.unit, range, p.text(defaults), p.meaning);
    }
  }
  return exit_code::kOk;
}

}  // namespace

int params_command(const ParamsOptions& options, const io::ScenarioResolvers& resolvers) {
  if (options.vehicle && options.list) return vehicle_presets_table();
  if (options.vehicle) return vehicle_params_table(options.markdown, options.preset);
  if (options.list) {
    std::cout << fmt::format("{:<10} {}\n", "type", "controller");
    for (const auto& t : controllers::controller_types())
      std::cout << fmt::format("{:<10} {}\n", t.name, t.description);
    return exit_code::kOk;
  }
  // A Python class or an FMU is loaded as a scenario naming it would load it: its declared parameters
  // and their defaults are known only then.
  const control::ControllerConfig defaults = io::defaults_flown_by(options.controller, resolvers).controller;
  std::cout << fmt::format("{:<26} {:<10} {:<22} {:<12} {}\n", "name", "unit", "range", "default", "meaning");
  for (const control::ParameterSpec* spec : control::all_parameters(defaults)) {
    const control::ParameterSpec& p = *spec;
    std::string range;
    if (p.is_choice()) {
      for (auto c : p.choices) {
        if (!range.empty()) range += '|';
        range.append(c);
      }
    } else {
      range = fmt::format("[{:g}, {:g}]", p.min, p.max);
    }
    std::cout << fmt::format("{:<26} {:<10} {:<22} {:<12} {}\n", p.name, p.is_choice() ? "" : p.unit, range,
                             control::to_string(*control::get_parameter(defaults, p.name)), p.description);
  }
  return exit_code::kOk;
}

}  // namespace quadcosim::app
