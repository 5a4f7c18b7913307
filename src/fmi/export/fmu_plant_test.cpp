// The plant FMU through FMI 2.0, loaded with dlopen: its outputs against model::Quadrotor stepped
// natively tick by tick (bit for bit), and every bad use refused with a message, the instance usable after.
#include <clocale>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>

#include "fmi/export/fmu_test_support.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "model/attitude.hpp"
#include "model/quadrotor.hpp"
#include "sim/clock.hpp"

namespace quadcosim::fmi::test {
namespace {

/// One FMI 2 plant instance, instantiated and (by default) initialised.
class Plant : public Fmi2Instance {
 public:
  explicit Plant(const FmuConfig& config, bool initialise = true) : Fmi2Instance("plant", config) {
    if (initialise) init();
  }
  void command(const model::Vector4& omega) {
    for (int i = 0; i < 4; ++i) ASSERT_EQ(set(names::kOmegaCmd[static_cast<std::size_t>(i)], omega[i]), fmi2OK);
  }
};

/// The FMU's outputs equal `y` (and euler, omega from `x`) bit for bit.
void expect_outputs(Plant& p, const model::Outputs& y, const model::State& x, const std::string& where) {
  auto same = [&](const auto& names, const auto& values) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      const double got = p.get(names[i]), want = values[static_cast<Eigen::Index>(i)];
      EXPECT_EQ(std::memcmp(&got, &want, sizeof got), 0)
          << names[i] << " at " << where << ": " << got << " vs " << want;
    }
  };
  same(names::kPosition, y.p_W);
  same(names::kVelocity, y.v_W);
  same(names::kAttitude, Eigen::Vector4d(y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z()));
  const model::Euler e = model::euler_from_quaternion(y.q_WB);
  same(names::kEuler, Eigen::Vector3d(e.roll_rad, e.pitch_rad, e.yaw_rad));
  same(names::kRates, y.w_B);
  same(names::kSpecificForce, y.specific_force_B);
  same(names::kRotorSpeed, x.omega_rad_s);
}

/// Flies the FMU and model::Quadrotor side by side, 2 ticks per communication step, the command from
/// `command(j)` for step j, and compares every output after every step.
/// Returns the native model's final state.
model::State fly_side_by_side(FmuConfig config, const std::function<model::Vector4(int)>& command, int steps) {
  config.guid = make_guid(config);
  Plant fmu(config);
  const model::Quadrotor quad(config.vehicle);
  const sim::TickClock clock{config.plant_period_ns};
  model::State x = config.initial;
  model::RotorInput input = quad.rotor_input(x.omega_rad_s);
  expect_outputs(fmu, quad.outputs(0.0, x, input), x, "t = 0");
  sim::Tick k = 0;
  for (int j = 0; j < steps; ++j) {
    const model::Vector4 cmd = command(j);
    fmu.command(cmd);
    EXPECT_EQ(fmu.step(clock.seconds(k), 0.02), fmi2OK) << fmu.log_.last();
    input = quad.rotor_input(cmd);
    for (int i = 0; i < 2; ++i, ++k) quad.step(x, clock.seconds(k), input, clock.period_s(), config.substeps);
    expect_outputs(fmu, quad.outputs(clock.seconds(k), x, input), x, "tick " + std::to_string(k));
    if (::testing::Test::HasFailure()) break;
  }
  return x;
}

TEST(FmuPlant, HoverEqualsTheNativeModelBitForBit) {
  FmuConfig c = config_for(FmuKind::kPlant);
  c.initial.p_W = {1.0, -2.0, 5.0};
  const double hover = c.vehicle.hover_omega_rad_s();
  c.initial.omega_rad_s.setConstant(hover);
  const model::State x = fly_side_by_side(
      c, [&](int) { return model::Vector4::Constant(hover); }, 200);
  EXPECT_NEAR(x.p_W.z(), 5.0, 1e-9);
}

