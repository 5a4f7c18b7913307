// Scenario keys of the reliability features: simulation.watchdog_s / watchdog_policy and message_faults:.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "hosts/scenario_resolvers_test_support.hpp"
#include "io/scenario.hpp"

namespace quadcosim::io {
namespace {

std::string write_yaml(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "faults_" + name + ".yaml";
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::string& name, const std::string& text) {
  try {
    load_scenario(write_yaml(name, text), hosts::test_resolvers());
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ReliabilityKeysTest, DefaultsAreAHalfSecondStopWatchdogAndNoFaults) {
  const Scenario sc = load_scenario(write_yaml("defaults", "simulation: {duration_s: 1}\n"), hosts::test_resolvers());
  EXPECT_EQ(sc.simulation.plant.watchdog_ticks, 50);
  EXPECT_EQ(sc.simulation.plant.watchdog_policy, sim::WatchdogPolicy::kStop);
  EXPECT_FALSE(sc.simulation.faults.active());
}

TEST(ReliabilityKeysTest, WatchdogAndFaultsAreRead) {
  const Scenario sc = load_scenario(write_yaml("read", R"(simulation:
  plant_rate_hz: 200
  watchdog_s: 0.25
  watchdog_policy: hold
  namespace: /uav1
message_faults:
  seed: 9
  drop_probability: 0.1
  delay_ticks: 1
  topics:
    motor_commands: {drop_probability: 0.2}
    controller_status: {delay_ticks: 3}
)"),
                                    hosts::test_resolvers());
  EXPECT_EQ(sc.simulation.plant.watchdog_ticks, 50);  // 0.25 s at 200 Hz
  EXPECT_EQ(sc.simulation.plant.watchdog_policy, sim::WatchdogPolicy::kHold);
  const auto& t = sc.simulation.faults.topics;
  EXPECT_EQ(sc.simulation.faults.seed, 9u);
  EXPECT_EQ(t.at("/uav1/Pose").drop_probability, 0.1);
  EXPECT_EQ(t.at("/uav1/Imu").delay_ticks, 1);
  EXPECT_EQ(t.at("/uav1/motor_commands").drop_probability, 0.2);
  EXPECT_EQ(t.at("/uav1/motor_commands").delay_ticks, 1);
  EXPECT_EQ(t.at("/uav1/controller_status").delay_ticks, 3);
  EXPECT_EQ(t.at("/uav1/controller_status").drop_probability, 0.0);
  EXPECT_EQ(t.count("/clock"), 0u);
}

TEST(ReliabilityKeysTest, BadValuesNameFileKeyAndValue) {
  std::string e = error_of("frac", "simulation: {watchdog_s: 0.015}\n");
  EXPECT_NE(e.find("simulation.watchdog_s"), std::string::npos) << e;
  EXPECT_NE(e.find("0.015"), std::string::npos) << e;
  e = error_of("policy", "simulation: {watchdog_policy: land}\n");
  EXPECT_NE(e.find("simulation.watchdog_policy"), std::string::npos) << e;
  EXPECT_NE(e.find("land"), std::string::npos) << e;
  e = error_of("prob", "message_faults: {drop_probability: 1.5}\n");
  EXPECT_NE(e.find("message_faults.drop_probability"), std::string::npos) << e;
  e = error_of("topic", "message_faults: {topics: {Odom: {drop_probability: 0.1}}}\n");
  EXPECT_NE(e.find("message_faults.topics.Odom"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown topic"), std::string::npos) << e;
  e = error_of("key", "message_faults: {loss: 0.1}\n");
  EXPECT_NE(e.find("message_faults.loss"), std::string::npos) << e;
  e = error_of("delay", "message_faults: {delay_ticks: -1}\n");
  EXPECT_NE(e.find("message_faults.delay_ticks"), std::string::npos) << e;
}

}  // namespace
}  // namespace quadcosim::io
