// The master (fmi/fmu.hpp) on the point-mass test FMU (tests/fmi/point_mass, FMI 2.0 and 3.0): its
// trajectory against the closed form, parameters, logging, and every refusal naming its culprit.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "fmi/fmu.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "fmi/unzip.hpp"

namespace quadcosim::fmi {
namespace {

namespace fs = std::filesystem;

const std::string kFmuDir = QUADCOSIM_TEST_FMU_DIR;

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
}

/// A copy of the unpacked FMU `name` in a fresh temporary directory, for tests that break it.
struct FmuCopy {
  TempDir dir{"quadcosim-fmu-test-"};
  fs::path root;
  explicit FmuCopy(const std::string& name, const std::string& as = "fmu") : root(fs::path(dir.path()) / as) {
    fs::copy(fs::path(kFmuDir) / name, root, fs::copy_options::recursive);
  }
  void patch_xml(const std::string& from, const std::string& to) const {
    std::string xml = read(root / "modelDescription.xml");
    const auto at = xml.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    xml.replace(at, from.size(), to);
    write(root / "modelDescription.xml", xml);
  }
};

/// The message of the FmuError `f` throws; "" (and a test failure) when it throws none.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const FmuError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no FmuError thrown";
  return "";
}

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text) << "\nwanted: " << (part)

struct LogLine {
  std::string category, status, message;
};

/// A log sink that keeps what it gets.
struct Log {
  std::vector<LogLine> lines;
  LogSink sink() {
    return [this](const std::string& c, const std::string& s, const std::string& m) { lines.push_back({c, s, m}); };
  }
  bool has(const std::string& status, const std::string& part) const {
    return std::any_of(lines.begin(), lines.end(), [&](const LogLine& l) {
      return l.status == status && l.message.find(part) != std::string::npos;
    });
  }
};

ValueReference vr(const Instance& i, std::string_view name) {
  const Variable* v = i.description().find(name);
  if (v == nullptr) throw FmuError("test: no variable " + std::string(name));
  return v->vr;
}

double get(Instance& i, std::string_view name) {
  const ValueReference r = vr(i, name);
  double value = 0;
  i.get_real({&r, 1}, {&value, 1});
  return value;
}

void set(Instance& i, std::string_view name, double value) {
  const ValueReference r = vr(i, name);
  i.set_real({&r, 1}, {&value, 1});
}

void set_int(Instance& i, std::string_view name, std::int32_t value) {
  const ValueReference r = vr(i, name);
  i.set_integer({&r, 1}, {&value, 1});
}

std::int32_t get_int(Instance& i, std::string_view name) {
  const ValueReference r = vr(i, name);
  std::int32_t value = 0;
  i.get_integer({&r, 1}, {&value, 1});
  return value;
}

void set_omega(Instance& i, const std::array<double, 4>& omega) {
  std::array<ValueReference, 4> refs{};
  for (std::size_t k = 0; k < 4; ++k) refs[k] = vr(i, names::kOmegaCmd[k]);
  i.set_real(refs, omega);
}

/// Each test runs on the FMI 2.0 and the FMI 3.0 build of the point mass: `name` is the unpacked
/// directory in build/tests/fmi and `name`.fmu the archive.
class PointMass : public testing::TestWithParam<std::string> {
 protected:
  std::string fmu_file() const { return kFmuDir + "/" + GetParam() + ".fmu"; }
  std::string unpacked() const { return kFmuDir + "/" + GetParam(); }
  std::string do_step_call() const { return GetParam() == "point_mass" ? "fmi2DoStep" : "fmi3DoStep"; }
  std::string set_real_call() const { return GetParam() == "point_mass" ? "fmi2SetReal" : "fmi3SetFloat64"; }
};

INSTANTIATE_TEST_SUITE_P(Fmi, PointMass, testing::Values("point_mass", "point_mass3"));