TEST(FmuPlant, SpinUpWithMotorLagAndTiltEqualsTheNativeModelBitForBit) {
  FmuConfig c = config_for(FmuKind::kPlant);
  c.vehicle.motor.model = model::MotorModel::kFirstOrder;
  c.substeps = 2;
  const double hover = c.vehicle.hover_omega_rad_s();
  // From rest on the ground: the rotors spin up past hover, rotor 1 a little faster (the vehicle tilts).
  const model::State x = fly_side_by_side(
      c,
      [&](int j) {
        const double w = std::min(1.2, 0.02 * j) * hover;
        return model::Vector4(w * 1.0002, w, w, w);
      },
      100);
  EXPECT_GT(x.p_W.z(), 0.1);                                     // it took off
  EXPECT_GT(std::abs(x.q_WB.x()) + std::abs(x.q_WB.y()), 1e-4);  // and tilted
  EXPECT_NEAR(x.omega_rad_s[1], 1.2 * hover, 1e-6);              // the lag has settled on the command
}

TEST(FmuPlant, LongerStepsAreTheSameTicks) {
  // One step of 0.1 s equals five of 0.02 s.
  FmuConfig c = config_for(FmuKind::kPlant);
  c.vehicle.motor.model = model::MotorModel::kFirstOrder;
  c.guid = make_guid(c);
  Plant a(c), b(c);
  const model::Vector4 cmd(9000.0, 8000.0, 9000.0, 8500.0);
  a.command(cmd);
  b.command(cmd);
  ASSERT_EQ(a.step(0.0, 0.1), fmi2OK);
  for (int j = 0; j < 5; ++j) ASSERT_EQ(b.step(0.02 * j, 0.02), fmi2OK) << b.log_.last();
  for (auto n : names::kPosition) EXPECT_EQ(a.get(n), b.get(n)) << n;
  for (auto n : names::kRotorSpeed) EXPECT_EQ(a.get(n), b.get(n)) << n;
}

// ---- bad use ------------------------------------------------------------------------------------

TEST(FmuPlantBadUse, WrongGuidIsRefusedWithAMessage) {
  const FmuConfig c = config_for(FmuKind::kPlant);
  Resources r(c);
  Log log;
  fmi2CallbackFunctions cb = log.fmi2_callbacks();
  EXPECT_EQ(QC_FMI(fmi2Instantiate)("p", fmi2CoSimulation, "{wrong}", r.uri().c_str(), &cb, 0, 0), nullptr);
  EXPECT_TRUE(log.contains("GUID mismatch")) << log.last();
  EXPECT_TRUE(log.contains("{wrong}")) << log.last();
  // Model exchange, a resource location that is not a file: URI, a folder without the configuration.
  EXPECT_EQ(QC_FMI(fmi2Instantiate)("p", fmi2ModelExchange, c.guid.c_str(), r.uri().c_str(), &cb, 0, 0), nullptr);
  EXPECT_TRUE(log.contains("co-simulation only")) << log.last();
  EXPECT_EQ(QC_FMI(fmi2Instantiate)("p", fmi2CoSimulation, c.guid.c_str(), "http://x/", &cb, 0, 0), nullptr);
  EXPECT_TRUE(log.contains("not a file: URI")) << log.last();
  EXPECT_EQ(QC_FMI(fmi2Instantiate)("p", fmi2CoSimulation, c.guid.c_str(), "file:///nonexistent/", &cb, 0, 0), nullptr);
  EXPECT_TRUE(log.contains("/nonexistent/quadcosim.json")) << log.last();
  // No logger at all: refused, no crash.
  fmi2CallbackFunctions silent{};
  EXPECT_EQ(QC_FMI(fmi2Instantiate)("p", fmi2CoSimulation, "{wrong}", r.uri().c_str(), &silent, 0, 0), nullptr);
  // A percent-escaped URI works.
  std::string escaped = r.uri();
  escaped.replace(escaped.find("quadcosim_fmu_test"), 1, "%71");  // 'q'
  fmi2Component ok = QC_FMI(fmi2Instantiate)("p", fmi2CoSimulation, c.guid.c_str(), escaped.c_str(), &cb, 0, 0);
  EXPECT_NE(ok, nullptr) << log.last();
  QC_FMI(fmi2FreeInstance)(ok);
}

