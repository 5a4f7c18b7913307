// The FMU's configuration file and its variables.
#include <gtest/gtest.h>

#include <set>

#include "fmi/export/fmu_config.hpp"
#include "fmi/quadrotor_variables.hpp"

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
  c.initial.omega_rad_s = {1.0, 2.0, 3.0, 4.0};
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
  auto refused = [](const std::string& t) {
    try {
      config_from_json(t, "cfg.json");
    } catch (const FmuError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused("{"), refused("{")) << "not JSON";
  EXPECT_NE(refused("{").find("cfg.json: not JSON"), std::string::npos);
  std::string bad = text;
  bad.replace(bad.find("\"motor.tau_up_s\""), 16, "\"motor.tau_upp\"");
  EXPECT_EQ(refused(bad), "cfg.json: 'vehicle.motor.tau_up_s' missing");
  bad = text;
  bad.replace(bad.find("\"x\""), 3, "\"q\"");
  EXPECT_EQ(refused(bad), "cfg.json: 'vehicle.layout' is 'q', not one of the choices");
  bad = text;
  bad.replace(bad.find("\"controller\""), 12, "\"controllers\"");
  EXPECT_EQ(refused(bad), "cfg.json: 'controller' missing");
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
    if (v.name == "omega_cmd[1]") EXPECT_EQ(v.causality, Causality::kInput);
    if (v.name == "realism.seed") EXPECT_EQ(v.type, VariableType::kInteger);
    if (v.name == "initial.q_WB[1]") EXPECT_EQ(v.start, "1");
  }
}

TEST(FmuConfig, ControllerVariablesAreTheTypesParameters) {
  const FmuConfig c = unusual();
  const ModelDescription md = describe(c);
  EXPECT_EQ(md.model_identifier, "quadcosim_controller");
  EXPECT_EQ(md.step_size, 0.01);  // 4 x 2.5 ms
  ASSERT_EQ(md.outputs.size(), 4u);
  bool k_x = false;
  for (const Variable& v : md.variables) {
    if (v.name == "controller.k_x.x") {
      k_x = true;
      EXPECT_EQ(v.start, "5");
      EXPECT_EQ(v.variability, Variability::kTunable);
    }
    if (v.name == "ref.p_W[3]") EXPECT_EQ(v.start, "2");
    if (v.name == "ref.yaw") EXPECT_EQ(v.start, "0.5");
  }
  EXPECT_TRUE(k_x);
  FmuConfig bad = c;
  bad.controller_parameters.push_back({"no_such_gain", 1.0});
  EXPECT_THROW(describe(bad), FmuError);
  bad.controller_type = "nonesuch";
  EXPECT_THROW(describe(bad), std::exception);
}

}  // namespace
}  // namespace quadcosim::fmi
