// The FMU plant and controller (fmi/fmu_plant.hpp, fmi/fmu_controller.hpp) over an in-memory FMU:
// an fmi::Fmu whose instances compute a vertical point mass in C++, so that the mapping, the calls
// and their order, and every refusal are checked without a binary. Loaded FMUs are flown in
// tests/fmi (the point mass in C) and the round trips of tests/fmi/round_trip_cases.sh.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fmi/fmu_controller.hpp"
#include "fmi/fmu_plant.hpp"
#include "fmi/quadrotor_variables.hpp"

namespace quadcosim::fmi {
namespace {

/// A mapping whose instances stay in this process: the in-memory FMUs below record their calls in a
/// Journal here (an isolated instance would record them in its child; tests/foreign covers isolation).
FmuMapping in_memory(FmuMapping m = {}) {
  m.isolated = false;
  return m;
}

/// What the in-memory instances were asked, over all of them.
struct Journal {
  std::vector<std::string> calls;
  std::map<std::string, double> set;  ///< last value set per variable name
  int instances = 0;
};

Variable var(std::string name, ValueReference vr, Causality c, std::string unit,
             Variability v = Variability::kContinuous, std::optional<std::string> start = std::nullopt) {
  Variable x;
  x.name = std::move(name);
  x.vr = vr;
  x.causality = c;
  x.unit = std::move(unit);
  x.variability = v;
  x.start = std::move(start);
  return x;
}

/// A point mass moving along z under the four rotors' thrust k_t sum(omega^2) and gravity, with the
/// plant FMU's default variable names (a subset: no attitude, rates or specific force), stepped
/// exactly: constant acceleration over a step.
ModelDescription point_mass_description(int rotors = 4) {
  ModelDescription md;
  md.fmi_version = "2.0";
  md.model_name = "PointMass";
  md.model_identifier = "point_mass";
  ValueReference vr = 1;
  for (auto n : names::omega_cmd(rotors)) md.variables.push_back(var(std::string(n), vr++, Causality::kInput, "rad/s"));
  for (auto n : names::kPosition) md.variables.push_back(var(std::string(n), vr++, Causality::kOutput, "m"));
  for (auto n : names::kVelocity) md.variables.push_back(var(std::string(n), vr++, Causality::kOutput, "m/s"));
  md.variables.push_back(var("vehicle.mass_kg", vr++, Causality::kParameter, "kg", Variability::kFixed, "1"));
  md.variables.push_back(var("vehicle.kt_N_per_rad2_s2", vr++, Causality::kParameter, "", Variability::kFixed, "1e-7"));
  md.variables.push_back(var("vehicle.gravity_m_s2", vr++, Causality::kParameter, "m/s2", Variability::kFixed, "9.81"));
  md.variables.push_back(var("initial.p_W[3]", vr++, Causality::kParameter, "m", Variability::kFixed, "0"));
  md.variables.push_back(var("drag", vr++, Causality::kParameter, "", Variability::kTunable, "0"));
  return md;
}

class PointMassInstance final : public Instance {
 public:
  PointMassInstance(std::shared_ptr<Fmu> fmu, Journal& j) : Instance(std::move(fmu)), j_(j) { ++j_.instances; }
  void enter_initialization(double t, std::optional<double>) override {
    j_.calls.push_back("enter@" + std::to_string(t));
  }
  void exit_initialization() override {
    j_.calls.push_back("exit");
    z_ = value("initial.p_W[3]");
  }
  void do_step(double t, double h) override {
    j_.calls.push_back("step");
    if (fail_at_ >= 0 && t >= fail_at_) throw FmuError("fmi2DoStep: Error (the FMU logged: it broke)");
    double sum = 0.0;
    for (auto n : names::kOmegaCmdAll) sum += value(std::string(n)) * value(std::string(n));  // 0: absent
    const double a = value("vehicle.kt_N_per_rad2_s2") * sum / value("vehicle.mass_kg") - value("vehicle.gravity_m_s2");
    z_ += v_ * h + 0.5 * a * h * h;
    v_ += a * h;
    last_t_ = t;
  }
  void terminate() override {}
  void reset() override {}
  void get_real(std::span<const ValueReference> vr, std::span<double> out) override {
    for (std::size_t i = 0; i < vr.size(); ++i) {
      const std::string& n = name(vr[i]);
      out[i] = n == "p_W[3]" ? z_ : n == "v_W[3]" ? v_ : n == "p_W[1]" ? nan_x_ : 0.0;
    }
  }
  void set_real(std::span<const ValueReference> vr, std::span<const double> v) override {
    for (std::size_t i = 0; i < vr.size(); ++i) values_[name(vr[i])] = j_.set[name(vr[i])] = v[i];
  }
  void get_integer(std::span<const ValueReference>, std::span<std::int32_t>) override {}
  void set_integer(std::span<const ValueReference>, std::span<const std::int32_t>) override {}
  void get_boolean(std::span<const ValueReference>, std::span<bool>) override {}
  void set_boolean(std::span<const ValueReference>, std::span<const bool>) override {}
  void set_string(std::span<const ValueReference>, std::span<const std::string>) override {}