TEST_P(PointMass, ReadsItsDescription) {
  const auto fmu = Fmu::load(fmu_file());
  const ModelDescription& md = fmu->description();
  EXPECT_EQ(fmu->path(), fmu_file());
  EXPECT_EQ(md.model_name, "PointMass");
  EXPECT_EQ(md.version, GetParam() == "point_mass" ? FmiVersion::k2 : FmiVersion::k3);
  EXPECT_EQ(md.model_identifier, GetParam());
  EXPECT_TRUE(md.can_handle_variable_step);
  EXPECT_EQ(md.step_size, 0.01);
  for (std::size_t k = 0; k < 4; ++k) {
    const Variable* omega = md.find(names::kOmegaCmd[k]);
    ASSERT_NE(omega, nullptr) << names::kOmegaCmd[k];
    EXPECT_EQ(omega->vr, k);
    EXPECT_EQ(omega->causality, Causality::kInput);
    EXPECT_EQ(omega->type, VariableType::kReal);
    EXPECT_EQ(omega->unit, "rad/s");
  }
  const Variable* mass = md.find("mass_kg");
  ASSERT_NE(mass, nullptr);
  EXPECT_EQ(mass->causality, Causality::kParameter);
  EXPECT_EQ(mass->variability, Variability::kFixed);
  EXPECT_EQ(mass->start, "1");
  EXPECT_EQ(mass->unit, "kg");
  // Every plant output it has is listed in ModelStructure.
  std::vector<std::string_view> outputs;
  for (std::size_t i : md.outputs) outputs.push_back(md.variables[i].name);
  for (auto list :
       {std::span<const std::string_view>(names::kPosition), std::span<const std::string_view>(names::kVelocity),
        std::span<const std::string_view>(names::kAttitude)}) {
    for (std::string_view name : list) {
      const Variable* v = md.find(name);
      ASSERT_NE(v, nullptr) << name;
      EXPECT_EQ(v->causality, Causality::kOutput) << name;
      EXPECT_NE(std::find(outputs.begin(), outputs.end(), name), outputs.end()) << name;
    }
  }
  EXPECT_EQ(md.find("p_W[3]")->vr, 22u);
  EXPECT_EQ(md.find("p_W[3]")->unit, "m");
  EXPECT_EQ(md.find("v_W[3]")->unit, "m/s");
  EXPECT_EQ(md.find("steps")->type, VariableType::kInteger);
  // A name the FMU does not have.
  EXPECT_EQ(md.find("p_W[4]"), nullptr);
  EXPECT_EQ(md.find("omega_cmd"), nullptr);
}

// The mass under piecewise-constant rotor commands, stepped with two step sizes, against
// z(t) = z0 + v0 t + a t^2 / 2 on each piece (a = k sum(w^2) / m - g).
TEST_P(PointMass, FollowsTheClosedForm) {
  const auto fmu = Fmu::load(fmu_file());
  Log log;
  auto instance = fmu->instantiate("plant", log.sink());
  const double m = 0.8, k = 2e-6, g = 9.81, z0 = 1.5, v0 = 0.3;
  set(*instance, "mass_kg", m);
  set(*instance, "k_thrust", k);
  set(*instance, "g", g);
  set(*instance, "z0", z0);
  set(*instance, "vz0", v0);
  instance->enter_initialization(0.0, 2.0);
  instance->exit_initialization();
  EXPECT_EQ(get(*instance, "p_W[3]"), z0);
  EXPECT_EQ(get(*instance, "v_W[3]"), v0);
  EXPECT_EQ(get(*instance, "mass_kg"), m);  // the parameter set before initialisation holds

  struct Piece {
    std::array<double, 4> omega;
    double h;
    int steps;
  };
  const Piece pieces[] = {{{1000, 1100, 1200, 1300}, 0.01, 100}, {{900, 900, 900, 900}, 0.025, 40}};
  double t = 0, z_start = z0, v_start = v0, t_start = 0, worst = 0;
  for (const Piece& piece : pieces) {
    double sum = 0;
    for (double w : piece.omega) sum += w * w;
    const double a = k * sum / m - g;
    set_omega(*instance, piece.omega);
    for (int n = 1; n <= piece.steps; ++n) {
      instance->do_step(t, piece.h);
      t = t_start + n * piece.h;
      const double tau = t - t_start;
      const double z_exact = z_start + v_start * tau + a * tau * tau / 2;
      const double v_exact = v_start + a * tau;
      const double z = get(*instance, "p_W[3]"), v = get(*instance, "v_W[3]");
      ASSERT_NEAR(z, z_exact, 1e-12 * std::max(1.0, std::abs(z_exact))) << "t = " << t;
      ASSERT_NEAR(v, v_exact, 1e-12 * std::max(1.0, std::abs(v_exact))) << "t = " << t;
      worst = std::max({worst, std::abs(z - z_exact) / std::max(1.0, std::abs(z_exact)),
                        std::abs(v - v_exact) / std::max(1.0, std::abs(v_exact))});
    }
    z_start = z_start + v_start * (t - t_start) + a * (t - t_start) * (t - t_start) / 2;
    v_start = v_start + a * (t - t_start);
    t_start = t;
  }
  EXPECT_EQ(get_int(*instance, "steps"), 140);
  EXPECT_EQ(get(*instance, "p_W[1]"), 0.0);
  EXPECT_EQ(get(*instance, "q_WB[1]"), 1.0);
  std::printf("point mass (%s): 140 steps to t = %g s, z = %.6f m, worst relative error %.3g\n", GetParam().c_str(), t,
              get(*instance, "p_W[3]"), worst);
  EXPECT_TRUE(log.lines.empty()) << log.lines.front().message;
}