TEST(FmuPlantBadUse, DoStepBeforeInitialisationEndsIsRefusedThenWorks) {
  const FmuConfig c = config_for(FmuKind::kPlant);
  Plant p(c, /*initialise=*/false);
  EXPECT_EQ(p.step(0.0, 0.01), fmi2Error);
  EXPECT_TRUE(p.log_.contains("doStep is allowed only after exitInitializationMode")) << p.log_.last();
  double v = 0.0;
  const fmi2ValueReference z = p.vr("p_W[3]");
  EXPECT_EQ(QC_FMI(fmi2GetReal)(p.c_, &z, 1, &v), fmi2Error);
  EXPECT_TRUE(p.log_.contains("not allowed before enterInitializationMode")) << p.log_.last();
  p.init();
  EXPECT_EQ(p.step(0.0, 0.01), fmi2OK) << p.log_.last();
}

TEST(FmuPlantBadUse, BadStepSizesAndTimesAreRefusedAndTheInstanceGoesOn) {
  const FmuConfig c = config_for(FmuKind::kPlant);
  Plant p(c);
  EXPECT_EQ(p.step(0.0, -0.01), fmi2Error);
  EXPECT_TRUE(p.log_.contains("h = -0.01 s: it must be positive")) << p.log_.last();
  EXPECT_EQ(p.step(0.0, 0.0), fmi2Error);
  EXPECT_TRUE(p.log_.contains("h = 0 s: it must be positive")) << p.log_.last();
  EXPECT_EQ(p.step(0.0, 0.015), fmi2Error);
  EXPECT_TRUE(p.log_.contains("h = 0.015 s is not a whole number of periods (period 0.01 s)")) << p.log_.last();
  EXPECT_EQ(p.step(0.05, 0.01), fmi2Error);
  EXPECT_TRUE(p.log_.contains("doStep from t = 0.05 s, but the FMU is at t = 0 s")) << p.log_.last();
  EXPECT_EQ(p.step(0.0, 0.01 + 2e-9), fmi2OK) << p.log_.last();  // within the tolerance of a few ns
  EXPECT_EQ(p.step(0.01, 0.03), fmi2OK) << p.log_.last();
  double t = 0.0;
  EXPECT_EQ(QC_FMI(fmi2GetRealStatus)(p.c_, fmi2LastSuccessfulTime, &t), fmi2OK);
  EXPECT_DOUBLE_EQ(t, 0.04);
  EXPECT_DOUBLE_EQ(p.get("time"), 0.04);
}

TEST(FmuPlantBadUse, UnknownValueReferencesAndWrongTypesAreNamed) {
  const FmuConfig c = config_for(FmuKind::kPlant);
  Plant p(c);
  const fmi2ValueReference unknown = 99999;
  double v = 1.0;
  EXPECT_EQ(QC_FMI(fmi2GetReal)(p.c_, &unknown, 1, &v), fmi2Error);
  EXPECT_TRUE(p.log_.contains("unknown value reference 99999")) << p.log_.last();
  EXPECT_EQ(QC_FMI(fmi2SetReal)(p.c_, &unknown, 1, &v), fmi2Error);
  EXPECT_TRUE(p.log_.contains("setReal: unknown value reference 99999")) << p.log_.last();
  const fmi2ValueReference z = p.vr("p_W[3]");
  fmi2Integer i = 0;
  EXPECT_EQ(QC_FMI(fmi2GetInteger)(p.c_, &z, 1, &i), fmi2Error);
  EXPECT_TRUE(p.log_.contains("p_W[3] (value reference " + std::to_string(z) + ") is Real, not Integer"))
      << p.log_.last();
  EXPECT_EQ(p.step(0.0, 0.01), fmi2OK) << p.log_.last();
}

TEST(FmuPlantBadUse, SettingWhatCannotBeSetIsRefusedNamingIt) {
  const FmuConfig c = config_for(FmuKind::kPlant);
  Plant p(c);
  EXPECT_EQ(p.set("p_W[3]", 3.0), fmi2Error);
  EXPECT_TRUE(p.log_.contains("p_W[3] is an output (computed by the FMU): it cannot be set")) << p.log_.last();
  EXPECT_EQ(p.set("time", 3.0), fmi2Error);
  EXPECT_TRUE(p.log_.contains("time is the independent variable")) << p.log_.last();
  EXPECT_EQ(p.set("period", 0.02), fmi2Error);
  EXPECT_TRUE(p.log_.contains("period is a constant: it cannot be set")) << p.log_.last();
  EXPECT_EQ(p.get("period"), 0.01);  // the plant period, unchanged
  EXPECT_EQ(p.set("vehicle.mass_kg", 3.0), fmi2Error);
  EXPECT_TRUE(p.log_.contains("vehicle.mass_kg is a fixed parameter: it can be set only before exitInitializationMode"))
      << p.log_.last();
  EXPECT_EQ(p.get("vehicle.mass_kg"), c.vehicle.mass_kg);
  EXPECT_EQ(p.step(0.0, 0.01), fmi2OK) << p.log_.last();
}

