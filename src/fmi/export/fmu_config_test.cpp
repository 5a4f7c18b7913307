// The FMU's configuration file and its variables.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "fmi/export/fmu_config.hpp"
#include "fmi/export/rotor_test_vehicles.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "trajectory/spec.hpp"

namespace quadcosim::fmi {
namespace {

FmuConfig unusual() {
  FmuConfig c;
  c.kind = FmuKind::kController;
  c.fmi_version = FmiVersion::k3;
  c.plant_period_ns = 2'500'000;
  c.substeps = 3;
  c.controller_divider = 4;
  c.stop_time_s = 12.5;
  c.vehicle.mass_kg = 1.0 / 3.0;  // needs all 17 digits
  c.vehicle.layout = model::RotorLayout::kX;
  c.vehicle.spin = {-1, 1, -1, 1};
  c.vehicle.motor.model = model::MotorModel::kFirstOrder;
  c.vehicle.aero.linear_drag_N_s_m = {0.1, 0.2, 0.3};
  c.initial.p_W = {1.0, 2.0, 3.0};
  c.initial.q_WB = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  c.initial.omega_rad_s = model::Vector4(1.0, 2.0, 3.0, 4.0);
  c.realism.seed = 99;
  c.realism.imu.timing = {2, 1};
  c.realism.pose.position_sigma_m = 0.01;
  c.realism.wind.mean_W_m_s = {1.0, 0.0, 0.0};
  c.realism.wind.gusts.enabled = true;
  c.realism.faults.push_back({10, 3, 0.5});
  c.realism_namespace = "/uav1";
  c.controller_type = "se3";
  c.controller_parameters.push_back({"k_x.x", 5.0});
  c.setpoint.mode = control::Mode::kPosition;
  c.setpoint.p_des_W = {0.0, 0.0, 2.0};
  c.setpoint.yaw_des_rad = 0.5;
  c.guid = make_guid(c);
  return c;
}

/// What config_from_json says to `text` as "cfg.json": its FmuError, or "accepted".
std::string refused(const std::string& text) {
  try {
    config_from_json(text, "cfg.json");
  } catch (const FmuError& e) {
    return std::string(e.what());
  }
  return std::string("accepted");
}

/// `text` with its first `from` replaced by `to`.
std::string replaced(std::string text, std::string_view from, std::string_view to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(FmuConfig, JsonRoundTripIsExact) {
  const FmuConfig c = unusual();
  const std::string text = to_json(c);
  const FmuConfig back = config_from_json(text, "test");
  EXPECT_EQ(to_json(back), text);
  EXPECT_EQ(back.vehicle.mass_kg, 1.0 / 3.0);
  EXPECT_EQ(back.initial.q_WB.coeffs(), c.initial.q_WB.coeffs());
  EXPECT_EQ(back.vehicle.layout, model::RotorLayout::kX);
  EXPECT_EQ(back.realism.faults.size(), 1u);
  EXPECT_EQ(back.controller_parameters.size(), 1u);
  EXPECT_EQ(make_guid(back), c.guid);
}

TEST(FmuConfig, GuidFollowsTheContent) {
  FmuConfig a = unusual(), b = unusual();
  EXPECT_EQ(make_guid(a), make_guid(b));
  b.vehicle.mass_kg = 2.0;
  EXPECT_NE(make_guid(a), make_guid(b));
  EXPECT_EQ(a.guid.size(), 38u);  // {8-4-4-4-12}
}

TEST(FmuConfig, ErrorsNameTheKey) {
  std::string text = to_json(unusual());
  EXPECT_EQ(refused("{"), refused("{")) << "not JSON";
  EXPECT_NE(refused("{").find("cfg.json: not JSON"), std::string::npos);
  EXPECT_EQ(refused(replaced(text, "\"motor.tau_up_s\"", "\"motor.tau_upp\"")),
            "cfg.json: 'vehicle.motor.tau_up_s' missing");
  EXPECT_EQ(refused(replaced(text, "\"x\"", "\"q\"")), "cfg.json: 'vehicle.layout' is 'q', not one of the choices");
  EXPECT_EQ(refused(replaced(text, "\"controller\"", "\"controllers\"")), "cfg.json: 'controller' missing");
}

TEST(FmuConfig, PlantVariables) {
  FmuConfig c;
  c.guid = make_guid(c);
  const ModelDescription md = describe(c);
  EXPECT_EQ(md.model_identifier, "quadcosim_plant");
  EXPECT_EQ(md.guid, c.guid);
  EXPECT_FALSE(md.can_handle_variable_step);
  EXPECT_EQ(md.step_size, 0.01);
  std::set<ValueReference> vrs;
  std::set<std::string> names;
  for (std::size_t i = 0; i < md.variables.size(); ++i) {
    EXPECT_EQ(md.variables[i].vr, i);  // value reference = index
    vrs.insert(md.variables[i].vr);
    names.insert(md.variables[i].name);
  }
  EXPECT_EQ(names.size(), md.variables.size());
  EXPECT_EQ(md.variables[0].name, "time");
  EXPECT_EQ(md.variables[0].causality, Causality::kIndependent);
  // 3 + 3 + 4 + 3 + 3 + 3 + 4 outputs, in the order of fmi/quadrotor_variables.hpp.
  ASSERT_EQ(md.outputs.size(), 23u);
  EXPECT_EQ(md.variables[md.outputs[0]].name, "p_W[1]");
  EXPECT_EQ(md.variables[md.outputs[22]].name, "omega[4]");
  for (auto n : names::kOmegaCmd) EXPECT_TRUE(names.count(std::string(n))) << n;
  for (const auto& p : model::vehicle_parameters()) {
    if (p.kind != model::VehicleParameter::Kind::kNumber) continue;
    const std::string name = "vehicle." + std::string(p.name);
    ASSERT_TRUE(names.count(name)) << name;
  }
  for (const Variable& v : md.variables) {
    if (v.name == "vehicle.mass_kg") {
      EXPECT_EQ(v.unit, "kg");
      EXPECT_EQ(v.start, "1.96");
      EXPECT_EQ(v.variability, Variability::kFixed);
      EXPECT_EQ(v.min, 1e-6);
    }
    if (v.name == "omega_cmd[1]") {
      EXPECT_EQ(v.causality, Causality::kInput);
    }
    if (v.name == "realism.seed") {
      EXPECT_EQ(v.type, VariableType::kInteger);
    }
    if (v.name == "initial.q_WB[1]") {
      EXPECT_EQ(v.start, "1");
    }
  }
}

TEST(FmuConfig, ControllerVariablesAreTheTypesParameters) {
  const FmuConfig c = unusual();
  const ModelDescription md = describe(c);
  EXPECT_EQ(md.model_identifier, "quadcosim_controller");
  EXPECT_EQ(md.step_size, 0.01);  // 4 x 2.5 ms
  // The command, what the step tracked, then se3's 14 figures by their names.
  std::vector<std::string> outputs;
  for (const std::size_t i : md.outputs) outputs.push_back(md.variables[i].name);
  const std::vector<std::string> expected = {
      "omega_cmd[1]", "omega_cmd[2]",   "omega_cmd[3]", "omega_cmd[4]",  "roll_des", "pitch_des",
      "yaw_des",      "tilt_saturated", "e_x.x",        "e_x.y",         "e_x.z",    "e_v.x",
      "e_v.y",        "e_v.z",          "e_R.x",        "e_R.y",         "e_R.z",    "e_Omega.x",
      "e_Omega.y",    "e_Omega.z",      "thrust",       "yaw_torque_cut"};
  EXPECT_EQ(outputs, expected);
  bool k_x = false;
  for (const Variable& v : md.variables) {
    if (v.name == "controller.k_x.x") {
      k_x = true;
      EXPECT_EQ(v.start, "5");
      EXPECT_EQ(v.variability, Variability::kTunable);
    }
    if (v.name == "ref.p_W[3]") {
      EXPECT_EQ(v.start, "2");
    }
    if (v.name == "ref.yaw") {
      EXPECT_EQ(v.start, "0.5");
    }
  }
  EXPECT_TRUE(k_x);
  FmuConfig bad = c;
  bad.controller_parameters.push_back({"no_such_gain", 1.0});
  EXPECT_THROW(describe(bad), FmuError);
  bad.controller_type = "nonesuch";
  EXPECT_THROW(describe(bad), std::exception);
}

// One description of each kind a scenario's trajectory: section can give.
std::vector<trajectory::TrajectorySpec> every_kind() {
  trajectory::CircleParams circle;
  circle.centre_m = {1.0, 0.0};
  circle.altitude_m = 5.0;
  circle.radius_m = 2.0;
  circle.period_s = 1.0 / 3.0;  // needs all 17 digits
  circle.clockwise = true;
  circle.yaw_mode = trajectory::YawMode::kCentre;
  trajectory::LissajousParams lissajous;
  lissajous.phase_rad = {0.1, 0.2};
  lissajous.yaw_mode = trajectory::YawMode::kTangent;
  trajectory::Figure8Params figure8;
  figure8.start_s = 1.5;
  figure8.yaw_rad = 0.25;
  trajectory::WaypointsSpec waypoints;
  waypoints.method = trajectory::WaypointMethod::kMinJerk;
  waypoints.points = {{0.0, {0.0, 0.0, 0.0}, std::nullopt}, {2.0, {1.0, 2.0, 3.0}, 0.5}, {5.0, {0.0, 1.0, 1.0}, {}}};
  trajectory::PiecewisePolynomial::Segment a, b;
  a.duration_s = 0.7;
  a.c.setConstant(0.1);
  a.c(2, 0) = 1.0 / 7.0;
  b.duration_s = 2.0;
  b.c(0, 3) = -3.25;
  const trajectory::PiecewisePolynomial polynomial({a, b}, 0.5, "polynomial file fig8.csv");
  return {circle, lissajous, figure8, waypoints, polynomial};
}

TEST(FmuConfig, TrajectoryRoundTripIsExact) {
  const FmuConfig without = unusual();
  for (const trajectory::TrajectorySpec& spec : every_kind()) {
    FmuConfig c = unusual();
    c.trajectory = spec;
    const std::string text = to_json(c);
    const FmuConfig back = config_from_json(text, "test");
    EXPECT_EQ(to_json(back), text);
    EXPECT_NE(make_guid(c), make_guid(without));
    ASSERT_TRUE(back.trajectory.has_value());
    EXPECT_EQ(back.trajectory->index(), spec.index());
    const auto original = trajectory::make_trajectory(spec);
    const auto read = trajectory::make_trajectory(*back.trajectory);
    EXPECT_EQ(read->describe(), original->describe());
    for (double t : {0.0, 0.3, 1.0 / 3.0, 1.7, 2.5, 4.9, 12.0}) {
      const trajectory::FlatOutput x = original->at(t), y = read->at(t);
      EXPECT_EQ(x.p_W, y.p_W) << original->describe() << " at " << t;
      EXPECT_EQ(x.v_W, y.v_W);
      EXPECT_EQ(x.a_W, y.a_W);
      EXPECT_EQ(x.j_W, y.j_W);
      EXPECT_EQ(x.yaw_rad, y.yaw_rad);
      EXPECT_EQ(x.yaw_rate_rad_s, y.yaw_rate_rad_s);
    }
  }
  // No trajectory: no key, so an FMU exported without one keeps its configuration and GUID.
  EXPECT_EQ(to_json(without).find("\"trajectory\""), std::string::npos);
}

TEST(FmuConfig, TrajectoryErrorsNameTheKey) {
  FmuConfig c = unusual();
  c.trajectory = every_kind()[0];
  const std::string text = to_json(c);
  EXPECT_EQ(refused(replaced(text, "\"circle\"", "\"spiral\"")),
            "cfg.json: 'trajectory.kind' is 'spiral', not circle, lissajous, figure8, waypoints or polynomial");
  EXPECT_EQ(refused(replaced(text, "\"radius_m\": 2.0", "\"radius_m\": -2.0")),
            "cfg.json: 'trajectory' is not a valid trajectory: radius must be finite and > 0");
  EXPECT_EQ(refused(replaced(text, "\"centre\"", "\"middle\"")),
            "cfg.json: 'trajectory.yaw_mode' is 'middle', not fixed, tangent or centre");
}

TEST(FmuConfig, ControllerWithATrajectoryStartsOnIt) {
  FmuConfig c = unusual();
  const ModelDescription plain = describe(c);  // no trajectory: no switch
  EXPECT_TRUE(std::none_of(plain.variables.begin(), plain.variables.end(),
                           [](const Variable& v) { return v.name == names::kRefExternal; }));
  trajectory::CircleParams circle;  // r = 2 about (1, 0) at 5 m, phase 0: starts at (3, 0, 5)
  circle.centre_m = {1.0, 0.0};
  circle.altitude_m = 5.0;
  circle.radius_m = 2.0;
  c.trajectory = circle;
  const ModelDescription md = describe(c);
  std::map<std::string, const Variable*> by_name;
  for (const Variable& v : md.variables) by_name[v.name] = &v;
  ASSERT_TRUE(by_name.count(std::string(names::kRefExternal)));
  const Variable& external = *by_name[std::string(names::kRefExternal)];
  EXPECT_EQ(external.type, VariableType::kBoolean);
  EXPECT_EQ(external.causality, Causality::kParameter);
  EXPECT_EQ(external.variability, Variability::kFixed);
  EXPECT_EQ(external.start, "false");
  EXPECT_EQ(by_name["ref.p_W[1]"]->start, "3");
  EXPECT_EQ(by_name["ref.p_W[2]"]->start, "0");
  EXPECT_EQ(by_name["ref.p_W[3]"]->start, "5");
  EXPECT_EQ(by_name["ref.yaw"]->start, "0");     // the circle's fixed yaw, not the setpoint's 0.5
  EXPECT_EQ(by_name["ref.v_W[1]"]->start, "0");  // at rest before the spin-up
}

}  // namespace
}  // namespace quadcosim::fmi

// A vehicle's rotors in the configuration: the layout, one spin sign per rotor and a custom layout's
// positions, read back exactly; a bad rotor list is refused naming the field.
namespace quadcosim::fmi::rotors {

using test::octo_x8;

/// The variable `name` of `md`, or nullptr (ModelDescription::find is the importer's library's).
const Variable* find(const ModelDescription& md, std::string_view name) {
  for (const Variable& v : md.variables) {
    if (v.name == name) return &v;
  }
  return nullptr;
}

/// `v` as describe() writes start values: the shortest text that reads back to the same double.
std::string to_json_number(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

model::VehicleParams hex_x() {
  model::VehicleParams v;
  v.set_layout(model::RotorLayout::kHexX);
  v.spin = {1, -1, 1, -1, 1, -1, 1, -1};
  return v;
}

FmuConfig with(const model::VehicleParams& v, FmuKind kind = FmuKind::kPlant) {
  FmuConfig c;
  c.kind = kind;
  c.vehicle = v;
  c.initial.omega_rad_s = model::RotorVector::LinSpaced(v.rotor_count, 100.0 / 3.0, 800.0 / 7.0);
  c.realism.faults.push_back({10, v.rotor_count - 1, 0.5});
  c.guid = make_guid(c);
  return c;
}

TEST(FmuConfigRotors, LayoutSpinsAndCustomPositionsRoundTripExactly) {
  for (const model::VehicleParams& v : {hex_x(), octo_x8()}) {
    const FmuConfig c = with(v);
    const std::string text = to_json(c);
    const FmuConfig back = config_from_json(text, "test");
    EXPECT_EQ(to_json(back), text);
    EXPECT_EQ(make_guid(back), c.guid);
    EXPECT_EQ(back.vehicle.layout, v.layout);
    ASSERT_EQ(back.vehicle.rotor_count, v.rotor_count);
    for (std::size_t i = 0; i < static_cast<std::size_t>(v.rotor_count); ++i) {
      EXPECT_EQ(back.vehicle.spin[i], v.spin[i]) << i;
      if (v.layout == model::RotorLayout::kCustom) EXPECT_EQ(back.vehicle.rotor_positions_m[i], v.rotor_positions_m[i]);
    }
    ASSERT_EQ(back.initial.omega_rad_s.size(), v.rotor_count);
    EXPECT_EQ(back.initial.omega_rad_s, c.initial.omega_rad_s);  // 100/3 .. 800/7: all 17 digits
    EXPECT_EQ(back.realism.faults.at(0).rotor, v.rotor_count - 1);
  }
  // A standard layout writes no rotor list (a quadrotor's configuration is what it always was).
  EXPECT_EQ(to_json(with(hex_x())).find("\"rotors\""), std::string::npos);
  EXPECT_NE(to_json(with(octo_x8())).find("\"rotors\""), std::string::npos);
}

TEST(FmuConfigRotors, ABadRotorListNamesTheField) {
  const std::string octo = to_json(with(octo_x8())), hex = to_json(with(hex_x()));
  // The octorotor's rotors, its first entry and its spins as to_json wrote them (2-space indent).
  const std::string first = "{\n        \"position_m\": [\n          0.2475,\n          0.2475,\n          0.04\n";
  ASSERT_NE(octo.find(first), std::string::npos) << octo;
  EXPECT_EQ(refused(replaced(octo, "\"custom\"", "\"hex_x\"")),
            "cfg.json: 'vehicle.rotors' is given, but layout hex_x places its rotors itself (rotors go with layout "
            "custom)");
  EXPECT_EQ(refused(replaced(octo, "\"rotors\"", "\"rotor\"")), "cfg.json: 'vehicle.rotors' missing");
  EXPECT_EQ(refused(replaced(octo, "\"rotors\": [", "\"rotors\": [], \"x\": [")),
            "cfg.json: 'vehicle.rotors' is not a list of 4 to 8 rotors {position_m: [x, y, z], spin: 1 or -1}");
  EXPECT_EQ(refused(replaced(octo, "0.2475,\n          0.04\n", "0.04\n")),
            "cfg.json: 'vehicle.rotors[0].position_m' not an array of 3 numbers");
  EXPECT_EQ(refused(replaced(octo, "\"spin\": 1", "\"spin\": 2")), "cfg.json: 'vehicle.rotors[0].spin' is not 1 or -1");
  // Two rotors at one place: the vehicle file's rule (model::validate_rotors), at the rotor list.
  const std::string same = replaced(octo, "0.2475,\n          0.04\n", "0.2475,\n          -0.04\n");
  EXPECT_NE(refused(same).find("cfg.json: 'vehicle.rotors' is refused: rotors must"), std::string::npos)
      << refused(same);
  // The spins: one per rotor, as the rotor list gives them for a custom layout.
  EXPECT_EQ(refused(replaced(hex, "\"spin\": [\n      1,", "\"spin\": [")),
            "cfg.json: 'vehicle.spin' is not a list of 6 signs (one per rotor of layout hex_x)");
  EXPECT_EQ(refused(replaced(octo, "\"spin\": [\n      1,", "\"spin\": [\n      -1,")),
            "cfg.json: 'vehicle.spin[0]' is -1, but rotors[0].spin is 1");
  // The initial rotor speeds and the faults follow the rotor count.
  EXPECT_EQ(refused(replaced(hex, "\"omega\": [\n", "\"omega\": [\n      1,\n")),
            "cfg.json: 'initial.omega' not an array of 6 numbers (one per rotor)");
  EXPECT_EQ(refused(replaced(hex, "\"rotor\": 5", "\"rotor\": 6")),
            "cfg.json: 'realism.faults[0].rotor' must be 0..5 (one of the vehicle's 6 rotors)");
}

TEST(FmuConfigRotors, AnNRotorFmuHasOneCommandPerRotorAndKeepsTheQuadrotorsReferences) {
  for (const FmuKind kind : {FmuKind::kPlant, FmuKind::kController}) {
    for (const model::VehicleParams& v : {hex_x(), octo_x8()}) {
      const int n = v.rotor_count;
      FmuConfig quad;
      quad.kind = kind;
      quad.controller_type = "se3";
      quad.guid = make_guid(quad);
      FmuConfig multi = with(v, kind);
      multi.controller_type = "se3";
      const ModelDescription md4 = describe(quad), md = describe(multi);
      // Exactly omega_cmd[1..N] (plant: inputs; controller: outputs), in rotor order by value reference.
      const Causality side = kind == FmuKind::kPlant ? Causality::kInput : Causality::kOutput;
      std::vector<std::pair<ValueReference, std::string>> commands;
      for (const Variable& var : md.variables) {
        if (var.name.rfind("omega_cmd", 0) == 0) {
          EXPECT_EQ(var.causality, side) << var.name;
          commands.emplace_back(var.vr, var.name);
        }
      }
      ASSERT_EQ(commands.size(), static_cast<std::size_t>(n));
      std::sort(commands.begin(), commands.end());
      for (int i = 0; i < n; ++i) EXPECT_EQ(commands[i].second, "omega_cmd[" + std::to_string(i + 1) + "]");
      // Every variable of the quadrotor's FMU keeps its value reference; the rotors past four come after.
      const std::size_t extra = static_cast<std::size_t>(n - 4) * (kind == FmuKind::kPlant ? 3 : 1);
      ASSERT_EQ(md.variables.size(), md4.variables.size() + extra);
      for (const Variable& var : md4.variables) {
        const Variable* same = find(md, var.name);
        ASSERT_NE(same, nullptr) << var.name;
        EXPECT_EQ(same->vr, var.vr) << var.name;
        EXPECT_EQ(same->causality, var.causality) << var.name;
      }
      for (std::size_t i = md4.variables.size(); i < md.variables.size(); ++i) {
        EXPECT_EQ(md.variables[i].vr, i);
        EXPECT_NE(md.variables[i].name.find("omega"), std::string::npos) << md.variables[i].name;
      }
      if (kind == FmuKind::kPlant) {
        for (int i = 1; i <= n; ++i) {
          const std::string k = "[" + std::to_string(i) + "]";
          ASSERT_NE(find(md, "omega" + k), nullptr) << i;
          EXPECT_EQ(find(md, "omega" + k)->causality, Causality::kOutput);
          ASSERT_NE(find(md, "initial.omega" + k), nullptr) << i;
          EXPECT_EQ(find(md, "initial.omega" + k)->start, to_json_number(multi.initial.omega_rad_s[i - 1]));
        }
        EXPECT_EQ(find(md, "omega[" + std::to_string(n + 1) + "]"), nullptr);
      }
    }
  }
}

}  // namespace quadcosim::fmi::rotors