TEST_P(PointMass, DefaultsAreTheDescriptionsStartValues) {
  // No parameter set: m = 1, g = 9.81, no thrust: free fall from rest at z = 0.
  auto instance = Fmu::load(unpacked())->instantiate("falling");
  instance->enter_initialization(0.0);
  instance->exit_initialization();
  for (int n = 0; n < 10; ++n) instance->do_step(n * 0.1, 0.1);
  EXPECT_NEAR(get(*instance, "p_W[3]"), -9.81 / 2, 1e-12);
  EXPECT_NEAR(get(*instance, "v_W[3]"), -9.81, 1e-12);
}

TEST_P(PointMass, InstancesAreIndependent) {
  const auto fmu = Fmu::load(fmu_file());
  auto a = fmu->instantiate("a");
  auto b = fmu->instantiate("b");
  set(*a, "g", 1.0);
  set(*b, "g", 2.0);
  for (Instance* i : {a.get(), b.get()}) {
    i->enter_initialization(0.0);
    i->exit_initialization();
    i->do_step(0.0, 1.0);
  }
  EXPECT_EQ(get(*a, "p_W[3]"), -0.5);
  EXPECT_EQ(get(*b, "p_W[3]"), -1.0);
}

TEST_P(PointMass, FindsItsResources) {
  EXPECT_EQ(get_int(*Fmu::load(fmu_file())->instantiate("r"), "resources_ok"), 1);
  // A directory whose name needs percent-encoding in FMI 2's file URI.
  FmuCopy copy(GetParam(), "with space, 100% & ü");
  EXPECT_EQ(get_int(*Fmu::load(copy.root.string())->instantiate("r"), "resources_ok"), 1);
}

TEST_P(PointMass, ForwardsItsLogAndTerminatesAtTheEnd) {
  Log log;
  {
    auto instance = Fmu::load(fmu_file())->instantiate("logged", log.sink());
    const ValueReference on = vr(*instance, "log_steps");
    const bool yes = true;
    instance->set_boolean({&on, 1}, {&yes, 1});
    bool back = false;
    instance->get_boolean({&on, 1}, {&back, 1});
    EXPECT_TRUE(back);
    const ValueReference label = vr(*instance, "label");
    const std::string text = "plant-7";
    instance->set_string({&label, 1}, {&text, 1});
    instance->enter_initialization(0.0);
    instance->exit_initialization();
    instance->do_step(0.0, 0.5);
    instance->do_step(0.5, 0.5);
    // Warning: logged, and the step is taken.
    set_omega(*instance, {2500, 0, 0, 0});
    instance->do_step(1.0, 0.5);
    EXPECT_EQ(get_int(*instance, "steps"), 3);
    EXPECT_TRUE(log.has("Warning", "omega_cmd[1] = 2500 exceeds 2000 rad/s"));
    EXPECT_FALSE(log.has("OK", "terminated"));
  }  // the destructor terminates an instance that is running, then frees it
  EXPECT_TRUE(log.has("OK", "plant-7 step 1 to t = 0.5: z = -1.22625"));
  EXPECT_TRUE(log.has("OK", "plant-7 step 2 to t = 1"));
  EXPECT_TRUE(log.has("OK", "plant-7 terminated after 3 steps"));
}