  double fail_at_ = -1.0;
  double nan_x_ = 0.0;

 private:
  const std::string& name(ValueReference vr) const {
    for (const Variable& v : description().variables) {
      if (v.vr == vr) return v.name;
    }
    throw FmuError("unknown value reference " + std::to_string(vr));
  }
  double value(const std::string& n) const {
    if (auto it = values_.find(n); it != values_.end()) return it->second;
    const Variable* v = description().find(n);
    return v && v->start ? std::stod(*v->start) : 0.0;
  }
  Journal& j_;
  std::map<std::string, double> values_;
  double z_ = 0.0, v_ = 0.0, last_t_ = 0.0;
};

class MemoryFmu final : public Fmu {
 public:
  MemoryFmu(ModelDescription md, Journal& j) : j_(j) {
    description_ = std::move(md);
    path_ = "/nowhere/" + description_.model_identifier + ".fmu";
  }
  std::unique_ptr<Instance> instantiate(const std::string& name, LogSink) override {
    j_.calls.push_back("instantiate " + name);
    auto i = std::make_unique<PointMassInstance>(shared_from_this(), j_);
    i->fail_at_ = fail_at;
    i->nan_x_ = nan_x;
    return i;
  }
  double fail_at = -1.0;
  double nan_x = 0.0;

