// The FMU binary through FMI 3.0: instantiate, initialise, step and read both kinds, against
// model::Quadrotor and a natively stepped controller, and the FMI 3 specific refusals.
#include <cstring>

#include "controllers/registry.hpp"
#include "fmi/export/fmu_test_support.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "model/attitude.hpp"
#include "model/quadrotor.hpp"
#include "sim/clock.hpp"

namespace quadcosim::fmi::test {
namespace {

class Instance3 {
 public:
  explicit Instance3(const FmuConfig& config) : md_(describe(config)), resources_(config) {
    i_ = QC_FMI(fmi3InstantiateCoSimulation)("fmu3", config.guid.c_str(), resources_.path().c_str(), false, false,
                                             false, false, nullptr, 0, &log_, &Log::fmi3_logger, nullptr);
    if (!i_) throw std::runtime_error("instantiate failed: " + log_.last());
  }
  ~Instance3() { QC_FMI(fmi3FreeInstance)(i_); }
  void init() {
    ASSERT_EQ(QC_FMI(fmi3EnterInitializationMode)(i_, false, 0.0, 0.0, false, 0.0), fmi3OK) << log_.last();
    ASSERT_EQ(QC_FMI(fmi3ExitInitializationMode)(i_), fmi3OK) << log_.last();
  }
  fmi3ValueReference vr(std::string_view name) const {
    for (const Variable& v : md_.variables) {
      if (v.name == name) return v.vr;
    }
    throw std::runtime_error("no variable " + std::string(name));
  }
  template <std::size_t N>
  Eigen::Matrix<double, static_cast<int>(N), 1> get(const std::array<std::string_view, N>& names) {
    std::array<fmi3ValueReference, N> vrs{};
    for (std::size_t i = 0; i < N; ++i) vrs[i] = vr(names[i]);
    Eigen::Matrix<double, static_cast<int>(N), 1> v;
    EXPECT_EQ(QC_FMI(fmi3GetFloat64)(i_, vrs.data(), N, v.data(), N), fmi3OK) << log_.last();
    return v;
  }
  template <std::size_t N, class V>
  void set(const std::array<std::string_view, N>& names, const V& values) {
    std::array<fmi3ValueReference, N> vrs{};
    std::array<double, N> v{};
    for (std::size_t i = 0; i < N; ++i) {
      vrs[i] = vr(names[i]);
      v[i] = values[static_cast<Eigen::Index>(i)];
    }
    ASSERT_EQ(QC_FMI(fmi3SetFloat64)(i_, vrs.data(), N, v.data(), N), fmi3OK) << log_.last();
  }
  fmi3Status step(double t, double h, double* last = nullptr) {
    fmi3Boolean event = true, terminate = true, early = true;
    double last_time = -1.0;
    const fmi3Status s = QC_FMI(fmi3DoStep)(i_, t, h, true, &event, &terminate, &early, &last_time);
    EXPECT_FALSE(event || terminate || early);
    if (last) *last = last_time;
    return s;
  }

  fmi3Instance i_ = nullptr;
  Log log_;