TEST(FmuPlantBadUse, NonFiniteCommandIsRefusedAndTheLastOneHeld) {
  FmuConfig c = config_for(FmuKind::kPlant);
  c.initial.p_W.z() = 3.0;
  c.initial.omega_rad_s.setConstant(c.vehicle.hover_omega_rad_s());
  c.guid = make_guid(c);
  Plant p(c);
  EXPECT_EQ(p.set("omega_cmd[2]", std::numeric_limits<double>::quiet_NaN()), fmi2Error);
  EXPECT_TRUE(p.log_.contains("omega_cmd[2] = nan refused: not a finite number")) << p.log_.last();
  EXPECT_EQ(p.set("omega_cmd[3]", std::numeric_limits<double>::infinity()), fmi2Error);
  EXPECT_TRUE(p.log_.contains("omega_cmd[3] = inf refused")) << p.log_.last();
  EXPECT_EQ(p.get("omega_cmd[2]"), c.vehicle.hover_omega_rad_s());
  ASSERT_EQ(p.step(0.0, 0.5), fmi2OK) << p.log_.last();
  EXPECT_NEAR(p.get("p_W[3]"), 3.0, 1e-9);  // still hovering on the held command
}

TEST(FmuPlantBadUse, VehicleParametersAreCheckedWhenSetAndWhenInitialisationEnds) {
  const FmuConfig c = config_for(FmuKind::kPlant);
  Plant p(c, /*initialise=*/false);
  ASSERT_EQ(QC_FMI(fmi2EnterInitializationMode)(p.c_), fmi2OK);
  EXPECT_EQ(p.set("vehicle.mass_kg", -1.0), fmi2Error);
  EXPECT_TRUE(p.log_.contains("vehicle.mass_kg = -1 is outside [1e-06, 1e+12]")) << p.log_.last();
  ASSERT_EQ(p.set("vehicle.motor.omega_min_rad_s", 13000.0), fmi2OK);  // above omega_max: a rule between fields
  EXPECT_EQ(QC_FMI(fmi2ExitInitializationMode)(p.c_), fmi2Error);
  EXPECT_TRUE(p.log_.contains("vehicle parameter refused: vehicle.")) << p.log_.last();
  EXPECT_TRUE(p.log_.contains("omega_min_rad_s")) << p.log_.last();
  ASSERT_EQ(p.set("vehicle.motor.omega_min_rad_s", 0.0), fmi2OK);
  ASSERT_EQ(p.set("vehicle.mass_kg", 2.5), fmi2OK);
  EXPECT_EQ(QC_FMI(fmi2ExitInitializationMode)(p.c_), fmi2OK) << p.log_.last();
  EXPECT_EQ(p.get("vehicle.mass_kg"), 2.5);
  // The heavier vehicle falls under the default vehicle's hover command... it rests on the ground here.
  EXPECT_EQ(p.step(0.0, 0.01), fmi2OK) << p.log_.last();
}

TEST(FmuPlantBadUse, UnsupportedFunctionsAnswerErrorWithAMessage) {
  const FmuConfig c = config_for(FmuKind::kPlant);
  Plant p(c);
  fmi2Real x[13];
  EXPECT_EQ(QC_FMI(fmi2GetDerivatives)(p.c_, x, 13), fmi2Error);
  EXPECT_TRUE(p.log_.contains("fmi2GetDerivatives is not supported: this FMU is for co-simulation only"));
  EXPECT_EQ(QC_FMI(fmi2CancelStep)(p.c_), fmi2Error);
  EXPECT_TRUE(p.log_.contains("fmi2CancelStep is not supported"));
  size_t size = 0;
  EXPECT_EQ(QC_FMI(fmi2SerializedFMUstateSize)(p.c_, nullptr, &size), fmi2Error);
  EXPECT_TRUE(p.log_.contains("cannot be serialized"));
  EXPECT_EQ(QC_FMI(fmi2DoStep)(nullptr, 0.0, 0.01, fmi2True), fmi2Error);  // a null instance
  EXPECT_EQ(p.step(0.0, 0.01), fmi2OK) << p.log_.last();
  EXPECT_EQ(QC_FMI(fmi2Terminate)(p.c_), fmi2OK);
  EXPECT_EQ(p.step(0.01, 0.01), fmi2Error);
  EXPECT_TRUE(p.log_.contains("not in terminated")) << p.log_.last();
  EXPECT_EQ(QC_FMI(fmi2Reset)(p.c_), fmi2OK);
  p.init();
  EXPECT_EQ(p.step(0.0, 0.01), fmi2OK) << p.log_.last();
}