 private:
  Journal& j_;
};

TEST(FmuPlantAsPlant, StepsThePointMassAndSetsVehicleAndInitialState) {
  Journal j;
  auto fmu = std::make_shared<MemoryFmu>(point_mass_description(), j);
  const FmuPlant plant(fmu, in_memory());
  EXPECT_TRUE(plant.refs().q_WB.empty());
  model::VehicleParams vehicle;
  model::State x0;
  x0.p_W = {0.0, 0.0, 2.0};
  x0.omega_rad_s.setConstant(100.0);
  const sim::TickClock clock{10'000'000};
  auto d = plant.make(vehicle, x0, clock);
  EXPECT_EQ(j.set.at("vehicle.mass_kg"), vehicle.mass_kg);
  EXPECT_EQ(j.set.at("vehicle.kt_N_per_rad2_s2"), vehicle.kt_N_per_rad2_s2);
  EXPECT_EQ(j.set.at("initial.p_W[3]"), 2.0);
  ASSERT_EQ(j.calls.size(), 3u);
  EXPECT_EQ(j.calls[1], "enter@0.000000");

  model::Outputs y;
  model::State x;
  d->outputs(0, y, x);
  EXPECT_EQ(y.p_W.z(), 2.0);
  EXPECT_EQ(x.omega_rad_s, x0.omega_rad_s);  // no omega output: the command acting
  // Defaults of the absent outputs: level, no rotation, the accelerometer at rest reads (0, 0, g).
  EXPECT_EQ(y.q_WB.coeffs(), Eigen::Quaterniond::Identity().coeffs());
  EXPECT_EQ(y.w_B, Eigen::Vector3d::Zero());
  EXPECT_EQ(y.specific_force_B, Eigen::Vector3d(0.0, 0.0, vehicle.gravity_m_s2));

  // Constant commands: z(t) = z0 + a t^2 / 2 with a = 4 k_t w^2 / m - g.
  const double w = 3000.0;
  const double a = 4.0 * vehicle.kt_N_per_rad2_s2 * w * w / vehicle.mass_kg - vehicle.gravity_m_s2;
  for (sim::Tick k = 0; k < 100; ++k) d->step(k, model::Vector4::Constant(w));
  d->outputs(100, y, x);
  EXPECT_NEAR(y.p_W.z(), 2.0 + 0.5 * a * 1.0, 1e-9);
  EXPECT_NEAR(y.v_W.z(), a * 1.0, 1e-9);
  EXPECT_EQ(x.omega_rad_s, model::Vector4::Constant(w));
}

TEST(FmuPlantAsPlant, AHexarotorFmuTakesSixCommandsAndRefusesAQuadrotorNamingBothCounts) {
  Journal j;
  auto fmu = std::make_shared<MemoryFmu>(point_mass_description(6), j);
  const FmuPlant plant(fmu, in_memory());
  EXPECT_EQ(plant.rotor_count(), 6);
  EXPECT_EQ(plant.refs().omega_cmd.size(), 6u);
  const sim::TickClock clock{10'000'000};
  const model::VehicleParams quad;
  EXPECT_EQ(plant.check(quad),
            "point_mass.fmu: the FMU plant takes 6 rotor speed commands (omega_cmd[1..6]); the vehicle has 4 rotors "
            "(layout plus)");
  EXPECT_THROW(plant.make(quad, model::State{}, clock), FmuError);

  model::VehicleParams hex;
  hex.set_layout(model::RotorLayout::kHexX);
  EXPECT_EQ(plant.check(hex), "");
  model::State x0;
  x0.p_W = {0.0, 0.0, 2.0};
  x0.omega_rad_s = model::RotorVector::Constant(6, 100.0);
  auto d = plant.make(hex, x0, clock);
  EXPECT_EQ(j.set.at("omega_cmd[6]"), 100.0);  // the initial speeds, the sixth included
  // Six different commands: z(t) = z0 + a t^2 / 2 with a = k_t sum(w_i^2) / m - g.
  model::RotorVector w(6);
  w << 3000.0, 2900.0, 3100.0, 3000.0, 2950.0, 3050.0;
  const double a = hex.kt_N_per_rad2_s2 * w.squaredNorm() / hex.mass_kg - hex.gravity_m_s2;
  for (sim::Tick k = 0; k < 100; ++k) d->step(k, w);
  model::Outputs y;
  model::State x;
  d->outputs(100, y, x);
  EXPECT_NEAR(y.p_W.z(), 2.0 + 0.5 * a * 1.0, 1e-9);
  EXPECT_EQ(x.omega_rad_s, w);  // no omega output: the command acting
  EXPECT_EQ(j.set.at("omega_cmd[6]"), 3050.0);

  FmuMapping three;
  three.inputs["omega_cmd"] = {"omega_cmd[1]", "omega_cmd[2]", "omega_cmd[3]"};
  try {
    FmuPlant p(fmu, in_memory(three));
    ADD_FAILURE() << "three rotor commands were taken";
  } catch (const MappingError& e) {
    EXPECT_EQ(e.key(), "inputs.omega_cmd");
    EXPECT_NE(std::string(e.what()).find("got 3 names, expected 4 to 8"), std::string::npos) << e.what();
  }
}

TEST(FmuPlantAsPlant, ScenarioParametersWinAndAreChecked) {
  Journal j;
  auto fmu = std::make_shared<MemoryFmu>(point_mass_description(), j);
  FmuMapping m;
  m.parameters = {{"vehicle.mass_kg", "3"}, {"drag", "0.5"}};
  const FmuPlant plant(fmu, in_memory(m));
  auto d = plant.make(model::VehicleParams{}, model::State{}, sim::TickClock{});
  EXPECT_EQ(j.set.at("vehicle.mass_kg"), 3.0);
  EXPECT_EQ(j.set.at("drag"), 0.5);

  auto refused = [&](FmuMapping mm, const std::string& key, const std::string& words) {
    try {
      FmuPlant p(fmu, in_memory(mm));
      ADD_FAILURE() << "not refused: " << key;
    } catch (const MappingError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  FmuMapping bad;
  bad.parameters = {{"nope", "1"}};
  refused(bad, "parameters.nope", "no variable 'nope'");
  bad.parameters = {{"drag", "heavy"}};
  refused(bad, "parameters.drag", "expected a finite number");
  bad.parameters = {{"p_W[1]", "1"}};
  refused(bad, "parameters.p_W[1]", "causality output");
}

TEST(FmuPlantAsPlant, MappingRefusalsNameTheKeyTheVariableAndTheUnit) {
  Journal j;
  auto refused = [&](ModelDescription md, FmuMapping m, const std::string& key, const std::string& words) {
    auto fmu = std::make_shared<MemoryFmu>(std::move(md), j);
    try {
      FmuPlant p(fmu, in_memory(m));
      ADD_FAILURE() << "not refused: " << key;
    } catch (const MappingError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  // Required and absent by the default names.
  ModelDescription no_v = point_mass_description();
  std::erase_if(no_v.variables, [](const Variable& v) { return v.name.rfind("v_W", 0) == 0; });
  refused(no_v, {}, "outputs.v_W", "no variable 'v_W[1]', 'v_W[2]', 'v_W[3]'");
  // Named, but not there.
  FmuMapping m;
  m.outputs["p_W"] = {"x", "y", "z"};
  refused(point_mass_description(), m, "outputs.p_W", "no variable 'x'");
  // Wrong count, unknown signal.
  m.outputs["p_W"] = {"p_W[1]", "p_W[2]"};
  refused(point_mass_description(), m, "outputs.p_W", "expected 3");
  FmuMapping unknown;
  unknown.outputs["position"] = {"p_W[1]", "p_W[2]", "p_W[3]"};
  refused(point_mass_description(), unknown, "outputs.position", "unknown signal");
  // Unit: a position in millimetres.
  ModelDescription mm = point_mass_description();
  for (Variable& v : mm.variables) {
    if (v.name == "p_W[2]") v.unit = "mm";
  }
  refused(mm, {}, "outputs.p_W", "variable 'p_W[2]' has unit 'mm', expected 'm'");
  // Causality: an output mapped as the command input.
  FmuMapping in;
  in.inputs["omega_cmd"] = {"p_W[1]", "p_W[2]", "p_W[3]", "v_W[1]"};
  refused(point_mass_description(), in, "inputs.omega_cmd", "causality output, expected input");
  // Type.
  ModelDescription integer = point_mass_description();
  integer.variables[0].type = VariableType::kInteger;
  refused(integer, {}, "inputs.omega_cmd", "expected Real");
}

TEST(FmuPlantAsPlant, FailuresNameTheTickAndNothingNonFiniteGetsThrough) {
  Journal j;
  auto fmu = std::make_shared<MemoryFmu>(point_mass_description(), j);
  fmu->fail_at = 0.05;
  const FmuPlant plant(fmu, in_memory());
  auto d = plant.make(model::VehicleParams{}, model::State{}, sim::TickClock{});
  for (sim::Tick k = 0; k < 5; ++k) d->step(k, model::Vector4::Zero());
  try {
    d->step(5, model::Vector4::Zero());
    ADD_FAILURE() << "a failed doStep went unnoticed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("tick 5 (t = 0.05 s)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("it broke"), std::string::npos) << e.what();
  }
  auto nan_fmu = std::make_shared<MemoryFmu>(point_mass_description(), j);
  nan_fmu->nan_x = NAN;
  try {
    FmuPlant(nan_fmu, in_memory()).make(model::VehicleParams{}, model::State{}, sim::TickClock{});
    ADD_FAILURE() << "a NaN output went unnoticed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("output 'p_W[1]' is nan at tick 0"), std::string::npos) << e.what();
  }
}

// The point mass in C (tests/fmi/point_mass), loaded from its .fmu, as the plant under constant
// commands: z(t) = z0 + v0 t + a t^2 / 2 with a = k sum(w^2) / m - g, against the closed form.
TEST(FmuPlantAsPlant, LoadedPointMassFollowsItsClosedForm) {
  for (const char* file : {"point_mass.fmu", "point_mass3.fmu"}) {
    FmuMapping m;
    const double mass = 1.5, k = 2e-6, g = 9.81, z0 = 3.0, v0 = 0.5;
    m.parameters = {{"mass_kg", "1.5"}, {"k_thrust", "2e-6"}, {"z0", "3"}, {"vz0", "0.5"}};
    const FmuPlant plant(Fmu::load(std::string(QUADCOSIM_TEST_FMU_DIR) + "/" + file), m);
    EXPECT_FALSE(plant.refs().q_WB.empty());  // the point mass reports a (constant) attitude
    EXPECT_TRUE(plant.refs().w_B.empty());
    const sim::TickClock clock{10'000'000};
    auto d = plant.make(model::VehicleParams{}, model::State{}, clock);
    const double w = 1500.0;
    const double a = k * 4.0 * w * w / mass - g;
    model::Outputs y;
    model::State x;
    for (sim::Tick k_ = 0; k_ < 200; ++k_) {
      d->outputs(k_, y, x);
      const double t = clock.seconds(k_);
      ASSERT_NEAR(y.p_W.z(), z0 + v0 * t + 0.5 * a * t * t, 1e-9) << file << " tick " << k_;
      ASSERT_NEAR(y.v_W.z(), v0 + a * t, 1e-9) << file << " tick " << k_;
      d->step(k_, model::Vector4::Constant(w));
    }
    EXPECT_EQ(y.q_WB.w(), 1.0);
    EXPECT_EQ(y.specific_force_B, Eigen::Vector3d(0.0, 0.0, model::VehicleParams{}.gravity_m_s2)) << "the default";
  }
}

TEST(FmuPlantAsPlant, LoadedPointMassErrorNamesTheTickAndWhatItLogged) {
  FmuMapping m;
  m.parameters = {{"fail_at_step", "7"}};
  const FmuPlant plant(Fmu::load(std::string(QUADCOSIM_TEST_FMU_DIR) + "/point_mass.fmu"), m);
  auto d = plant.make(model::VehicleParams{}, model::State{}, sim::TickClock{});
  try {
    for (sim::Tick k = 0; k < 20; ++k) d->step(k, model::Vector4::Zero());
    ADD_FAILURE() << "the failing step went unnoticed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("FMU point_mass.fmu"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at tick 6 (t = 0.06 s)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fail_at_step = 7"), std::string::npos) << e.what();
  }
}

/// A proportional altitude controller FMU: omega_cmd[i] = base + gain (ref.p_W[3] - p_W[3]) (NaN
/// when gain is negative), its error as the output "error.z".
ModelDescription altitude_controller_description(int rotors = 4) {
  ModelDescription md;
  md.fmi_version = "2.0";
  md.model_name = "Altitude";
  md.model_identifier = "altitude";
  ValueReference vr = 1;
  for (auto n : names::kPosition) md.variables.push_back(var(std::string(n), vr++, Causality::kInput, "m"));
  for (auto n : names::kRefPosition) md.variables.push_back(var(std::string(n), vr++, Causality::kInput, "m"));
  for (auto n : names::omega_cmd(rotors))
    md.variables.push_back(var(std::string(n), vr++, Causality::kOutput, "rad/s"));
  md.variables.push_back(var("error.z", vr++, Causality::kOutput, "m"));
  Variable gain = var("controller.gain", vr++, Causality::kParameter, "rad/s/m", Variability::kTunable, "100");
  gain.min = -10.0;
  gain.max = 1000.0;
  md.variables.push_back(gain);
  md.variables.push_back(var("base", vr++, Causality::kParameter, "rad/s", Variability::kFixed, "400"));
  return md;
}

class AltitudeInstance final : public Instance {
 public:
  AltitudeInstance(std::shared_ptr<Fmu> fmu, Journal& j) : Instance(std::move(fmu)), j_(j) { ++j_.instances; }
  void enter_initialization(double, std::optional<double>) override { j_.calls.push_back("enter"); }
  void exit_initialization() override { j_.calls.push_back("exit"); }
  void do_step(double t, double h) override {
    j_.calls.push_back(fmt("step {:g} {:g}", t, h));
    if (v("controller.gain") > 500.0) throw FmuError("fmi2DoStep: Error: gain too high");
    const double e = v("ref.p_W[3]") - v("p_W[3]");
    const double w = v("controller.gain") < 0.0 ? NAN : v("base") + v("controller.gain") * e;
    out_ = {w, w, w, w, e};
  }
  void terminate() override {}
  void reset() override { values_.clear(); }
  void get_real(std::span<const ValueReference> vr, std::span<double> out) override {
    for (std::size_t i = 0; i < vr.size(); ++i) {
      const std::string& n = name(vr[i]);
      out[i] = n == "error.z" ? out_[4] : n.rfind("omega_cmd", 0) == 0 ? out_[0] : v(n);
    }
  }
  void set_real(std::span<const ValueReference> vr, std::span<const double> x) override {
    for (std::size_t i = 0; i < vr.size(); ++i) {
      if (name(vr[i]) == "controller.gain" && x[i] == 13.0) throw FmuError("fmi2SetReal: Error: 13 is unlucky");
      values_[name(vr[i])] = j_.set[name(vr[i])] = x[i];
    }
  }
  void get_integer(std::span<const ValueReference>, std::span<std::int32_t>) override {}
  void set_integer(std::span<const ValueReference>, std::span<const std::int32_t>) override {}
  void get_boolean(std::span<const ValueReference>, std::span<bool>) override {}
  void set_boolean(std::span<const ValueReference>, std::span<const bool>) override {}
  void set_string(std::span<const ValueReference>, std::span<const std::string>) override {}

 private:
  static std::string fmt(const char* f, double a, double b) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "step %g %g", a, b);
    (void)f;
    return buf;
  }
  const std::string& name(ValueReference vr) const {
    for (const Variable& x : description().variables) {
      if (x.vr == vr) return x.name;
    }
    throw FmuError("unknown value reference");
  }
  double v(const std::string& n) const {
    if (auto it = values_.find(n); it != values_.end()) return it->second;
    const Variable* x = description().find(n);
    return x && x->start ? std::stod(*x->start) : 0.0;
  }
  Journal& j_;
  std::map<std::string, double> values_;
  std::array<double, 5> out_{};
};

class ControllerFmu final : public Fmu {
 public:
  explicit ControllerFmu(Journal& j, ModelDescription md = altitude_controller_description()) : j_(j) {
    description_ = std::move(md);
    path_ = "/nowhere/altitude.fmu";
  }
  std::unique_ptr<Instance> instantiate(const std::string& name, LogSink) override {
    j_.calls.push_back("instantiate " + name);
    return std::make_unique<AltitudeInstance>(shared_from_this(), j_);
  }