 private:
  ModelDescription md_;
  Resources resources_;
};

template <int N>
void expect_bits(const Eigen::Matrix<double, N, 1>& got, const Eigen::Matrix<double, N, 1>& want, const char* what) {
  for (int i = 0; i < N; ++i) EXPECT_EQ(std::memcmp(&got[i], &want[i], sizeof(double)), 0) << what << "[" << i + 1 << "]";
}

TEST(FmuFmi3, PlantStepsAsTheNativeModel) {
  FmuConfig c = config_for(FmuKind::kPlant, FmiVersion::k3);
  c.initial.p_W.z() = 2.0;
  c.guid = make_guid(c);
  Instance3 fmu(c);
  fmu.init();
  const model::Quadrotor quad(c.vehicle);
  const sim::TickClock clock{c.plant_period_ns};
  model::State x = c.initial;
  const model::Vector4 cmd(7200.0, 7100.0, 7200.0, 7100.0);  // near hover, yawing
  fmu.set(names::kOmegaCmd, cmd);
  const model::RotorInput input = quad.rotor_input(cmd);
  sim::Tick k = 0;
  for (int j = 0; j < 50; ++j) {
    double last = 0.0;
    ASSERT_EQ(fmu.step(clock.seconds(k), 0.02, &last), fmi3OK) << fmu.log_.last();
    for (int i = 0; i < 2; ++i, ++k) quad.step(x, clock.seconds(k), input, clock.period_s(), c.substeps);
    EXPECT_EQ(last, clock.seconds(k));
  }
  const model::Outputs y = quad.outputs(clock.seconds(k), x, input);
  expect_bits(fmu.get(names::kPosition), y.p_W, "p_W");
  expect_bits(fmu.get(names::kVelocity), y.v_W, "v_W");
  expect_bits(fmu.get(names::kAttitude), Eigen::Vector4d(y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z()), "q_WB");
  expect_bits(fmu.get(names::kRates), y.w_B, "w_B");
  expect_bits(fmu.get(names::kSpecificForce), y.specific_force_B, "f_B");
  EXPECT_NE(fmu.get(names::kEuler)[2], 0.0);  // it yawed
}

TEST(FmuFmi3, ControllerStepsAsTheNativeController) {
  FmuConfig c = config_for(FmuKind::kController, FmiVersion::k3);
  c.controller_type = "se3";
  c.setpoint.mode = control::Mode::kPosition;
  c.setpoint.p_des_W = {1.0, 2.0, 3.0};
  c.guid = make_guid(c);
  Instance3 fmu(c);
  fmu.init();
  fmu.set(names::kPosition, Eigen::Vector3d(0.5, 0.0, 2.0));
  ASSERT_EQ(fmu.step(0.0, 0.02), fmi3OK) << fmu.log_.last();

  std::unique_ptr<control::Controller> native = controllers::make_config("se3", c.vehicle).controller->clone();
  control::ControllerOutput out;
  out.outputs.assign(native->output_names().size(), 0.0);
  control::Observation o;
  o.p_W = {0.5, 0.0, 2.0};
  o.age_s = 0.0;
  control::Reference r;
  r.mode = control::Mode::kPosition;
  r.p_W = c.setpoint.p_des_W;
  native->step(o, r, 0.02, out);
  expect_bits(fmu.get(names::kOmegaCmd), Eigen::Vector4d(out.omega_rad_s), "omega_cmd");

  // Parameters of the type: Float64 "controller.<name>".
  const fmi3ValueReference first = fmu.vr("controller." + std::string(native->parameters()[0].name));
  double value = 0.0;
  ASSERT_EQ(QC_FMI(fmi3GetFloat64)(fmu.i_, &first, 1, &value, 1), fmi3OK);
  EXPECT_EQ(value, std::get<double>(*native->get_parameter(native->parameters()[0].name)));
}

TEST(FmuFmi3, RefusalsAreLoggedAndTheInstanceStaysUsable) {
  const FmuConfig c = config_for(FmuKind::kPlant, FmiVersion::k3);
  Resources r(c);
  Log log;
  auto instantiate = QC_FMI(fmi3InstantiateCoSimulation);
  EXPECT_EQ(instantiate("x", "{wrong}", r.path().c_str(), false, false, false, false, nullptr, 0, &log,
                        &Log::fmi3_logger, nullptr),
            nullptr);
  EXPECT_TRUE(log.contains("instantiationToken mismatch")) << log.last();
  EXPECT_EQ(instantiate("x", c.guid.c_str(), r.path().c_str(), false, false, true, false, nullptr, 0, &log,
                        &Log::fmi3_logger, nullptr),
            nullptr);
  EXPECT_TRUE(log.contains("no event mode")) << log.last();
  EXPECT_EQ(QC_FMI(fmi3InstantiateModelExchange)("x", c.guid.c_str(), r.path().c_str(), false, false, &log,
                                                 &Log::fmi3_logger),
            nullptr);
  EXPECT_TRUE(log.contains("co-simulation only")) << log.last();
  // No logger: refused, no crash.
  EXPECT_EQ(instantiate("x", "{wrong}", r.path().c_str(), false, false, false, false, nullptr, 0, nullptr, nullptr,
                        nullptr),
            nullptr);
  // An FMI 2 configuration instantiated through FMI 3.
  const FmuConfig c2 = config_for(FmuKind::kPlant, FmiVersion::k2);
  Resources r2(c2);
  EXPECT_EQ(instantiate("x", c2.guid.c_str(), r2.path().c_str(), false, false, false, false, nullptr, 0, &log,
                        &Log::fmi3_logger, nullptr),
            nullptr);
  EXPECT_TRUE(log.contains("is an FMI 2.0 FMU")) << log.last();

  Instance3 fmu(c);
  EXPECT_EQ(fmu.step(0.0, 0.01), fmi3Error);
  EXPECT_TRUE(fmu.log_.contains("doStep is allowed only after exitInitializationMode")) << fmu.log_.last();
  fmu.init();
  const fmi3ValueReference z = fmu.vr("p_W[3]");
  float f = 0.0f;
  EXPECT_EQ(QC_FMI(fmi3GetFloat32)(fmu.i_, &z, 1, &f, 1), fmi3Error);
  EXPECT_TRUE(fmu.log_.contains("the FMU has no Float32 variables")) << fmu.log_.last();
  double d[2];
  EXPECT_EQ(QC_FMI(fmi3GetFloat64)(fmu.i_, &z, 1, d, 2), fmi3Error);
  EXPECT_TRUE(fmu.log_.contains("every variable of this FMU is a scalar")) << fmu.log_.last();
  const fmi3ValueReference seed = fmu.vr("realism.seed");
  fmi3Int32 s = -1;
  EXPECT_EQ(QC_FMI(fmi3GetInt32)(fmu.i_, &seed, 1, &s, 1), fmi3OK);
  EXPECT_EQ(s, 0);
  const fmi3ValueReference wind = fmu.vr("realism.wind");
  const fmi3Boolean on = true;
  EXPECT_EQ(QC_FMI(fmi3SetBoolean)(fmu.i_, &wind, 1, &on, 1), fmi3Error);  // fixed, after initialisation
  EXPECT_TRUE(fmu.log_.contains("realism.wind is a fixed parameter")) << fmu.log_.last();
  EXPECT_EQ(QC_FMI(fmi3EnterStepMode)(fmu.i_), fmi3Error);
  EXPECT_TRUE(fmu.log_.contains("fmi3EnterStepMode is not supported")) << fmu.log_.last();
  EXPECT_EQ(fmu.step(0.0, -1.0), fmi3Error);
  EXPECT_TRUE(fmu.log_.contains("it must be positive")) << fmu.log_.last();
  EXPECT_EQ(fmu.step(0.0, 0.01), fmi3OK) << fmu.log_.last();
  EXPECT_EQ(QC_FMI(fmi3Terminate)(fmu.i_), fmi3OK);
}

}  // namespace
}  // namespace quadcosim::fmi::test