TEST_P(PointMass, AStepThatFailsNamesTheCallAndWhatTheFmuLogged) {
  Log log;
  auto instance = Fmu::load(fmu_file())->instantiate("failing", log.sink());
  set_int(*instance, "fail_at_step", 3);
  const ValueReference on = vr(*instance, "log_steps");
  const bool yes = true;
  instance->set_boolean({&on, 1}, {&yes, 1});
  instance->enter_initialization(0.0);
  instance->exit_initialization();
  instance->do_step(0.0, 0.01);
  instance->do_step(0.01, 0.01);
  const std::string message = error_of([&] { instance->do_step(0.02, 0.01); });
  EXPECT_CONTAINS(message,
                  do_step_call() + "(t = 0.02, h = 0.01) of FMU 'PointMass' instance 'failing' answered Error");
  // The FMU's message, formatted (FMI 2's logger takes a printf format: "100%%" is "100%").
  EXPECT_CONTAINS(message, "the FMU logged: [Error] step 3 fails as fail_at_step = 3 asks (100% on purpose)");
  EXPECT_TRUE(log.has("Error", "step 3 fails"));
  // After an Error the instance is not terminated at destruction (only reset or free are allowed).
  instance.reset();
  EXPECT_FALSE(log.has("OK", "terminated"));
}

TEST_P(PointMass, ANonFiniteInputFailsTheStep) {
  Log log;
  auto instance = Fmu::load(fmu_file())->instantiate("nan", log.sink());
  instance->enter_initialization(0.0);
  instance->exit_initialization();
  set_omega(*instance, {100, std::numeric_limits<double>::quiet_NaN(), 100, 100});
  EXPECT_CONTAINS(error_of([&] { instance->do_step(0.0, 0.01); }), "omega_cmd[2] = nan is not finite");
}

TEST_P(PointMass, AFailedSetNamesTheVariableAndValue) {
  Log log;
  auto instance = Fmu::load(fmu_file())->instantiate("late", log.sink());
  instance->enter_initialization(0.0);
  instance->exit_initialization();
  const std::string message = error_of([&] { set(*instance, "mass_kg", 2.0); });
  EXPECT_CONTAINS(message, set_real_call() + "(mass_kg = 2) of FMU 'PointMass' instance 'late' answered Error");
  EXPECT_CONTAINS(message, "value reference 10 is a fixed parameter: set it before ExitInitializationMode");
}

TEST_P(PointMass, AfterFatalEveryCallThrowsAndOnlyFreeIsCalled) {
  Log log;
  auto instance = Fmu::load(fmu_file())->instantiate("doomed", log.sink());
  set_int(*instance, "fatal_at_step", 2);
  const ValueReference on = vr(*instance, "log_steps");
  const bool yes = true;
  instance->set_boolean({&on, 1}, {&yes, 1});
  instance->enter_initialization(0.0);
  instance->exit_initialization();
  instance->do_step(0.0, 0.1);
  const std::string fatal = error_of([&] { instance->do_step(0.1, 0.1); });
  EXPECT_CONTAINS(fatal, "answered Fatal (the instance is unusable now)");
  EXPECT_CONTAINS(fatal, "step 2: fatal_at_step reached");
  const std::string after = error_of([&] { get(*instance, "p_W[3]"); });
  EXPECT_CONTAINS(after, "the instance is unusable since " + do_step_call() + "(t = 0.1, h = 0.1) answered Fatal");
  EXPECT_CONTAINS(error_of([&] { instance->reset(); }), "unusable");
  const std::size_t lines = log.lines.size();
  instance.reset();  // free only: no terminate, so the FMU logs nothing more
  EXPECT_EQ(log.lines.size(), lines);
}