 private:
  Journal& j_;
};

TEST(FmuControllerAsController, StepsSetsInputsAndReadsTheCommand) {
  Journal j;
  auto fmu = std::make_shared<ControllerFmu>(j);
  FmuController c(fmu, in_memory(), model::VehicleParams{});
  EXPECT_EQ(c.type(), "fmu");
  ASSERT_EQ(c.output_names().size(), 1u);
  EXPECT_EQ(c.output_names()[0], "error.z");
  ASSERT_EQ(c.parameters().size(), 2u);
  EXPECT_EQ(c.parameters()[0].name, "gain");  // controller. prefix dropped
  EXPECT_EQ(c.parameters()[0].unit, "rad/s/m");
  EXPECT_EQ(c.parameters()[0].min, -10.0);
  EXPECT_EQ(c.parameters()[0].max, 1000.0);
  EXPECT_EQ(std::get<double>(*c.get_parameter("base")), 400.0);

  control::Observation o;
  o.p_W = {0.0, 0.0, 1.0};
  control::Reference r;
  r.p_W = {0.0, 0.0, 3.0};
  r.roll_rad = 0.1;
  control::ControllerOutput out;
  out.outputs.resize(1);
  c.step(o, r, 0.02, out);
  c.step(o, r, 0.02, out);
  EXPECT_EQ(out.omega_rad_s, Eigen::Vector4d::Constant(400.0 + 100.0 * 2.0));
  EXPECT_EQ(out.outputs[0], 2.0);
  EXPECT_EQ(out.roll_des_rad, 0.1);
  const model::Wrench u = model::Quadrotor(model::VehicleParams{}).wrench(out.omega_rad_s);
  EXPECT_EQ(out.U[0], u.thrust_N);
  EXPECT_TRUE(std::isnan(out.attitude_error));
  // Instantiated once, initialised at the first step, stepped on n dt.
  const std::vector<std::string> expected = {"instantiate altitude_0", "enter", "exit", "step 0 0.02",
                                             "step 0.02 0.02"};
  EXPECT_EQ(std::vector<std::string>(j.calls.end() - 5, j.calls.end()),
            std::vector<std::string>(expected.begin(), expected.end()));
}

TEST(FmuControllerAsController, AHexarotorFmuCommandsSixRotorsAndRefusesAQuadrotorNamingBothCounts) {
  Journal j;
  auto fmu = std::make_shared<ControllerFmu>(j, altitude_controller_description(6));
  try {
    FmuController c(fmu, in_memory(), model::VehicleParams{});
    ADD_FAILURE() << "a six-rotor controller FMU was taken for a quadrotor";
  } catch (const FmuError& e) {
    EXPECT_EQ(std::string(e.what()),
              "altitude.fmu: the FMU controller outputs 6 rotor speed commands (omega_cmd[1..6]); the vehicle has 4 "
              "rotors (layout plus)");
  }
  model::VehicleParams hex;
  hex.set_layout(model::RotorLayout::kHexPlus);
  FmuController c(fmu, in_memory(), hex);
  ASSERT_EQ(c.output_names().size(), 1u);  // omega_cmd[5..6] are commands, not figures
  EXPECT_EQ(c.output_names()[0], "error.z");
  control::Observation o;
  o.p_W = {0.0, 0.0, 1.0};
  control::Reference r;
  r.p_W = {0.0, 0.0, 3.0};
  control::ControllerOutput out;
  out.outputs.resize(1);
  c.step(o, r, 0.02, out);
  EXPECT_EQ(out.omega_rad_s, model::RotorVector::Constant(6, 400.0 + 100.0 * 2.0));
  EXPECT_EQ(out.outputs[0], 2.0);
}

TEST(FmuControllerAsController, ParametersAllOrNothingFixedOnesUntilTheFirstStepCloneAfresh) {
  Journal j;
  auto fmu = std::make_shared<ControllerFmu>(j);
  FmuController c(fmu, in_memory(), model::VehicleParams{});
  const std::vector<control::Setting> both = {{"gain", 50.0}, {"base", 300.0}};
  EXPECT_EQ(c.set_parameters(both), "");
  const std::vector<control::Setting> out_of_range = {{"gain", 60.0}, {"base", 1.0}, {"gain", 2000.0}};
  EXPECT_NE(c.set_parameters(out_of_range).find("gain"), std::string::npos);
  EXPECT_EQ(std::get<double>(*c.get_parameter("gain")), 50.0);  // nothing changed
  const std::vector<control::Setting> unknown = {{"gian", 1.0}};
  EXPECT_NE(c.set_parameters(unknown).find("gian"), std::string::npos);

  control::ControllerOutput out;
  out.outputs.resize(1);
  c.step({}, {}, 0.02, out);
  EXPECT_EQ(j.set.at("base"), 300.0);  // applied at initialisation
  EXPECT_EQ(j.set.at("controller.gain"), 50.0);
  const std::vector<control::Setting> fixed = {{"base", 350.0}};
  EXPECT_NE(c.set_parameters(fixed).find("base: the FMU declares it fixed"), std::string::npos);
  // Tunable, through the FMU; a refusal by the FMU undoes the others and names the parameter.
  const std::vector<control::Setting> tunable = {{"gain", 70.0}};
  EXPECT_EQ(c.set_parameters(tunable), "");
  EXPECT_EQ(j.set.at("controller.gain"), 70.0);
  const std::vector<control::Setting> unlucky = {{"gain", 13.0}};
  EXPECT_NE(c.set_parameters(unlucky).find("gain: refused by FMU altitude.fmu"), std::string::npos);
  EXPECT_EQ(std::get<double>(*c.get_parameter("gain")), 70.0);

  const int before = j.instances;
  std::unique_ptr<control::Controller> copy = c.clone();
  EXPECT_EQ(j.instances, before + 1);
  EXPECT_EQ(std::get<double>(*copy->get_parameter("gain")), 70.0);
  EXPECT_EQ(std::get<double>(*copy->get_parameter("base")), 300.0);
}

TEST(FmuControllerAsController, AFailedStepOrANanCommandThrowsNamingTheFmuAndTheStep) {
  Journal j;
  auto fmu = std::make_shared<ControllerFmu>(j);
  FmuController c(fmu, in_memory(), model::VehicleParams{});
  control::ControllerOutput out;
  out.outputs.resize(1);
  c.step({}, {}, 0.02, out);
  const std::vector<control::Setting> high = {{"gain", 600.0}};
  ASSERT_EQ(c.set_parameters(high), "");
  try {
    c.step({}, {}, 0.02, out);
    ADD_FAILURE() << "a failed doStep went unnoticed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("FMU altitude.fmu"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("control step 1 (t = 0.02 s)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gain too high"), std::string::npos) << e.what();
  }
  FmuController nan(fmu, in_memory(), model::VehicleParams{});
  const std::vector<control::Setting> negative = {{"gain", -1.0}};
  ASSERT_EQ(nan.set_parameters(negative), "");
  out.omega_rad_s.setConstant(7.0);
  try {
    nan.step({}, {}, 0.02, out);
    ADD_FAILURE() << "a NaN command went unnoticed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("output 'omega_cmd[1]' is nan"), std::string::npos) << e.what();
  }
  EXPECT_EQ(out.omega_rad_s, Eigen::Vector4d::Constant(7.0));  // nothing written
}

TEST(FmuControllerAsController, MappingRefusals) {
  Journal j;
  auto fmu = std::make_shared<ControllerFmu>(j);
  auto refused = [&](FmuMapping m, const std::string& key, const std::string& words) {
    try {
      FmuController c(fmu, in_memory(m), model::VehicleParams{});
      ADD_FAILURE() << "not refused: " << key;
    } catch (const MappingError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  FmuMapping m;
  m.outputs["omega_cmd"] = {"error.z", "error.z", "error.z", "nope"};
  refused(m, "outputs.omega_cmd", "unit 'm', expected 'rad/s'");
  FmuMapping in;
  in.inputs["ref.yaw"] = {"yaw"};
  refused(in, "inputs.ref.yaw", "no variable 'yaw'");
  FmuMapping p;
  p.parameters = {{"controller.gain", "5000"}};
  refused(p, "parameters.controller.gain", "[-10, 1000]");
}

/// The altitude controller with inputs named like the plant FMU's extra-sensor outputs: the
/// magnetometer's field, the barometer's altitude (not its pressure) and every GNSS column.
ModelDescription sensing_controller_description() {
  ModelDescription md = altitude_controller_description();
  ValueReference vr = 100;
  auto input = [&](const std::string& name, const std::string& unit) {
    md.variables.push_back(var(name, vr++, Causality::kInput, unit));
  };
  for (int i = 1; i <= 3; ++i) input("magnetometer.field[" + std::to_string(i) + "]", "T");
  input("barometer.altitude", "m");
  input("gnss.fix", "1");
  input("gnss.latitude_deg", "deg");
  input("gnss.longitude_deg", "deg");
  input("gnss.altitude_m", "m");
  for (int i = 1; i <= 3; ++i) input("gnss.v[" + std::to_string(i) + "]", "m/s");
  return md;
}

TEST(FmuControllerAsController, ExtraSensorInputsAreTheObservationsReadings) {
  Journal j;
  auto fmu = std::make_shared<ControllerFmu>(j, sensing_controller_description());
  FmuController c(fmu, in_memory(), model::VehicleParams{});
  control::Observation o;
  o.sensors.carry<sensors::MagnetometerKind>();
  o.sensors.carry<sensors::BarometerKind>();
  o.sensors.carry<sensors::GnssKind>();
  control::ControllerOutput out;
  out.outputs.resize(1);
  // Before the first sample: NaN, the fix flag 0.
  c.step(o, {}, 0.02, out);
  for (const char* n :
       {"magnetometer.field[1]", "magnetometer.field[3]", "barometer.altitude", "gnss.latitude_deg", "gnss.v[2]"}) {
    EXPECT_TRUE(std::isnan(j.set.at(n))) << n;
  }
  EXPECT_EQ(j.set.at("gnss.fix"), 0.0);

  sensors::MagnetometerSample mag;
  mag.field_B_T = {2.1e-5, -3.5e-6, -4.3e-5};
  o.sensors.set<sensors::MagnetometerKind>(mag, 20'000'000);
  sensors::BarometerSample baro;
  baro.pressure_Pa = 95000.0;
  baro.altitude_m = 540.25;
  o.sensors.set<sensors::BarometerKind>(baro, 20'000'000);
  sensors::GnssSample gnss;
  gnss.fix = true;
  gnss.position.latitude_rad = 0.8272;
  gnss.position.longitude_rad = 0.1491;
  gnss.position.height_m = 536.5;
  gnss.velocity_W = {0.25, -0.5, 0.125};
  o.sensors.set<sensors::GnssKind>(gnss, 0);
  c.step(o, {}, 0.02, out);
  EXPECT_EQ(j.set.at("magnetometer.field[1]"), 2.1e-5);
  EXPECT_EQ(j.set.at("magnetometer.field[2]"), -3.5e-6);
  EXPECT_EQ(j.set.at("magnetometer.field[3]"), -4.3e-5);
  EXPECT_EQ(j.set.at("barometer.altitude"), 540.25);
  EXPECT_EQ(j.set.count("barometer.pressure"), 0u);  // the FMU has no such input
  EXPECT_EQ(j.set.at("gnss.fix"), 1.0);
  EXPECT_NEAR(j.set.at("gnss.latitude_deg"), 47.395068813221705, 1e-12);  // 0.8272 rad
  EXPECT_NEAR(j.set.at("gnss.longitude_deg"), 8.542800725400575, 1e-12);  // 0.1491 rad
  EXPECT_EQ(j.set.at("gnss.altitude_m"), 536.5);
  EXPECT_EQ(j.set.at("gnss.v[1]"), 0.25);
  EXPECT_EQ(j.set.at("gnss.v[2]"), -0.5);
  EXPECT_EQ(j.set.at("gnss.v[3]"), 0.125);

  // What the vehicle must carry: every sensor the FMU has an input of.
  sensors::SensorSet set;
  set.magnetometer.emplace();
  set.barometer.emplace();
  EXPECT_NE(c.check_sensors(set).find("altitude.fmu has the input 'gnss.fix', but the vehicle carries no gnss: turn "
                                      "it on with the scenario key sensors.gnss"),
            std::string::npos)
      << c.check_sensors(set);
  set.gnss.emplace();
  EXPECT_EQ(c.check_sensors(set), "");
  // The altitude controller without them needs none.
  FmuController plain(std::make_shared<ControllerFmu>(j), in_memory(), model::VehicleParams{});
  EXPECT_EQ(plain.check_sensors(sensors::SensorSet{}), "");
}

TEST(FmuControllerAsController, ExtraSensorInputsMayBeRenamedAndAreChecked) {
  Journal j;
  ModelDescription md = altitude_controller_description();
  md.variables.push_back(var("baro_alt", 200, Causality::kInput, "m"));
  md.variables.push_back(var("baro_p", 201, Causality::kInput, "m"));
  auto fmu = std::make_shared<ControllerFmu>(j, md);
  FmuMapping m;
  m.inputs["barometer.altitude"] = {"baro_alt"};
  FmuController c(fmu, in_memory(m), model::VehicleParams{});
  control::Observation o;
  o.sensors.carry<sensors::BarometerKind>();
  sensors::BarometerSample baro;
  baro.altitude_m = 512.0;
  o.sensors.set<sensors::BarometerKind>(baro, 0);
  control::ControllerOutput out;
  out.outputs.resize(1);
  c.step(o, {}, 0.02, out);
  EXPECT_EQ(j.set.at("baro_alt"), 512.0);
  EXPECT_NE(c.check_sensors({}).find("'baro_alt'"), std::string::npos);
  FmuMapping unit;
  unit.inputs["barometer.pressure"] = {"baro_p"};
  try {
    FmuController bad(fmu, in_memory(unit), model::VehicleParams{});
    ADD_FAILURE() << "a pressure input in metres was taken";
  } catch (const MappingError& e) {
    EXPECT_EQ(e.key(), "inputs.barometer.pressure");
    EXPECT_NE(std::string(e.what()).find("unit 'm', expected 'Pa'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace quadcosim::fmi
