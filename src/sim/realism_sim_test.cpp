// The plant node with realism on: a repeated tick publishes the same sample, each noise source keeps
// its own numbers when others are added, latency and rates shape what is published, covariances
// follow the configured noise, and the off switch leaves the paper's plant.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim/plant_rig_test_support.hpp"

namespace quadcosim::sim {
namespace {

struct Captured {
  std::vector<msg::PoseStamped> pose;
  std::vector<msg::TwistStamped> twist;
  std::vector<msg::Imu> imu;
};

// A plant on an in-process bus whose sensor messages are collected.
struct Rig : test::PlantRig {
  Captured got;
  Rig(const RealismConfig& r, const model::State& x0, model::VehicleParams v = {}) : PlantRig(r, x0, v) {
    const Topics t = Topics::for_namespace("/drone");
    bus.subscribe<msg::PoseStamped>(t.pose, [this](const msg::PoseStamped& m) { got.pose.push_back(m); });
    bus.subscribe<msg::TwistStamped>(t.velocity, [this](const msg::TwistStamped& m) { got.twist.push_back(m); });
    bus.subscribe<msg::Imu>(t.imu, [this](const msg::Imu& m) { got.imu.push_back(m); });
  }
};

model::State hover_state() { return model::Quadrotor(model::VehicleParams{}).initial_state({0, 0, 5}, 0.0, true); }

RealismConfig noisy() {
  RealismConfig r;
  r.seed = 99;
  r.imu.gyro_noise_density = 0.001;
  r.imu.gyro_bias_random_walk = 0.0001;
  r.imu.accel_noise_density = 0.01;
  r.imu.orientation_sigma_rad = 0.01;
  r.pose.position_sigma_m = 0.05;
  r.velocity.linear_sigma_m_s = 0.05;
  r.wind.mean_W_m_s = {2, 0, 0};
  r.wind.gusts.enabled = true;
  return r;
}

bool same(const msg::Imu& a, const msg::Imu& b) {
  return a.header.stamp.to_ns() == b.header.stamp.to_ns() && a.angular_velocity.x == b.angular_velocity.x &&
         a.angular_velocity.y == b.angular_velocity.y && a.linear_acceleration.z == b.linear_acceleration.z &&
         a.orientation.x == b.orientation.x && a.orientation.w == b.orientation.w;
}

TEST(PlantRealismTest, ALockstepRepeatPublishesTheSameSampleAndDrawsNothingNew) {
  model::VehicleParams v;
  v.aero.linear_drag_N_s_m.setConstant(0.3);
  Rig once(noisy(), hover_state(), v), twice(noisy(), hover_state(), v);
  once.run(200);
  twice.run(200, /*repeat_each=*/true);
  ASSERT_EQ(once.got.imu.size(), 200u);
  ASSERT_EQ(twice.got.imu.size(), 400u);
  for (std::size_t k = 0; k < 200; ++k) {
    ASSERT_TRUE(same(twice.got.imu[2 * k], twice.got.imu[2 * k + 1])) << "tick " << k;
    ASSERT_TRUE(same(once.got.imu[k], twice.got.imu[2 * k])) << "tick " << k;
    ASSERT_EQ(once.got.pose[k].position.x, twice.got.pose[2 * k].position.x);
  }
  EXPECT_EQ(once.plant.state().p_W, twice.plant.state().p_W);
  // The noise is there: the gyro reading differs from the true (zero-mean) rate by about sigma.
  EXPECT_NE(once.got.imu[5].angular_velocity.x, once.got.imu[6].angular_velocity.x);
}

TEST(PlantRealismTest, AddingASourceDoesNotShiftAnotherSourcesNumbers) {
  // Gyro noise alone on a vehicle resting on the ground (true rate exactly 0) vs the same gyro noise
  // with pose, velocity and attitude noise added: the gyro readings are the same numbers.
  model::State ground = model::Quadrotor(model::VehicleParams{}).initial_state({0, 0, 0}, 0.0, false);
  RealismConfig gyro_only;
  gyro_only.seed = 5;
  gyro_only.imu.gyro_noise_density = 0.002;
  RealismConfig more = gyro_only;
  more.pose.position_sigma_m = 0.1;
  more.velocity.angular_sigma_rad_s = 0.1;
  more.imu.orientation_sigma_rad = 0.1;
  more.imu.accel_noise_density = 0.1;
  Rig a(gyro_only, ground), b(more, ground);
  a.run(100);
  b.run(100);
  for (std::size_t k = 0; k < 100; ++k) {
    ASSERT_EQ(a.got.imu[k].angular_velocity.x, b.got.imu[k].angular_velocity.x);
    ASSERT_EQ(a.got.imu[k].angular_velocity.z, b.got.imu[k].angular_velocity.z);
  }
  EXPECT_NE(a.got.pose[3].position.x, b.got.pose[3].position.x);
  // A different seed gives different numbers.
  RealismConfig other = gyro_only;
  other.seed = 6;
  Rig c(other, ground);
  c.run(10);
  EXPECT_NE(a.got.imu[3].angular_velocity.x, c.got.imu[3].angular_velocity.x);
}

TEST(PlantRealismTest, ImuCovariancesCarryTheDiscreteNoiseVariance) {
  RealismConfig r;
  r.imu.gyro_noise_density = 0.001;  // at 100 Hz: sigma 0.01 rad/s
  r.imu.accel_noise_density = 0.02;  // sigma 0.2 m/s^2
  r.imu.timing.divider = 2;          // 50 Hz: sigma = density * sqrt(50)
  r.imu.orientation_sigma_rad = 0.003;
  Rig rig(r, hover_state());
  rig.run(4);
  ASSERT_EQ(rig.got.imu.size(), 2u);  // ticks 0 and 2 only
  const msg::Imu& m = rig.got.imu[1];
  EXPECT_EQ(m.header.stamp.to_ns(), 20'000'000);
  EXPECT_NEAR(m.angular_velocity_covariance[0], 0.001 * 0.001 * 50.0, 1e-15);
  EXPECT_NEAR(m.angular_velocity_covariance[8], 0.001 * 0.001 * 50.0, 1e-15);
  EXPECT_EQ(m.angular_velocity_covariance[1], 0.0);
  EXPECT_NEAR(m.linear_acceleration_covariance[4], 0.02 * 0.02 * 50.0, 1e-15);
  EXPECT_NEAR(m.orientation_covariance[0], 0.003 * 0.003, 1e-18);
  EXPECT_EQ(rig.got.pose.size(), 4u);  // the other sensors keep the plant rate
}

TEST(PlantRealismTest, PublishedImuReadingsHaveTheDatasheetStatistics) {
  // At rest on the ground the true rate is 0 and the specific force (0, 0, g). Gyro density
  // 0.001 rad/s/√Hz and accel density 0.02 m/s²/√Hz at 100 Hz: sigma 0.01 rad/s and 0.2 m/s².
  RealismConfig r;
  r.seed = 17;
  r.imu.gyro_noise_density = 0.001;
  r.imu.accel_noise_density = 0.02;
  const model::State ground = model::Quadrotor(model::VehicleParams{}).initial_state({0, 0, 0}, 0.0, false);
  Rig rig(r, ground);
  const int n = 20000;
  rig.run(n);
  double sg = 0.0, sg2 = 0.0, sa = 0.0, sa2 = 0.0;
  for (const msg::Imu& m : rig.got.imu) {
    sg += m.angular_velocity.y;
    sg2 += m.angular_velocity.y * m.angular_velocity.y;
    sa += m.linear_acceleration.z;
    sa2 += m.linear_acceleration.z * m.linear_acceleration.z;
  }
  const double mg = sg / n, ma = sa / n;
  EXPECT_NEAR(mg, 0.0, 5 * 0.01 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sg2 / n - mg * mg), 0.01, 0.01 * 5 / std::sqrt(2.0 * n));
  EXPECT_NEAR(ma, 9.81, 5 * 0.2 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sa2 / n - ma * ma), 0.2, 0.2 * 5 / std::sqrt(2.0 * n));
}