TEST(FmuPlant, StateCanBeSavedAndRestored) {
  FmuConfig c = config_for(FmuKind::kPlant);
  c.vehicle.motor.model = model::MotorModel::kFirstOrder;
  c.guid = make_guid(c);
  Plant p(c);
  p.command(model::Vector4(9000.0, 9100.0, 9000.0, 9050.0));
  ASSERT_EQ(p.step(0.0, 0.2), fmi2OK);
  fmi2FMUstate saved = nullptr;
  ASSERT_EQ(QC_FMI(fmi2GetFMUstate)(p.c_, &saved), fmi2OK);
  ASSERT_EQ(p.step(0.2, 0.3), fmi2OK);
  const double z = p.get("p_W[3]"), roll = p.get("euler[1]");
  ASSERT_EQ(QC_FMI(fmi2SetFMUstate)(p.c_, saved), fmi2OK);
  ASSERT_EQ(p.step(0.2, 0.3), fmi2OK) << p.log_.last();
  EXPECT_EQ(p.get("p_W[3]"), z);
  EXPECT_EQ(p.get("euler[1]"), roll);
  EXPECT_EQ(QC_FMI(fmi2FreeFMUstate)(p.c_, &saved), fmi2OK);
  EXPECT_EQ(saved, nullptr);
}

TEST(FmuPlant, ParametersSetBeforeInitialisationTakeEffect) {
  const FmuConfig c = config_for(FmuKind::kPlant);
  Plant p(c, /*initialise=*/false);
  ASSERT_EQ(p.set("initial.p_W[3]", 7.0), fmi2OK);
  ASSERT_EQ(p.set("initial.v_W[1]", 1.5), fmi2OK);
  ASSERT_EQ(QC_FMI(fmi2EnterInitializationMode)(p.c_), fmi2OK);
  EXPECT_EQ(p.get("p_W[3]"), 7.0);  // outputs in initialization mode follow the parameters
  ASSERT_EQ(QC_FMI(fmi2ExitInitializationMode)(p.c_), fmi2OK);
  ASSERT_EQ(p.step(0.0, 0.5), fmi2OK);
  // Free fall with the rotors stopped, no drag: z = 7 - g t^2 / 2, x = 1.5 t (RK4 exact on polynomials).
  EXPECT_NEAR(p.get("p_W[3]"), 7.0 - 0.5 * c.vehicle.gravity_m_s2 * 0.25, 1e-12);
  EXPECT_NEAR(p.get("p_W[1]"), 0.75, 1e-12);
  EXPECT_NEAR(p.get("f_B[3]"), 0.0, 1e-12);  // free fall: the accelerometer reads nothing
}

}  // namespace
}  // namespace quadcosim::fmi::test

namespace quadcosim::fmi::test {
namespace {

TEST(FmuPlant, NumbersAreReadTheSameUnderADecimalCommaLocale) {
  // An importer (a GUI tool) may run with a locale whose decimal separator is a comma.
  const char* locale = nullptr;
  for (const char* l : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8"}) {
    if (std::setlocale(LC_ALL, l)) {
      locale = l;
      break;
    }
  }
  if (!locale) GTEST_SKIP() << "no decimal-comma locale is installed (de_DE, fr_FR)";
  FmuConfig c = config_for(FmuKind::kPlant);
  c.initial.p_W.z() = 2.5;
  c.guid = make_guid(c);
  Plant p(c);
  EXPECT_EQ(p.get("vehicle.mass_kg"), 1.96);
  EXPECT_EQ(p.get("p_W[3]"), 2.5);
  std::setlocale(LC_ALL, "C");
}

}  // namespace
}  // namespace quadcosim::fmi::test
