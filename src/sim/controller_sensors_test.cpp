// The extra sensors on the controller's side: the node subscribes the ones the vehicle carries, its
// observation holds each one's newest sample and stamp (checked against the truth by independent
// formulas), refused samples are counted and leave the reading as it was, and a lockstep controller
// waits for the samples due at a tick before it steps.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "controllers/registry.hpp"
#include "sensors/barometer.hpp"
#include "sim/controller_node.hpp"
#include "sim/lockstep_stepper.hpp"
#include "sim/plant_rig_test_support.hpp"
#include "sim/sensor_wire.hpp"

namespace quadcosim::sim {
namespace {

using sensors::BarometerKind;
using sensors::GnssKind;
using sensors::MagnetometerKind;

constexpr double kDeg = std::numbers::pi / 180.0;

/// Every extra sensor, noiseless: the magnetometer at 100 Hz with a hard iron, the barometer at
/// 50 Hz, the GNSS at 10 Hz, 100 ms old, without a fix for its first 0.25 s.
RealismConfig noiseless_sensors() {
  RealismConfig r;
  r.seed = 11;
  sensors::MagnetometerConfig m;
  m.field_T = 48e-6;
  m.inclination_rad = 63.5 * kDeg;
  m.declination_rad = 3.0 * kDeg;
  m.hard_iron_T = {2e-6, -1.5e-6, 0.8e-6};
  r.extra_sensors.magnetometer = m;
  sensors::BarometerConfig b;
  b.timing.divider = 2;
  b.site_altitude_m = 488.0;
  r.extra_sensors.barometer = b;
  sensors::GnssConfig g;
  g.timing = {10, 10};
  g.site.height_m = 488.0;
  g.fix_after_s = 0.25;
  r.extra_sensors.gnss = g;
  return r;
}

struct Rig : test::PlantRig {
  control::ControllerConfig cfg = controllers::make_config("paper", model::VehicleParams{});
  ControllerNode node;
  explicit Rig(const RealismConfig& r, const sensors::SensorSet& carried)
      : PlantRig(r, PlantRig::climbing()), node(bus, Topics::for_namespace("/drone"), cfg, {}, carried) {}
};

TEST(ControllerSensorsTest, TheObservationHoldsEachCarriedSensorsNewestSample) {
  const RealismConfig r = noiseless_sensors();
  Rig rig(r, r.extra_sensors);
  const TickClock clock;
  // The Earth's field in the world frame (ENU) from its three elements, by hand: the body reading of a
  // level vehicle at yaw 0 is that plus the hard iron.
  const double F = 48e-6, I = 63.5 * kDeg, D = 3.0 * kDeg;
  const Eigen::Vector3d expected_field =
      Eigen::Vector3d(F * std::cos(I) * std::sin(D), F * std::cos(I) * std::cos(D), -F * std::sin(I)) +
      Eigen::Vector3d(2e-6, -1.5e-6, 0.8e-6);
  int gnss_fixes = 0;
  std::vector<double> z, vz;  // the true height and climb rate of each tick (the controller flies)
  for (Tick k = 0; k < 80; ++k) {
    z.push_back(rig.plant.state().p_W.z());
    vz.push_back(rig.plant.state().v_W.z());
    rig.plant.publish_outputs(k);
    if (k % 2 == 0) {
      rig.node.step(clock.ns(k), 0.02);
      const control::Observation& o = rig.node.observation();
      const auto* mag = o.sensors.get<MagnetometerKind>();
      const auto* baro = o.sensors.get<BarometerKind>();
      const auto* gnss = o.sensors.get<GnssKind>();
      ASSERT_TRUE(mag && baro && gnss);
      EXPECT_EQ(mag->stamp_ns, clock.ns(k));
      EXPECT_LT((mag->sample.field_B_T - expected_field).norm(), 1e-15) << k;
      EXPECT_EQ(baro->stamp_ns, clock.ns(k));
      // z above a site at 488 m: the ISA inverse of the reading gives it back.
      EXPECT_NEAR(baro->sample.altitude_m, 488.0 + z[static_cast<std::size_t>(k)], 1e-6) << k;
      EXPECT_TRUE(std::isnan(baro->sample.temperature_K));       // FluidPressure has no field for it
      EXPECT_EQ(gnss->stamp_ns, clock.ns(k - k % 10));           // 10 Hz: the newest, published at a 10th tick
      const Tick measured = std::max<Tick>(k - k % 10 - 10, 0);  // 100 ms old
      if (clock.seconds(measured) >= 0.25) {
        ++gnss_fixes;
        EXPECT_TRUE(gnss->sample.fix) << k;
        EXPECT_NEAR(gnss->sample.position.height_m, 488.0 + z[static_cast<std::size_t>(measured)], 1e-6) << k;
        EXPECT_NEAR(gnss->sample.position.latitude_rad, 0.0, 1e-15);
        EXPECT_EQ(gnss->sample.velocity_W.z(), vz[static_cast<std::size_t>(measured)]);
        EXPECT_TRUE(std::isnan(gnss->sample.velocity_variance));  // TwistStamped has no field for it
      } else {
        EXPECT_FALSE(gnss->sample.fix) << k;
        EXPECT_TRUE(std::isnan(gnss->sample.position.latitude_rad));
      }
    }
    rig.plant.latch_command(k);
    rig.plant.integrate(k);
  }
  EXPECT_EQ(gnss_fixes, 4 * 5);  // the samples published at ticks 40, 50, 60, 70 (measuring 0.3 .. 0.6 s)
  // Nothing refused: a sample without a fix has NaN numbers by definition.
  EXPECT_EQ(rig.node.core().rejected(SensorFault::kNonFinite), 0u);
}

TEST(ControllerSensorsTest, OnlyCarriedSensorsAreInTheObservation) {
  RealismConfig r = noiseless_sensors();
  sensors::SensorSet only_baro;
  only_baro.barometer = r.extra_sensors.barometer;
  Rig rig(r, only_baro);
  rig.plant.publish_outputs(0);
  rig.node.step(0, 0.02);
  const control::Observation& o = rig.node.observation();
  EXPECT_EQ(o.sensors.get<MagnetometerKind>(), nullptr);
  EXPECT_EQ(o.sensors.get<GnssKind>(), nullptr);
  ASSERT_NE(o.sensors.get<BarometerKind>(), nullptr);
  EXPECT_EQ(o.sensors.get<BarometerKind>()->stamp_ns, 0);

  Rig none(r, {});
  none.plant.publish_outputs(0);
  none.node.step(0, 0.02);
  EXPECT_FALSE(none.node.observation().sensors.any());
}

TEST(ControllerSensorsTest, ARefusedSampleIsCountedAndTheReadingKept) {
  RealismConfig r = noiseless_sensors();
  Rig rig(r, r.extra_sensors);
  rig.plant.publish_outputs(0);
  rig.node.step(0, 0.02);
  const sensors::MagnetometerSample before = rig.node.observation().sensors.get<MagnetometerKind>()->sample;
  std::vector<std::string> log;
  rig.node.set_log([&](const std::string& line) { log.push_back(line); });

  Publisher<msg::MagneticField> stranger = rig.bus.advertise<msg::MagneticField>("/drone/MagneticField");
  msg::MagneticField m;
  m.header.stamp = msg::Time::from_ns(10'000'000);
  m.magnetic_field = {std::nan(""), 1e-5, 0.0};
  stranger.publish(m);
  // A fix whose latitude is NaN is refused too (with a fix the numbers must be numbers).
  Publisher<msg::NavSatFix> fix = rig.bus.advertise<msg::NavSatFix>("/drone/NavSatFix");
  Publisher<msg::TwistStamped> vel = rig.bus.advertise<msg::TwistStamped>("/drone/NavSatVelocity");
  msg::NavSatFix f;
  f.header.stamp = msg::Time::from_ns(100'000'000);
  f.status.status = msg::NavSatStatus::kStatusFix;
  f.latitude = std::nan("");
  msg::TwistStamped v;
  v.header.stamp = f.header.stamp;
  fix.publish(f);
  vel.publish(v);

  rig.node.step(20'000'000, 0.02);
  const control::Observation& o = rig.node.observation();
  EXPECT_EQ(o.sensors.get<MagnetometerKind>()->stamp_ns, 0);
  EXPECT_EQ(o.sensors.get<MagnetometerKind>()->sample.field_B_T, before.field_B_T);
  EXPECT_EQ(o.sensors.get<GnssKind>()->stamp_ns, 0);
  EXPECT_EQ(rig.node.core().rejected(SensorFault::kNonFinite), 2u);
  ASSERT_EQ(log.size(), 1u);  // 1st of a reason logged, then every 100th
  EXPECT_NE(log[0].find("magnetometer field (nan, 1e-05, 0): expected finite values"), std::string::npos) << log[0];
}

TEST(ControllerSensorsTest, ALockstepControllerWaitsForTheSamplesDueAtItsTick) {
  RealismConfig r = noiseless_sensors();
  Rig rig(r, r.extra_sensors);
  std::vector<msg::Float64MultiArray> commands;
  rig.bus.subscribe<msg::Float64MultiArray>("/drone/motor_commands",
                                            [&](const msg::Float64MultiArray& m) { commands.push_back(m); });
  LockstepStepper stepper(rig.node, {}, TickClock{}, 2);
  // Tick 0 from the plant: every sensor is due and published, so the controller steps.
  rig.plant.publish_outputs(0);
  ASSERT_EQ(commands.size(), 1u);

  // Tick 10 by hand: Pose, Velocity, Imu, the magnetometer and barometer, and the GNSS fix, but not yet
  // the GNSS velocity: the GNSS sample of tick 10 is not whole, no step.
  const msg::Time t10 = msg::Time::from_ns(100'000'000);
  msg::PoseStamped p;
  p.header.stamp = t10;
  p.orientation.w = 1.0;
  msg::TwistStamped tw;
  tw.header.stamp = t10;
  msg::Imu imu;
  imu.header.stamp = t10;
  imu.orientation.w = 1.0;
  msg::MagneticField mag;
  mag.header.stamp = t10;
  msg::FluidPressure baro;
  baro.header.stamp = t10;
  baro.fluid_pressure = 95000.0;
  msg::NavSatFix fix;
  fix.header.stamp = t10;
  fix.status.status = msg::NavSatStatus::kStatusNoFix;
  msg::TwistStamped gnss_v;
  gnss_v.header.stamp = t10;
  const auto publish_pose_velocity_imu_magnetometer = [&] {
    rig.bus.advertise<msg::PoseStamped>("/drone/Pose").publish(p);
    rig.bus.advertise<msg::TwistStamped>("/drone/Velocity").publish(tw);
    rig.bus.advertise<msg::Imu>("/drone/Imu").publish(imu);
    rig.bus.advertise<msg::MagneticField>("/drone/MagneticField").publish(mag);
  };
  publish_pose_velocity_imu_magnetometer();
  rig.bus.advertise<msg::FluidPressure>("/drone/FluidPressure").publish(baro);
  rig.bus.advertise<msg::NavSatFix>("/drone/NavSatFix").publish(fix);
  EXPECT_EQ(commands.size(), 1u);
  rig.bus.advertise<msg::TwistStamped>("/drone/NavSatVelocity").publish(gnss_v);
  ASSERT_EQ(commands.size(), 2u);
  EXPECT_EQ(commands[1].dim.at(0).label, "rotors@100000000");
  EXPECT_EQ(rig.node.observation().sensors.get<BarometerKind>()->sample.pressure_Pa, 95000.0);

  // Tick 12: the GNSS is not due (10 Hz), the magnetometer and barometer are: without the barometer's
  // sample no step, with it one.
  const msg::Time t12 = msg::Time::from_ns(120'000'000);
  p.header.stamp = tw.header.stamp = imu.header.stamp = mag.header.stamp = baro.header.stamp = t12;
  publish_pose_velocity_imu_magnetometer();
  EXPECT_EQ(commands.size(), 2u);
  rig.bus.advertise<msg::FluidPressure>("/drone/FluidPressure").publish(baro);
  EXPECT_EQ(commands.size(), 3u);
}

TEST(ControllerSensorsTest, WhatAControllerReadsIsWhatTheMessagesCarry) {
  // as_read (Batch's path, no bus) against fill + read by hand: the same numbers.
  sensors::GnssConfig g;
  sensors::GnssSample s;
  s.fix = true;
  s.position = {0.8, 0.15, 500.0};
  s.velocity_W = {1.0, -2.0, 0.5};
  s.position_variance_enu = {0.64, 0.64, 2.25};
  s.velocity_variance = 0.0025;
  const sensors::GnssSample read = as_read<GnssKind>(s, g);
  sensor_wire::Gnss::Messages m;
  sensor_wire::Gnss::fill(s, msg::Time{}, m);
  EXPECT_EQ(std::get<0>(m).latitude, 0.8 * (180.0 / std::numbers::pi));
  EXPECT_EQ(read.position.latitude_rad, std::get<0>(m).latitude / (180.0 / std::numbers::pi));
  EXPECT_NEAR(read.position.latitude_rad, 0.8, 1e-16);
  EXPECT_EQ(read.position.height_m, 500.0);
  EXPECT_EQ(read.velocity_W, s.velocity_W);
  EXPECT_EQ(read.position_variance_enu, s.position_variance_enu);
  EXPECT_TRUE(read.fix);
  EXPECT_TRUE(std::isnan(read.velocity_variance));

  sensors::BarometerConfig b;
  b.sea_level_pressure_Pa = 100000.0;
  sensors::BarometerSample bs;
  bs.pressure_Pa = 95000.0;
  const sensors::BarometerSample br = as_read<BarometerKind>(bs, b);
  EXPECT_EQ(br.pressure_Pa, 95000.0);
  // The ISA troposphere by hand: h = T0 / L (1 - (p / p0)^(R L / (g0 M))).
  const double exponent = 8.31446 * 0.0065 / (9.80665 * 0.0289644);
  EXPECT_NEAR(br.altitude_m, 288.15 / 0.0065 * (1.0 - std::pow(0.95, exponent)), 1e-2);
}

}  // namespace
}  // namespace quadcosim::sim