TEST(PlantRealismTest, LatencyPublishesTheStateOfEarlierTicks) {
  // Free fall from 20 m with rotors stopped: z(t) = 20 - g t^2 / 2 (RK4 is exact on it). With a
  // latency of 3 ticks the pose published at tick k shows z(t_{k-3}), stamped t_k.
  RealismConfig r;
  r.pose.timing.latency_ticks = 3;
  const model::State x0 = model::Quadrotor(model::VehicleParams{}).initial_state({0, 0, 20}, 0.0, false);
  Rig rig(r, x0);
  rig.run(50);
  const double g = model::VehicleParams{}.gravity_m_s2;
  for (int k = 0; k < 50; ++k) {
    const double t = std::max(k - 3, 0) * 0.01;
    ASSERT_NEAR(rig.got.pose[k].position.z, 20.0 - 0.5 * g * t * t, 1e-9) << "tick " << k;
    ASSERT_EQ(rig.got.pose[k].header.stamp.to_ns(), k * 10'000'000);
    const double tv = k * 0.01;  // velocity has no latency
    ASSERT_NEAR(rig.got.twist[k].linear.z, -g * tv, 1e-9);
  }
}

TEST(PlantRealismTest, MotorFailureAtItsTickAndTheIdealPlantWhenAllIsOff) {
  RealismConfig r;
  r.faults.push_back({100, 0, 0.0});
  r.faults.push_back({100, 2, 0.0});  // two opposite rotors stop at t = 1 s: the vehicle falls
  Rig failing(r, hover_state());
  Rig ideal(RealismConfig{}, hover_state());
  EXPECT_FALSE(RealismConfig{}.active());
  failing.run(100);
  ideal.run(100);
  EXPECT_EQ(failing.plant.state().p_W, ideal.plant.state().p_W);  // nothing happened before the fault
  const double z_before = failing.plant.state().p_W.z();          // at t = 1 s
  for (Tick k = 100; k < 149; ++k) {
    failing.plant.publish_outputs(k);
    failing.plant.latch_command(k);
    failing.plant.integrate(k);
  }
  // Half the thrust: a = -g/2 from t = 1 s (rotor speeds stay at hover, the command holds), and
  // the two stopped rotors are opposite, so the torques stay balanced.
  const double t = 0.49;
  EXPECT_NEAR(failing.plant.state().p_W.z(), z_before - 0.25 * 9.81 * t * t, 1e-6);
}

}  // namespace
}  // namespace quadcosim::sim
