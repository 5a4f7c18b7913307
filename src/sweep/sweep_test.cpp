// The sweep library: statistics against hand-computed values, the --vary forms, keys set in the
// parsed scenario, draws (pure in (seed, run, key), grid factorial, Latin hypercube strata, the
// truncated normal against its closed-form mean), the scenario a run flies, and summaries that do not
// depend on threads or on the order runs come in.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <unistd.h>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include "control/parameters.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "hosts/scenario_resolvers_test_support.hpp"
#include "model/random.hpp"
#include "sweep/statistics.hpp"
#include "sweep/sweep.hpp"

namespace quadcosim::sweep {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A 2 s altitude step (fast runs) with a dotted controller key and a vehicle section.
fs::path scenario_file() {
  const fs::path dir = fs::temp_directory_path() / ("sweep_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / "step.yaml";
  std::ofstream(p) << R"(name: step
simulation: {plant_rate_hz: 100, controller_rate_hz: 50, duration_s: 2}
vehicle:
  mass_kg: 1.2
controller:
  mode: attitude
  altitude.kp: 4
  z_des: 0
schedule:
  - at_s: 0
    set: {z_des: 1.0}
analysis:
  steps:
    - channel: z
      at_s: 0
      criteria:
        overshoot_pct: [null, 25]
)";
  return p;
}

/// What make_plan says to `specs` on scenario_file(): its error, or "accepted".
std::string plan_error(const std::vector<std::string>& specs) {
  try {
    make_plan(scenario_file().string(), specs, 1, 4, Sampler::kRandom, hosts::test_resolvers());
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  return std::string("accepted");
}

// Yaw steps from hover at t = 0 (yaw_des from the controller section), 3 s; at most 0.5 s saturated.
fs::path yaw_scenario_file() {
  const fs::path dir = fs::temp_directory_path() / ("sweep_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / "yaw.yaml";
  std::ofstream(p) << R"(name: yaw
simulation: {plant_rate_hz: 100, controller_rate_hz: 50, duration_s: 3}
initial: {position_m: [0, 0, 10], hover: true}
controller: {mode: attitude, z_des: 10, yaw_des: 0.2}
analysis:
  limits: {max_saturated_s: 0.5}
)";
  return p;
}

TEST(Statistics, PercentilesAndMomentsAgainstHandComputedValues) {
  // 1, 2, 3, 4, 10: mean 4, sample variance (9+4+1+0+36)/4 = 12.5; p25 at rank 1 -> 2; p95 at rank
  // 3.8 -> 4 + 0.8 * 6 = 8.8; p5 at rank 0.2 -> 1.2.
  const FigureStats d = figure_stats({10.0, 2.0, std::nullopt, 1.0, 4.0, 3.0, std::nullopt});
  EXPECT_EQ(d.count, 5u);
  EXPECT_EQ(d.missing, 2u);
  EXPECT_DOUBLE_EQ(d.mean, 4.0);
  EXPECT_DOUBLE_EQ(d.std, std::sqrt(12.5));
  EXPECT_DOUBLE_EQ(d.min, 1.0);
  EXPECT_DOUBLE_EQ(d.max, 10.0);
  EXPECT_DOUBLE_EQ(d.p25, 2.0);
  EXPECT_DOUBLE_EQ(d.p50, 3.0);
  EXPECT_DOUBLE_EQ(d.p95, 8.8);
  EXPECT_DOUBLE_EQ(d.p5, 1.2);
  const FigureStats none = figure_stats({std::nullopt, std::nullopt});
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(none.missing, 2u);
  EXPECT_EQ(figure_stats({7.0}).std, 0.0);
}

TEST(ParseVary, EveryForm) {
  Vary v = parse_vary("mass=10%");
  EXPECT_EQ(v.name, "mass");
  EXPECT_EQ(v.distribution, Distribution::kPercent);
  EXPECT_DOUBLE_EQ(v.a, 0.1);
  v = parse_vary("controller.altitude.kp=uniform(2, 6)");
  EXPECT_EQ(v.distribution, Distribution::kUniform);
  EXPECT_EQ(v.a, 2.0);
  EXPECT_EQ(v.b, 6.0);
  v = parse_vary("x=normal(1,0.5)");
  EXPECT_EQ(v.distribution, Distribution::kNormal);
  v = parse_vary("x=grid(1,2.5,-3)");
  EXPECT_EQ(v.values, (std::vector<double>{1.0, 2.5, -3.0}));
  v = parse_vary("x=linspace(0,1,5)");
  EXPECT_EQ(v.values, (std::vector<double>{0.0, 0.25, 0.5, 0.75, 1.0}));
  v = parse_vary("x=linspace(0.1,0.7,3)");
  EXPECT_EQ(v.values.front(), 0.1);
  EXPECT_EQ(v.values.back(), 0.7);  // the ends exactly as typed
}

TEST(ParseVary, BadSpecsNameWhatIsWrong) {
  const auto error_of = [](const std::string& spec) {
    try {
      parse_vary(spec);
    } catch (const PlanError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(error_of("mass=10"), HasSubstr("expected KEY=P%"));
  EXPECT_THAT(error_of("mass=150%"), HasSubstr("percentage in [0, 100)"));
  EXPECT_THAT(error_of("k=uniform(3,1)"), HasSubstr("a < b"));
  EXPECT_THAT(error_of("k=uniform(1)"), HasSubstr("takes 2 numbers"));
  EXPECT_THAT(error_of("k=normal(1,0)"), HasSubstr("sigma > 0"));
  EXPECT_THAT(error_of("k=grid(1,x)"), HasSubstr("got 'x', expected a finite number"));
  EXPECT_THAT(error_of("k=linspace(0,1,2.5)"), HasSubstr("whole n"));
  EXPECT_THAT(error_of("k=beta(1,2)"), HasSubstr("unknown distribution 'beta'"));
}

TEST(SetKey, DottedNestedListsAndErrors) {
  YAML::Node root = YAML::Load("controller: {altitude.kp: 4, lqr: {roll: {r: 100}}}\ninitial: {position_m: [0, 0, 1]}");
  set_key(root, "controller.altitude.kp", 7.5);
  set_key(root, "controller.lqr.roll.r", 50);
  set_key(root, "initial.position_m[2]", 3.25);
  set_key(root, "initial.position_m.x", -1);
  set_key(root, "vehicle.motor.tau_up_s", 0.03);  // absent mappings are created
  EXPECT_EQ(root["controller"]["altitude.kp"].as<double>(), 7.5);
  EXPECT_FALSE(root["controller"]["altitude"]);  // the dotted key was set, not a second one added
  EXPECT_EQ(root["controller"]["lqr"]["roll"]["r"].as<double>(), 50.0);
  EXPECT_EQ(root["initial"]["position_m"][2].as<double>(), 3.25);
  EXPECT_EQ(root["initial"]["position_m"][0].as<double>(), -1.0);
  EXPECT_EQ(root["vehicle"]["motor"]["tau_up_s"].as<double>(), 0.03);
  // A value round-trips exactly through the node (17 significant digits).
  set_key(root, "vehicle.mass_kg", 0.1 + 0.2);
  EXPECT_EQ(root["vehicle"]["mass_kg"].as<double>(), 0.1 + 0.2);
  EXPECT_THROW(set_key(root, "initial.position_m[3]", 1), PlanError);
  EXPECT_THROW(set_key(root, "controller.altitude.kp.x", 1), PlanError);
  EXPECT_THROW(set_key(root, "environment.list[0]", 1), PlanError);  // no list to index
  // A default list is written whole when the file has none.
  YAML::Node empty = YAML::Load("{}");
  set_key(empty, "initial.position_m.z", 2, {{"initial.position_m", {0.5, 0.25, 0}}});
  EXPECT_EQ(empty["initial"]["position_m"][0].as<double>(), 0.5);
  EXPECT_EQ(empty["initial"]["position_m"][2].as<double>(), 2.0);
}

TEST(Plan, RefusesUnknownKeysDoubleVariationAndValuesTheLoaderRefuses) {
  EXPECT_THAT(plan_error({"wingspan=5%"}), HasSubstr("unknown parameter 'wingspan'"));
  EXPECT_THAT(plan_error({"controller.altitude.kpp=uniform(1,2)"}),
              HasSubstr("unknown controller parameter 'altitude.kpp'"));
  EXPECT_THAT(plan_error({"controller.mode=grid(1)"}), HasSubstr("is a choice"));
  EXPECT_THAT(plan_error({"inertia=5%", "Ixx=5%"}), HasSubstr("already varied"));
  EXPECT_THAT(plan_error({"vehicle.mass_kg=5%", "mass=1%"}), HasSubstr("already varied"));
  EXPECT_THAT(plan_error({"vehicle.mass_kg=grid(1, -2)"}),
              AllOf(HasSubstr("vehicle.mass_kg = -2"), HasSubstr("declared range [1e-06, 1e+12]")));
  EXPECT_THAT(plan_error({"initial.yaw_rad=grid(0, 12)"}),
              AllOf(HasSubstr("grid value 12"), HasSubstr("initial.yaw_rad")));
  EXPECT_THAT(plan_error({"simulation.wobble=uniform(1,2)"}), HasSubstr("wobble"));
  EXPECT_THAT(plan_error({"environment.gusts.w20_m_s=10%"}), HasSubstr("has no value in"));
  // Outside the controller table's declared range: refused before any run.
  EXPECT_THAT(plan_error({"controller.altitude.min_cos_tilt=uniform(0.01,0.5)"}),
              HasSubstr("declared range [0.05, 1]"));
  EXPECT_EQ(plan_error({"controller.altitude.kp=uniform(1,2)", "environment.gusts.w20_m_s=uniform(0,2)"}), "accepted");
}

TEST(Plan, AListEntryIsOneKeyWhetherWrittenAsIndexOrXyz) {
  // initial.position_m[2] and initial.position_m.z are one key (docs/sweeps.md): varied twice, refused.
  EXPECT_THAT(plan_error({"initial.position_m[2]=grid(1)", "initial.position_m.z=grid(2)"}),
              AllOf(HasSubstr("--vary initial.position_m.z=grid(2)"), HasSubstr("already varied"),
                    HasSubstr("initial.position_m[2]")));
  EXPECT_THAT(plan_error({"initial.position_m.x=grid(1)", "initial.position_m.0=grid(2)"}),
              HasSubstr("already varied"));
  EXPECT_EQ(plan_error({"initial.position_m[0]=grid(1)", "initial.position_m.z=grid(2)"}), "accepted");

  // A vehicle list entry by its index is the vehicle key .x/.y/.z: the table's range, the plant's key.
  const Plan p =
      make_plan(scenario_file().string(),
                {"vehicle.aero.linear_drag_N_s_m[0]=normal(0,1)", "aero.quadratic_drag_N_s2_m2[2]=grid(0.5)"}, 3, 50,
                Sampler::kRandom, hosts::test_resolvers());
  ASSERT_EQ(p.vary.size(), 2u);
  const Key& lin = p.vary[0].keys.at(0);
  EXPECT_EQ(lin.path, "vehicle.aero.linear_drag_N_s_m.x");
  EXPECT_EQ(lin.stream, "aero.linear_drag_N_s_m.x");
  EXPECT_TRUE(lin.is_vehicle);
  ASSERT_TRUE(lin.declared.has_value());
  EXPECT_EQ(lin.declared->min, 0.0);
  EXPECT_EQ(lin.declared->max, 1e6);
  EXPECT_EQ(p.vary[1].keys.at(0).path, "vehicle.aero.quadratic_drag_N_s2_m2.z");
  EXPECT_TRUE(p.vary[1].keys.at(0).is_vehicle);
  // normal(0, 1) truncated at the declared minimum 0: no negative drag drawn (half would be, untruncated).
  for (int i = 0; i < p.runs; ++i) EXPECT_GE(sample(p, i).values[0].second, 0.0) << i;
  const io::Scenario sc = scenario_for(p, sample(p, 7));
  EXPECT_EQ(sc.vehicle.aero.linear_drag_N_s_m.x(), sample(p, 7).values[0].second);
  EXPECT_EQ(sc.vehicle.aero.quadratic_drag_N_s2_m2.z(), 0.5);
  EXPECT_THAT(plan_error({"vehicle.aero.linear_drag_N_s_m[1]=grid(-1)"}),
              AllOf(HasSubstr("vehicle.aero.linear_drag_N_s_m.y = -1"), HasSubstr("declared range [0, 1e+06]")));
  EXPECT_THAT(plan_error({"linear_drag=uniform(0,1)", "vehicle.aero.linear_drag_N_s_m[1]=grid(0.3)"}),
              HasSubstr("already varied"));
}

TEST(PassesNeeded, CeilOfRateTimesRunsWithoutTheProductsRoundingError) {
  // 0.55 * 100 is 55.000000000000007 in binary: exactly 55 of 100 passing meets --min-pass-rate 0.55.
  ASSERT_GT(0.55 * 100, 55.0);
  EXPECT_EQ(passes_needed(0.55, 100), 55);
  EXPECT_EQ(passes_needed(0.07, 100), 7);    // 0.07 * 100 = 7.000000000000001
  EXPECT_EQ(passes_needed(0.29, 100), 29);   // 0.29 * 100 = 28.999999999999996
  EXPECT_EQ(passes_needed(0.57, 100), 57);   // 0.57 * 100 = 56.99999999999999
  EXPECT_EQ(passes_needed(0.551, 100), 56);  // a fraction of a run more: the next whole run
  EXPECT_EQ(passes_needed(1.0 / 3.0, 3), 1);
  EXPECT_EQ(passes_needed(0.5, 3), 2);
  EXPECT_EQ(passes_needed(1.0, 10'000'000), 10'000'000);
  EXPECT_EQ(passes_needed(0.1, 10'000'000), 1'000'000);
  EXPECT_EQ(passes_needed(0.0, 7), 0);
  EXPECT_EQ(passes_needed(1.0, 0), 0);
  // Every rate k/100 of 100 runs needs exactly k runs.
  for (int k = 0; k <= 100; ++k) EXPECT_EQ(passes_needed(k / 100.0, 100), k) << k;
  EXPECT_THROW(passes_needed(1.5, 10), std::invalid_argument);
  EXPECT_THROW(passes_needed(std::nan(""), 10), std::invalid_argument);
}

TEST(Sample, PureInSeedRunAndKeyAndCompatibleWithRelativeSpread) {
  const std::string f = scenario_file().string();
  const Plan a = make_plan(f, {"mass=10%", "controller.altitude.kp=uniform(2,6)"}, 42, 100, Sampler::kRandom,
                           hosts::test_resolvers());
  const Plan b = make_plan(f, {"controller.altitude.kp=uniform(2,6)", "mass=10%"}, 42, 100, Sampler::kRandom,
                           hosts::test_resolvers());
  for (int i : {0, 57, 99}) {
    const Sample s = sample(a, i);
    EXPECT_EQ(sample(a, i).values, s.values);  // same call, same numbers
    // A key's draw depends on (seed, run, key) only, not on the other keys or their order.
    std::map<std::string, double> other(b.vary.empty() ? std::map<std::string, double>{}
                                                       : std::map<std::string, double>{});
    for (const auto& [k, v] : sample(b, i).values) other[k] = v;
    for (const auto& [k, v] : s.values) EXPECT_EQ(other.at(k), v) << k;
    // KEY=P%: factor 1 + P (2u - 1) with u the run's "vary"/field stream, as sweeps always drew.
    model::Rng rng(model::stream_seed(model::stream_seed(42, "sweep", "run/" + std::to_string(i)), "vary", "mass_kg"));
    const double factor = 1.0 + 0.1 * (2.0 * rng.uniform() - 1.0);
    EXPECT_EQ(s.factors.at("mass_kg"), factor);
    EXPECT_EQ(s.values[0].first, "vehicle.mass_kg");
    EXPECT_EQ(s.values[0].second, 1.2 * factor);
    EXPECT_GE(s.values[1].second, 2.0);
    EXPECT_LE(s.values[1].second, 6.0);
  }
  EXPECT_NE(sample(a, 1).values, sample(a, 2).values);
}

TEST(Sample, GridIsFullFactorialWithTheFirstKeySlowest) {
  const Plan p = make_plan(scenario_file().string(),
                           {"controller.altitude.kp=grid(2,4)", "controller.altitude.kd=linspace(1,3,3)"}, 1, 2,
                           Sampler::kRandom, hosts::test_resolvers());
  ASSERT_EQ(p.runs, 2 * 3 * 2);  // two repeats per point
  std::multiset<std::pair<double, double>> points;
  for (int i = 0; i < p.runs; ++i) {
    const Sample s = sample(p, i);
    points.insert({s.values[0].second, s.values[1].second});
  }
  for (double kp : {2.0, 4.0}) {
    for (double kd : {1.0, 2.0, 3.0}) EXPECT_EQ(points.count({kp, kd}), 2u) << kp << " " << kd;
  }
  EXPECT_EQ(sample(p, 0).values[1].second, 1.0);
  EXPECT_EQ(sample(p, 2).values[1].second, 2.0);  // runs 0, 1 repeat point 0; run 2 is the next kd
  EXPECT_EQ(sample(p, 6).values[0].second, 4.0);
  EXPECT_NE(sample(p, 0).seed, sample(p, 1).seed);  // repeats differ in their noise seed
}

TEST(Sample, LatinHypercubePutsOneRunInEveryStratumOfEveryKey) {
  const int n = 50;
  const Plan p = make_plan(scenario_file().string(),
                           {"controller.altitude.kp=uniform(0,1)", "controller.altitude.kd=uniform(10,20)"}, 3, n,
                           Sampler::kLhs, hosts::test_resolvers());
  std::set<int> kp_strata, kd_strata;
  for (int i = 0; i < n; ++i) {
    const Sample s = sample(p, i);
    kp_strata.insert(static_cast<int>(std::floor(s.values[0].second * n)));
    kd_strata.insert(static_cast<int>(std::floor((s.values[1].second - 10.0) / 10.0 * n)));
  }
  EXPECT_EQ(kp_strata.size(), static_cast<std::size_t>(n));
  EXPECT_EQ(kd_strata.size(), static_cast<std::size_t>(n));
  // Plain random draws leave strata empty (50 draws into 50 bins: about 18 stay empty).
  const Plan r = make_plan(scenario_file().string(), {"controller.altitude.kp=uniform(0,1)"}, 3, n, Sampler::kRandom,
                           hosts::test_resolvers());
  std::set<int> random_strata;
  for (int i = 0; i < n; ++i) random_strata.insert(static_cast<int>(std::floor(sample(r, i).values[0].second * n)));
  EXPECT_LT(random_strata.size(), static_cast<std::size_t>(n));
}

// Mean of N(mu, sigma) truncated to [a, b]: mu + sigma (phi(alpha) - phi(beta)) / (Phi(beta) - Phi(alpha)).
double truncated_mean(double mu, double sigma, double a, double b) {
  const auto pdf = [](double z) { return std::exp(-0.5 * z * z) / std::sqrt(2.0 * std::numbers::pi); };
  const auto cdf = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  const double al = (a - mu) / sigma, be = (b - mu) / sigma;
  return mu + sigma * (pdf(al) - pdf(be)) / (cdf(be) - cdf(al));
}

TEST(Sample, NormalTruncatedToTheDeclaredRangeHasTheClosedFormMean) {
  const int n = 4000;
  // altitude.min_cos_tilt is declared in [0.05, 1]: normal(0.1, 0.3) is cut hard at 0.05.
  const Plan p = make_plan(scenario_file().string(),
                           {"controller.altitude.min_cos_tilt=normal(0.1,0.3)", "controller.altitude.kd=normal(3,0.5)"},
                           9, n, Sampler::kLhs, hosts::test_resolvers());
  double sum = 0.0, sum_kd = 0.0, ss_kd = 0.0;
  for (int i = 0; i < n; ++i) {
    const Sample s = sample(p, i);
    const double x = s.values[0].second;
    ASSERT_GE(x, 0.05);
    ASSERT_LE(x, 1.0);
    sum += x;
    sum_kd += s.values[1].second;
    ss_kd += (s.values[1].second - 3.0) * (s.values[1].second - 3.0);
  }
  EXPECT_NEAR(sum / n, truncated_mean(0.1, 0.3, 0.05, 1.0), 0.005);  // 0.3066; untruncated it would be 0.1
  EXPECT_NEAR(sum_kd / n, 3.0, 0.01);                                // kd's range [0, 1e9] cuts nothing
  EXPECT_NEAR(std::sqrt(ss_kd / n), 0.5, 0.01);
}

TEST(ScenarioFor, PlantFliesTheDrawTheControllerKeepsTheNominalVehicle) {
  const Plan p = make_plan(scenario_file().string(), {"vehicle.mass_kg=grid(1.5)", "controller.altitude.kp=grid(7)"}, 1,
                           1, Sampler::kRandom, hosts::test_resolvers());
  const Sample s = sample(p, 0);
  const io::Scenario sc = scenario_for(p, s);
  EXPECT_EQ(sc.vehicle.mass_kg, 1.5);
  EXPECT_EQ(sc.controller.vehicle.mass_kg, 1.2);
  EXPECT_EQ(controllers::paper_controller(sc.controller)->vehicle().mass_kg, 1.2);
  EXPECT_EQ(std::get<double>(*control::get_parameter(sc.controller, "altitude.kp")), 7.0);
  EXPECT_EQ(sc.simulation.plant.realism.seed, s.seed);
}

TEST(RunOne, ARefusedDrawFailsThatRunNamingKeyAndValue) {
  // initial.yaw_rad declares no range; the loader takes [-10, 10]: normal(0, 20) draws outside it in
  // about 62 % of runs. The mass, declared in [1e-06, 1e12], is truncated there: never refused.
  const Plan p = make_plan(scenario_file().string(), {"initial.yaw_rad=normal(0,20)", "vehicle.mass_kg=normal(0.3,1)"},
                           5, 20, Sampler::kRandom, hosts::test_resolvers());
  int refused = 0;
  for (int i = 0; i < p.runs; ++i) {
    const Sample s = sample(p, i);
    EXPECT_GE(s.values[1].second, 1e-6);
    if (std::abs(s.values[0].second) <= 10.0) continue;
    const RunResult r = run_one(p, i, {});
    EXPECT_FALSE(r.passed);
    EXPECT_THAT(r.error, HasSubstr("initial.yaw_rad"));
    const auto q = r.error.find("got '");
    ASSERT_NE(q, std::string::npos) << r.error;
    EXPECT_EQ(std::stod(r.error.substr(q + 5)), s.values[0].second);  // the very value drawn
    ++refused;
  }
  EXPECT_GT(refused, 0);
}

TEST(RunOne, SaturationIsJudgedAsRunJudgesItFromTheCsv) {
  // A 1 rad yaw step clamps rotors 2 and 4 for about 1.5 s (the allocation's omega limits); 0.2 rad
  // clamps nothing. The limit max_saturated_s 0.5 fails exactly the 1 rad run.
  const Plan p = make_plan(yaw_scenario_file().string(), {"controller.yaw_des=grid(0.2,1)"}, 1, 1, Sampler::kRandom,
                           hosts::test_resolvers());
  ASSERT_EQ(p.runs, 2);
  const RunResult small = run_one(p, 0, {});
  const RunResult big = run_one(p, 1, {});
  ASSERT_TRUE(small.error.empty() && big.error.empty()) << small.error << big.error;
  ASSERT_TRUE(small.saturation && big.saturation);
  EXPECT_EQ(small.saturation->saturated_s(), 0.0);
  EXPECT_TRUE(small.passed);
  EXPECT_GT(big.saturation->rotor_saturated_s(2), 1.0);
  EXPECT_GT(big.saturation->rotor_saturated_s(4), 1.0);
  EXPECT_EQ(big.saturation->rotor_saturated_s(1), 0.0);
  EXPECT_FALSE(big.passed);
  ASSERT_EQ(big.saturation->criteria.size(), 1u);
  EXPECT_FALSE(big.saturation->criteria[0].passed);
  // Flown again and judged from its recorded trajectory.csv (the path `run` takes): the same doubles.
  const fs::path dir = fs::temp_directory_path() / ("sweep_test_" + std::to_string(::getpid())) / "rerun1";
  fs::remove_all(dir);
  const RunResult again = rerun(p, 1, dir);
  ASSERT_TRUE(again.saturation);
  EXPECT_EQ(again.saturation->figures, big.saturation->figures);
  EXPECT_FALSE(again.passed);
  // ... and counted here from the CSV's rows: ticks with sat2 or sat4 set times the 0.01 s period.
  std::ifstream csv(dir / "trajectory.csv");
  std::string line;
  std::getline(csv, line);
  std::vector<std::string> header;
  for (std::stringstream ss(line); std::getline(ss, line, ',');) header.push_back(line);
  const auto col = [&](const std::string& n) { return std::find(header.begin(), header.end(), n) - header.begin(); };
  int rows_any = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    for (std::stringstream ss(line); std::getline(ss, line, ',');) cells.push_back(line);
    bool any = false;
    for (const char* c : {"sat1", "sat2", "sat3", "sat4"}) any = any || cells.at(col(c)) == "1";
    rows_any += any ? 1 : 0;
  }
  EXPECT_NEAR(big.saturation->saturated_s(), rows_any * 0.01, 1e-9);
  // metrics.json and summary.json carry them; a run that could not be flown has them null.
  const nlohmann::json m = run_metrics_json(p, scenario_for(p, big.sample), big);
  EXPECT_EQ(m["saturation"]["figures"]["saturated_s"].get<double>(), big.saturation->saturated_s());
  EXPECT_FALSE(m["saturation"]["passed"].get<bool>());
  EXPECT_FALSE(m["passed"].get<bool>());
  const nlohmann::json s = summary_json(header_json(p), {per_run_json(p, small), per_run_json(p, big)});
  EXPECT_EQ(s["figures"]["saturation.saturated_s"]["count"].get<int>(), 2);
  EXPECT_EQ(s["figures"]["saturation.saturated_s"]["max"].get<double>(), big.saturation->saturated_s());
  EXPECT_EQ(s["per_run"][0]["figures"]["saturation.rotor2_saturated_s"].get<double>(), 0.0);
  EXPECT_EQ(s["passed"].get<int>(), 1);
  RunResult failed = big;
  failed.error = "controller design failed";
  EXPECT_TRUE(per_run_json(p, failed)["figures"]["saturation.saturated_s"].is_null());
  fs::remove_all(dir);
}

// A hexarotor's sweep lists the saturation of each of its six rotors (rotor5, rotor6 beyond the four of a
// quadrotor) in every run's figures. The Firefly's six rotors lift at most 6 k_t omega_max^2 = 36.0 N
// (k_t 8.54858e-6 N s^2, 838 rad/s): at its own 1.53 kg it hovers at 541 rad/s, unsaturated; at 4.5 kg
// (44.1 N of weight) every rotor reaches its limit as the controller (which keeps the nominal 1.53 kg)
// pushes against the sinking.
TEST(Summary, AHexarotorsSweepListsEachOfItsRotors) {
  const fs::path dir = fs::temp_directory_path() / ("sweep_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path f = dir / "hex.yaml";
  std::ofstream(f) << R"(name: hex
vehicle: {preset: firefly}
simulation: {plant_rate_hz: 100, controller_rate_hz: 50, duration_s: 1}
initial: {position_m: [0, 0, 5], hover: true}
controller: {type: se3, mode: position, z_des: 5}
)";
  const Plan p =
      make_plan(f.string(), {"vehicle.mass_kg=grid(1.53,4.5)"}, 1, 1, Sampler::kRandom, hosts::test_resolvers());
  ASSERT_EQ(p.nominal.vehicle.rotor_count, 6);
  ASSERT_EQ(p.runs, 2);
  const RunResult light = run_one(p, 0, {});
  const RunResult heavy = run_one(p, 1, {});
  ASSERT_TRUE(light.error.empty()) << light.error;
  ASSERT_TRUE(heavy.error.empty()) << heavy.error;
  const nlohmann::json fig = per_run_json(p, heavy)["figures"];
  for (int k = 1; k <= 6; ++k) {
    const std::string name = fmt::format("saturation.rotor{}_saturated_s", k);
    ASSERT_TRUE(fig.contains(name)) << name;
    EXPECT_GT(fig[name].get<double>(), 0.25) << name;
    EXPECT_EQ(per_run_json(p, light)["figures"][name].get<double>(), 0.0) << name;
  }
  EXPECT_FALSE(fig.contains("saturation.rotor7_saturated_s"));
}

TEST(Summary, SameBytesWhateverTheThreadsAndTheOrderOfRuns) {
  const Plan p = make_plan(scenario_file().string(), {"mass=20%", "controller.altitude.kd=uniform(1,4)"}, 7, 6,
                           Sampler::kRandom, hosts::test_resolvers());
  std::vector<int> all = shard_indices(p.runs, 1, 1);
  ASSERT_EQ(all, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  const auto one = run_many(p, all, 1, {});
  const auto two = run_many(p, all, 2, {});
  std::vector<nlohmann::json> a, b;
  for (const auto& r : one) a.push_back(per_run_json(p, r));
  for (const auto& r : two) b.push_back(per_run_json(p, r));
  const std::string dump = summary_json(header_json(p), a).dump(2);
  EXPECT_EQ(summary_json(header_json(p), b).dump(2), dump);
  // Shards 1/2 and 2/2 (even, odd runs), joined in the other order, through their JSON text.
  EXPECT_EQ(shard_indices(6, 2, 2), (std::vector<int>{1, 3, 5}));
  std::vector<nlohmann::json> joined;
  for (int k : {2, 1}) {
    for (const auto& r : run_many(p, shard_indices(p.runs, k, 2), 2, {})) {
      joined.push_back(nlohmann::json::parse(per_run_json(p, r).dump()));
    }
  }
  EXPECT_EQ(summary_json(header_json(p), joined).dump(2), dump);
  // The distribution is that of the per-run figures.
  const nlohmann::json s = summary_json(header_json(p), a);
  double mx = -1e300;
  for (const auto& r : s["per_run"]) mx = std::max(mx, r["figures"]["z.steady_state_error_pct"].get<double>());
  EXPECT_EQ(s["figures"]["z.steady_state_error_pct"]["max"].get<double>(), mx);
  EXPECT_EQ(s["figures"]["z.steady_state_error_pct"]["count"].get<int>(), 6);
  // A run missing or given twice is refused.
  a.pop_back();
  EXPECT_THROW(summary_json(header_json(p), a), std::invalid_argument);
  a.push_back(a.front());
  EXPECT_THROW(summary_json(header_json(p), a), std::invalid_argument);
}

TEST(RunMany, StoppedItReturnsTheRunsStartedALeadingPartAndAResumeGivesTheSameSummary) {
  const Plan p = make_plan(scenario_file().string(), {"mass=20%", "controller.altitude.kd=uniform(1,4)"}, 9, 8,
                           Sampler::kRandom, hosts::test_resolvers());
  const std::vector<int> all = shard_indices(p.runs, 1, 1);
  const nlohmann::json header = header_json(p);
  std::vector<nlohmann::json> whole;
  for (const auto& r : run_many(p, all, 2, {})) whole.push_back(per_run_json(p, r));
  const std::string dump = summary_json(header, whole).dump(2);
  // Stopped after the third run finished: the runs started (3 or 4 with two threads) are indices[0 .. k).
  std::atomic<int> finished{0};
  RunControl control;
  control.stop = [&] { return finished.load() >= 3; };
  control.finished = [&](const RunResult&) { ++finished; };
  const auto first = run_many(p, all, 2, {}, Keep::kNone, control);
  ASSERT_GE(first.size(), 3u);
  ASSERT_LT(first.size(), all.size());
  std::vector<nlohmann::json> done;
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].sample.index, all[i]);
    done.push_back(nlohmann::json::parse(per_run_json(p, first[i]).dump()));  // as read back from summary.json
  }
  const nlohmann::json partial = partial_summary_json(header, done);
  EXPECT_EQ(partial["partial"]["finished"].get<std::size_t>(), first.size());
  EXPECT_EQ(partial["partial"]["runs"].get<int>(), 8);
  EXPECT_EQ(partial["figures"]["z.steady_state_error_pct"]["count"].get<std::size_t>(), first.size());
  int passed = 0;
  for (const auto& r : done) passed += r["passed"].get<bool>() ? 1 : 0;
  EXPECT_EQ(partial["passed"].get<int>(), passed);
  // The rest, on one thread this time: the summary is the uninterrupted sweep's, byte for byte.
  const std::vector<int> rest(all.begin() + static_cast<std::ptrdiff_t>(first.size()), all.end());
  for (const auto& r : run_many(p, rest, 1, {})) done.push_back(per_run_json(p, r));
  EXPECT_EQ(summary_json(header, done).dump(2), dump);
  // A partial summary refuses a run twice or out of range.
  std::vector<nlohmann::json> twice = {whole[0], whole[0]};
  EXPECT_THROW(partial_summary_json(header, twice), std::invalid_argument);
  nlohmann::json out_of_range = whole[0];
  out_of_range["index"] = 8;
  EXPECT_THROW(partial_summary_json(header, {out_of_range}), std::invalid_argument);
}

// A run that fails once the stop was asked for failed of the stop (Ctrl-C kills a controller that
// flies in a process of its own): it is not a finished run, and its files are gone, so a resume flies
// it again. A run that fails before the stop, or finishes after it, is a result as any other.
TEST(RunMany, ARunThatFailsOnceStoppedIsNotFinished) {
  // initial.yaw_rad is refused outside [-10, 10], when the run is flown: normal(0, 1000) draws run 0
  // (seed 5) outside it.
  const Plan p = make_plan(scenario_file().string(), {"initial.yaw_rad=normal(0,1000)"}, 5, 4, Sampler::kRandom,
                           hosts::test_resolvers());
  ASSERT_GT(std::abs(sample(p, 0).values[0].second), 10.0);
  const std::vector<int> all = shard_indices(p.runs, 1, 1);
  const fs::path dir = fs::temp_directory_path() / ("quadcosim_sweep_cut_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  int asked = 0;
  RunControl control;
  control.stop = [&] { return ++asked > 1; };  // not before the first run, asked from then on
  EXPECT_TRUE(run_many(p, all, 1, dir, Keep::kAll, control).empty());
  EXPECT_FALSE(fs::exists(dir / "0000"));
  // Not stopped: the same failure is the run's result.
  const auto failed = run_many(p, {0}, 1, dir, Keep::kAll);
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_THAT(failed[0].error, HasSubstr("initial.yaw_rad"));
  // A run that succeeds while the stop is asked is finished.
  const Plan good = make_plan(scenario_file().string(), {"mass=5%"}, 5, 4, Sampler::kRandom, hosts::test_resolvers());
  asked = 0;
  const auto kept = run_many(good, all, 1, dir, Keep::kNone, control);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_TRUE(kept[0].error.empty()) << kept[0].error;
  EXPECT_TRUE(fs::exists(dir / "0000" / "metrics.json"));
  fs::remove_all(dir);
}

// A metrics.json written by hand: the bound named is the one the value is outside, a figure without
// a value names none (its note says why), passed criteria are left out, a channel's second step is
// "<channel>#2" as in summary.json, and fields the criteria layer adds are carried over.
TEST(FailedCriteria, NamesChannelFigureValueAndTheBoundCrossed) {
  const nlohmann::json metrics = nlohmann::json::parse(R"({
    "steps": [
      {"channel": "z", "criteria": [
        {"figure": "overshoot_pct", "min": 15.0, "max": 21.0, "value": 3.5, "passed": false, "note": null},
        {"figure": "peak_time_s", "min": 2.0, "max": 3.0, "value": 2.5, "passed": true, "note": null}]},
      {"channel": "z", "criteria": [
        {"figure": "settling_time_2pct_s", "min": null, "max": 8.5, "value": null, "passed": false,
         "note": "not settled"}]}],
    "saturation": {"criteria": [
        {"figure": "saturated_s", "min": null, "max": 0.5, "value": 1.52, "passed": false, "note": null,
         "kind": "specification"}]},
    "passed": false})");
  const nlohmann::json f = failed_criteria(metrics);
  ASSERT_EQ(f.size(), 3U) << f.dump(2);
  EXPECT_EQ(f[0]["channel"], "z");
  EXPECT_EQ(f[0]["name"], "overshoot_pct");
  EXPECT_EQ(f[0]["value"], 3.5);
  EXPECT_EQ(f[0]["bound"], 15.0);
  EXPECT_EQ(f[0]["side"], "min");
  EXPECT_EQ(f[1]["channel"], "z#2");
  EXPECT_EQ(f[1]["name"], "settling_time_2pct_s");
  EXPECT_TRUE(f[1]["value"].is_null() && f[1]["bound"].is_null());
  EXPECT_EQ(f[1]["note"], "not settled");
  EXPECT_EQ(f[2]["channel"], "saturation");
  EXPECT_EQ(f[2]["bound"], 0.5);
  EXPECT_EQ(f[2]["side"], "max");
  EXPECT_EQ(f[2]["kind"], "specification");
  EXPECT_TRUE(failed_criteria(nlohmann::json::parse(R"({"steps": [], "passed": true})")).empty());
}

// A failing run's per_run entry names what failed, the very criteria of its metrics.json; a passing
// run's has no failed_criteria.
TEST(RunOne, AFailedRunNamesItsFailedCriteriaAsItsMetricsJsonHasThem) {
  const fs::path dir = fs::temp_directory_path() / ("sweep_test_failed_" + std::to_string(::getpid()));
  // A 1 rad yaw step clamps rotors for about 1.5 s (more than the 0.5 s allowed), 0.2 rad none.
  const Plan p = make_plan(yaw_scenario_file().string(), {"controller.yaw_des=grid(1,0.2)"}, 1, 1, Sampler::kRandom,
                           hosts::test_resolvers());
  const std::vector<RunResult> results = run_many(p, {0, 1}, 1, dir);
  for (const RunResult& r : results) {
    std::ifstream in(dir / fmt::format("{:04d}", r.sample.index) / "metrics.json");
    const nlohmann::json m = nlohmann::json::parse(in);
    const nlohmann::json entry = per_run_json(p, r);
    ASSERT_EQ(m["passed"].get<bool>(), r.passed);
    if (r.passed) {
      EXPECT_FALSE(entry.contains("failed_criteria"));
      continue;
    }
    // Every criterion metrics.json marks failed, in its order, and no other.
    std::vector<nlohmann::json> expected;
    for (const auto& c : m["saturation"]["criteria"]) {
      if (!c["passed"].get<bool>()) expected.push_back(c);
    }
    ASSERT_EQ(expected.size(), 1U);
    ASSERT_EQ(entry["failed_criteria"].size(), 1U) << entry.dump(2);
    const nlohmann::json& f = entry["failed_criteria"][0];
    EXPECT_EQ(f["channel"], "saturation");
    EXPECT_EQ(f["name"], "saturated_s");
    EXPECT_EQ(f["value"], expected[0]["value"]);
    EXPECT_GT(f["value"].get<double>(), 0.5);
    EXPECT_EQ(f["bound"], 0.5);
    EXPECT_EQ(f["side"], "max");
  }
  EXPECT_FALSE(results[0].passed);
  fs::remove_all(dir);
}

// The record of where a sweep started: absolute paths, the loader's search order, each folder once.
TEST(Origin, RecordsTheScenarioFolderTheCwdAndPythonPathAbsoluteAndOnce) {
  const Origin o = origin_of("../scn/pd.yaml", "/work/start", "lib::/opt/py:/work/scn/");
  EXPECT_EQ(o.scenario_file, "/work/scn/pd.yaml");
  EXPECT_EQ(o.cwd, "/work/start");
  EXPECT_EQ(o.python_path, (std::vector<std::string>{"/work/scn", "/work/start", "/work/start/lib", "/opt/py"}));
  EXPECT_EQ(origin_of("pd.yaml", "/w", nullptr).python_path, (std::vector<std::string>{"/w"}));
  // Continued elsewhere: the recorded folders first, then the current PYTHONPATH's others.
  EXPECT_EQ(python_path_env(o, "/opt/py:/home/u/mods"), "/work/scn:/work/start:/work/start/lib:/opt/py:/home/u/mods");
  EXPECT_EQ(python_path_env(o, nullptr), "/work/scn:/work/start:/work/start/lib:/opt/py");
  // Written and read back; a record that is not one is refused naming the file.
  const fs::path dir = fs::temp_directory_path() / ("sweep_test_origin_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  EXPECT_FALSE(read_origin(dir).has_value());
  write_json(dir / kOriginFile, origin_json(o));
  const std::optional<Origin> back = read_origin(dir);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->scenario_file, o.scenario_file);
  EXPECT_EQ(back->python_path, o.python_path);
  std::ofstream(dir / kOriginFile) << "{\"cwd\": 3}";
  try {
    (void)read_origin(dir);
    ADD_FAILURE() << "a malformed origin.json was read";
  } catch (const io::ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("origin.json"));
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace quadcosim::sweep