TEST_P(PointMass, CallsOutOfOrderAreRefusedBeforeTheFmuSeesThem) {
  auto instance = Fmu::load(fmu_file())->instantiate("eager");
  EXPECT_CONTAINS(error_of([&] { instance->do_step(0.0, 0.01); }),
                  "instance 'eager': called when the instance is instantiated (before enter_initialization)");
  EXPECT_CONTAINS(error_of([&] { instance->exit_initialization(); }), "called when the instance is instantiated");
  instance->enter_initialization(0.0);
  EXPECT_CONTAINS(error_of([&] { instance->enter_initialization(0.0); }),
                  "called when the instance is initialization mode");
  instance->exit_initialization();
  instance->terminate();
  EXPECT_CONTAINS(error_of([&] { instance->do_step(0.0, 0.01); }), "called when the instance is terminated");
  // reset brings it back to the start, and it runs again with its start values.
  instance->reset();
  instance->enter_initialization(0.0);
  instance->exit_initialization();
  instance->do_step(0.0, 1.0);
  EXPECT_NEAR(get(*instance, "p_W[3]"), -9.81 / 2, 1e-12);
}

TEST_P(PointMass, RefusesUnknownValueReferencesAndMismatchedSpans) {
  auto instance = Fmu::load(fmu_file())->instantiate("strict");
  const ValueReference unknown = 99;
  double value = 0;
  EXPECT_CONTAINS(error_of([&] {
                    instance->get_real({&unknown, 1}, {&value, 1});
                  }),
                  "instance 'strict': value reference 99 is no Real variable of its modelDescription.xml");
  // steps is an Integer, not a Real.
  const ValueReference steps = vr(*instance, "steps");
  EXPECT_CONTAINS(error_of([&] {
                    instance->get_real({&steps, 1}, {&value, 1});
                  }),
                  "value reference 30 is no Real variable");
  const std::array<ValueReference, 2> two = {0, 1};
  EXPECT_CONTAINS(error_of([&] { instance->set_real(two, {&value, 1}); }), "2 value references but 1 values");
  EXPECT_THROW(vr(*instance, "no_such_variable"), FmuError);
}

TEST_P(PointMass, RefusesAGuidThatIsNotTheBinarys) {
  FmuCopy copy(GetParam());
  const std::string attribute = GetParam() == "point_mass" ? "guid=\"" : "instantiationToken=\"";
  copy.patch_xml(attribute + "{6f1d1b54", attribute + "{00000000");
  const auto fmu = Fmu::load(copy.root.string());
  Log log;
  const std::string message = error_of([&] { fmu->instantiate("impostor", log.sink()); });
  EXPECT_CONTAINS(message, "{00000000-3c2a-4b8e-9a51-point-mass-");
  EXPECT_CONTAINS(message, "returned no instance; the FMU logged: [Error]");
  EXPECT_CONTAINS(message, "is not this binary's {6f1d1b54-3c2a-4b8e-9a51-point-mass-");
}

TEST_P(PointMass, RefusesAMissingBinary) {
  FmuCopy copy(GetParam());
  const std::string platform = GetParam() == "point_mass" ? "linux64" : "x86_64-linux";
  fs::rename(copy.root / "binaries" / platform, copy.root / "binaries" / "win64");
  EXPECT_CONTAINS(error_of([&] { Fmu::load(copy.root.string()); }),
                  copy.root.string() + ": has no binary for this platform: binaries/" + platform + "/" + GetParam() +
                      ".so is missing (binaries present: win64)");
}

