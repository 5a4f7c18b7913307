// FMUs of vehicles with more than four rotors, loaded with dlopen: the Firefly hexarotor (layout
// hex_x) and a custom coaxial octorotor as plant FMUs (FMI 2 and 3) step as model::Quadrotor steps
// the same vehicle under the same per-rotor commands, bit for bit, their omega[1..N] included; the
// Firefly's se3 controller FMU commands its six rotors as the native controller does, bit for bit.
#include <cstring>

#include "control/observation_test_support.hpp"
#include "controllers/registry.hpp"
#include "fmi/export/fmu_test_support.hpp"
#include "fmi/export/rotor_test_vehicles.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_presets.hpp"
#include "sim/clock.hpp"

namespace quadcosim::fmi::test {
namespace {

model::VehicleParams firefly() { return model::find_vehicle_preset("firefly")->params; }

/// A plant FMU of `v` hovering at 2 m, its motors lagging (first order). (Drag, wind, gusts, a rotor
/// fault and sensor noise on a hexarotor: FmuPlantNode.AHexarotor*, against the plant node.)
FmuConfig plant_of(model::VehicleParams v, FmiVersion version) {
  FmuConfig c = config_for(FmuKind::kPlant, version);
  v.motor.model = model::MotorModel::kFirstOrder;
  c.vehicle = v;
  c.initial = model::Quadrotor(v).initial_state({0.0, 0.0, 2.0}, 0.0, true);
  c.guid = make_guid(c);
  return c;
}

/// Per rotor, a command of its own around hover: the vehicle rolls, pitches and yaws, so that a rotor
/// mixed up or a position misread shows.
model::RotorVector commands(const FmuConfig& c, int step) {
  const int n = c.vehicle.rotor_count;
  model::RotorVector w(n);
  for (int i = 0; i < n; ++i) {
    w[i] = c.vehicle.hover_omega_rad_s() * (1.0 + 0.002 * (i + 1) * std::sin(0.1 * (step + 1) * (i + 1)));
  }
  return w;
}

std::vector<std::string_view> plant_outputs(int rotors) {
  std::vector<std::string_view> out;
  for (auto names : {names::kPosition, names::kVelocity, names::kRates, names::kSpecificForce}) {
    out.insert(out.end(), names.begin(), names.end());
  }
  out.insert(out.end(), names::kAttitude.begin(), names::kAttitude.end());
  const auto speeds = names::rotor_speed(rotors);
  out.insert(out.end(), speeds.begin(), speeds.end());
  return out;
}

/// The native model's values of plant_outputs().
std::vector<double> native_outputs(const model::Outputs& y, const model::State& x) {
  std::vector<double> v;
  for (const Eigen::Vector3d& e : {y.p_W, y.v_W, y.w_B, y.specific_force_B}) v.insert(v.end(), e.data(), e.data() + 3);
  v.insert(v.end(), {y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z()});
  v.insert(v.end(), x.omega_rad_s.data(), x.omega_rad_s.data() + x.omega_rad_s.size());
  return v;
}

/// Steps `fmu` (set: the commands by value reference; step: one 0.02 s communication step; get: the
/// outputs) and model::Quadrotor side by side for 2 s; every output bit for bit after every step.
template <class Set, class Step, class Get>
void compare_with_model(const FmuConfig& c, const std::vector<ValueReference>& cmd_vrs,
                        const std::vector<ValueReference>& out_vrs, Set set, Step step, Get get) {
  const model::Quadrotor quad(c.vehicle);
  const sim::TickClock clock{c.plant_period_ns};
  model::State x = c.initial;
  sim::Tick k = 0;
  for (int j = 0; j < 100; ++j) {
    const model::RotorVector w = commands(c, j);
    set(cmd_vrs, std::vector<double>(w.data(), w.data() + w.size()));
    ASSERT_TRUE(step(clock.seconds(k), 0.02));
    const model::RotorInput input = quad.rotor_input(w);
    for (int i = 0; i < 2; ++i, ++k) quad.step(x, clock.seconds(k), input, clock.period_s(), c.substeps);
    const std::vector<double> want = native_outputs(quad.outputs(clock.seconds(k), x, input), x);
    const std::vector<double> got = get(out_vrs);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(std::memcmp(&got[i], &want[i], sizeof(double)), 0)
          << "output " << i << " after step " << j << ": " << got[i] << " vs " << want[i];
    }
  }
  EXPECT_GT(x.w_B.norm(), 1e-4);  // the uneven commands turned it: where each rotor is and its spin count
}

void plant_fmi2(const FmuConfig& c) {
  Fmi2Instance fmu("plant", c);
  ASSERT_NO_FATAL_FAILURE(fmu.init());
  std::vector<ValueReference> cmd, out;
  for (auto n : names::omega_cmd(c.vehicle.rotor_count)) cmd.push_back(fmu.vr(n));
  for (auto n : plant_outputs(c.vehicle.rotor_count)) out.push_back(fmu.vr(n));
  compare_with_model(
      c, cmd, out,
      [&](const std::vector<ValueReference>& vrs, const std::vector<double>& v) {
        ASSERT_EQ(QC_FMI(fmi2SetReal)(fmu.c_, vrs.data(), vrs.size(), v.data()), fmi2OK) << fmu.log_.last();
      },
      [&](double t, double h) { return fmu.step(t, h) == fmi2OK; },
      [&](const std::vector<ValueReference>& vrs) {
        std::vector<double> v(vrs.size());
        EXPECT_EQ(QC_FMI(fmi2GetReal)(fmu.c_, vrs.data(), vrs.size(), v.data()), fmi2OK) << fmu.log_.last();
        return v;
      });
}

TEST(FmuRotors, TheFireflyHexarotorPlantStepsAsTheNativeModel) { plant_fmi2(plant_of(firefly(), FmiVersion::k2)); }

TEST(FmuRotors, ACustomOctorotorPlantStepsAsTheNativeModel) { plant_fmi2(plant_of(octo_x8(), FmiVersion::k2)); }

TEST(FmuRotors, TheHexarotorPlantThroughFmi3) {
  model::VehicleParams hex_plus = firefly();
  hex_plus.set_layout(model::RotorLayout::kHexPlus);
  for (const model::VehicleParams& v : {hex_plus, octo_x8()}) {
    const FmuConfig c = plant_of(v, FmiVersion::k3);
    Resources resources(c);
    Log log;
    fmi3Instance i = QC_FMI(fmi3InstantiateCoSimulation)("fmu3", c.guid.c_str(), resources.path().c_str(), false, false,
                                                         false, false, nullptr, 0, &log, &Log::fmi3_logger, nullptr);
    ASSERT_NE(i, nullptr) << log.last();
    ASSERT_EQ(QC_FMI(fmi3EnterInitializationMode)(i, false, 0.0, 0.0, false, 0.0), fmi3OK) << log.last();
    ASSERT_EQ(QC_FMI(fmi3ExitInitializationMode)(i), fmi3OK) << log.last();
    auto vr = [&](std::string_view n) { return vr_of(c, n); };
    std::vector<ValueReference> cmd, out;
    for (auto n : names::omega_cmd(v.rotor_count)) cmd.push_back(vr(n));
    for (auto n : plant_outputs(v.rotor_count)) out.push_back(vr(n));
    compare_with_model(
        c, cmd, out,
        [&](const std::vector<ValueReference>& vrs, const std::vector<double>& x) {
          ASSERT_EQ(QC_FMI(fmi3SetFloat64)(i, vrs.data(), vrs.size(), x.data(), x.size()), fmi3OK) << log.last();
        },
        [&](double t, double h) {
          fmi3Boolean event = false, terminate = false, early = false;
          double last = 0.0;
          return QC_FMI(fmi3DoStep)(i, t, h, true, &event, &terminate, &early, &last) == fmi3OK;
        },
        [&](const std::vector<ValueReference>& vrs) {
          std::vector<double> x(vrs.size());
          EXPECT_EQ(QC_FMI(fmi3GetFloat64)(i, vrs.data(), vrs.size(), x.data(), x.size()), fmi3OK) << log.last();
          return x;
        });
    QC_FMI(fmi3FreeInstance)(i);
  }
}

TEST(FmuRotors, TheFireflysControllerCommandsItsSixRotorsAsTheNativeController) {
  FmuConfig c = config_for(FmuKind::kController);
  c.vehicle = firefly();
  c.controller_type = "se3";
  c.setpoint.mode = control::Mode::kPosition;
  c.setpoint.p_des_W = {1.0, -0.5, 2.5};
  c.setpoint.yaw_des_rad = 0.3;
  const model::Quadrotor quad(c.vehicle);
  c.initial = quad.initial_state({0.0, 0.0, 2.0}, 0.0, true);
  c.guid = make_guid(c);
  Fmi2Instance fmu("controller", c);
  ASSERT_NO_FATAL_FAILURE(fmu.init());

  std::unique_ptr<control::Controller> native = controllers::make_config("se3", c.vehicle).controller->clone();
  control::ControllerOutput out;
  out.outputs.assign(native->output_names().size(), 0.0);
  control::Reference ref;
  ref.mode = control::Mode::kPosition;
  ref.p_W = c.setpoint.p_des_W;
  ref.yaw_rad = c.setpoint.yaw_des_rad;

  const sim::TickClock clock{c.plant_period_ns};
  const double dt = clock.period_s() * c.controller_divider;
  model::State x = c.initial;
  model::RotorInput input = quad.rotor_input(x.omega_rad_s);
  sim::Tick k = 0;
  for (; clock.seconds(k) < 8.0 - 1e-9; k += c.controller_divider) {
    const model::Outputs y = quad.outputs(clock.seconds(k), x, input);
    const std::array<std::pair<const std::array<std::string_view, 3>*, Eigen::Vector3d>, 4> in = {
        {{&names::kPosition, y.p_W},
         {&names::kVelocity, y.v_W},
         {&names::kRates, y.w_B},
         {&names::kSpecificForce, y.specific_force_B}}};
    for (const auto& [names, value] : in) {
      for (int i = 0; i < 3; ++i) ASSERT_EQ(fmu.set((*names)[static_cast<std::size_t>(i)], value[i]), fmi2OK);
    }
    const Eigen::Vector4d q(y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z());
    for (int i = 0; i < 4; ++i) ASSERT_EQ(fmu.set(names::kAttitude[static_cast<std::size_t>(i)], q[i]), fmi2OK);
    ASSERT_EQ(fmu.step(clock.seconds(k), dt), fmi2OK) << fmu.log_.last();
    native->step(control::test::observe(y), ref, dt, out);
    ASSERT_EQ(out.omega_rad_s.size(), 6);
    model::RotorVector cmd(6);
    for (int i = 0; i < 6; ++i) {
      cmd[i] = fmu.get(names::kOmegaCmdAll[static_cast<std::size_t>(i)]);
      ASSERT_EQ(std::memcmp(&cmd[i], &out.omega_rad_s[i], sizeof(double)), 0)
          << "rotor " << i + 1 << " at t = " << clock.seconds(k) << ": " << cmd[i] << " vs " << out.omega_rad_s[i];
    }
    input = quad.rotor_input(cmd);
    for (int i = 0; i < c.controller_divider; ++i) quad.step(x, clock.seconds(k + i), input, clock.period_s(), 1);
  }
  // It flew there (the setpoint 1.2 m away): the closed loop, not only equal numbers.
  EXPECT_LT((x.p_W - c.setpoint.p_des_W).norm(), 0.1) << x.p_W.transpose();
}

}  // namespace
}  // namespace quadcosim::fmi::test