TEST_P(PointMass, RefusesAModelExchangeOnlyFmu) {
  FmuCopy copy(GetParam());
  copy.patch_xml("<CoSimulation", "<ModelExchange");
  EXPECT_CONTAINS(error_of([&] { Fmu::load(copy.root.string()); }),
                  copy.root.string() +
                      ": modelDescription.xml: model 'PointMass' has no CoSimulation element: "
                      "quadcosim masters co-simulation FMUs only (this one is for model exchange)");
}

TEST_P(PointMass, RefusesMalformedXml) {
  FmuCopy copy(GetParam());
  copy.patch_xml("</ModelVariables>", "</ModelVariable>");
  EXPECT_CONTAINS(error_of([&] { Fmu::load(copy.root.string()); }),
                  copy.root.string() + ": modelDescription.xml: not well-formed XML at line");
}

TEST_P(PointMass, HonoursInstantiationOnlyOncePerProcess) {
  FmuCopy copy(GetParam());
  copy.patch_xml("canBeInstantiatedOnlyOncePerProcess=\"false\"", "canBeInstantiatedOnlyOncePerProcess=\"true\"");
  const auto fmu = Fmu::load(copy.root.string());
  {
    auto first = fmu->instantiate("first");
    EXPECT_CONTAINS(error_of([&] { fmu->instantiate("second"); }),
                    "can be instantiated only once per process, and an instance exists: refused instance 'second'");
  }
  EXPECT_NE(fmu->instantiate("third"), nullptr);
}

TEST(Fmu, Fmi2ReadsAndWritesAnEnumerationAsAnInteger) {
  auto instance = Fmu::load(kFmuDir + "/point_mass.fmu")->instantiate("enum");
  EXPECT_EQ(instance->description().find("mode")->type, VariableType::kEnumeration);
  EXPECT_EQ(get_int(*instance, "mode"), 1);
  set_int(*instance, "mode", 2);
  EXPECT_EQ(get_int(*instance, "mode"), 2);
}

TEST(Fmu, RefusesABinaryThatLacksAFunction) {
  const std::string dir = kFmuDir + "/no_do_step";
  EXPECT_CONTAINS(error_of([&] { Fmu::load(dir); }),
                  dir + "/binaries/linux64/point_mass.so: the FMU's binary lacks the FMI function fmi2DoStep");
}

TEST(Fmu, RefusesWhatIsNoFmu) {
  EXPECT_CONTAINS(error_of([] { Fmu::load("/nonexistent/x.fmu"); }), "/nonexistent/x.fmu: no such FMU");
  TempDir dir;
  EXPECT_CONTAINS(error_of([&] { Fmu::load(dir.path()); }), dir.path() + ": has no modelDescription.xml");
  write(fs::path(dir.path()) / "plain.fmu", "this is not a zip archive");
  EXPECT_CONTAINS(error_of([&] { Fmu::load(dir.path() + "/plain.fmu"); }),
                  dir.path() + "/plain.fmu: cannot open as a zip archive");
}

TEST(Fmu, RemovesItsUnpackedCopyWithTheLastInstance) {
  TempDir tmp;
  const char* old = std::getenv("TMPDIR");
  const std::string saved = old != nullptr ? old : "";
  setenv("TMPDIR", tmp.path().c_str(), 1);
  auto fmu = Fmu::load(kFmuDir + "/point_mass.fmu");
  if (old != nullptr) {
    setenv("TMPDIR", saved.c_str(), 1);
  } else {
    unsetenv("TMPDIR");
  }
  const auto entries = [&] { return std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()); };
  ASSERT_EQ(entries(), 1);  // the unpacked FMU
  const fs::path unpacked = fs::directory_iterator(tmp.path())->path();
  EXPECT_EQ(fs::status(unpacked).permissions() & fs::perms::all, fs::perms::owner_all);  // private
  auto instance = fmu->instantiate("last");
  fmu.reset();
  EXPECT_EQ(entries(), 1);  // the instance keeps its FMU
  instance.reset();
  EXPECT_EQ(entries(), 0);
}

}  // namespace
}  // namespace quadcosim::fmi
