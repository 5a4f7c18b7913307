// The plant's extra sensors on the bus: rates and latency as configured, a lockstep repeat publishes
// the same samples and draws nothing new, and a sensor's numbers do not depend on which others are on.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sensors/barometer.hpp"
#include "sim/plant_rig_test_support.hpp"

namespace quadcosim::sim {
namespace {

struct Rig : test::PlantRig {
  std::vector<msg::MagneticField> mag;
  std::vector<msg::FluidPressure> baro;
  std::vector<msg::NavSatFix> fix;
  std::vector<msg::TwistStamped> vel;
  explicit Rig(const RealismConfig& r) : PlantRig(r, PlantRig::climbing()) {
    bus.subscribe<msg::MagneticField>("/drone/MagneticField", [this](const auto& m) { mag.push_back(m); });
    bus.subscribe<msg::FluidPressure>("/drone/FluidPressure", [this](const auto& m) { baro.push_back(m); });
    bus.subscribe<msg::NavSatFix>("/drone/NavSatFix", [this](const auto& m) { fix.push_back(m); });
    bus.subscribe<msg::TwistStamped>("/drone/NavSatVelocity", [this](const auto& m) { vel.push_back(m); });
  }
};

RealismConfig all_sensors() {
  RealismConfig r;
  r.seed = 5;
  sensors::MagnetometerConfig m;
  m.noise_sigma_T = 0.5e-6;
  r.extra_sensors.magnetometer = m;
  sensors::BarometerConfig b;
  b.timing.divider = 2;  // 50 Hz
  r.extra_sensors.barometer = b;
  sensors::GnssConfig g;
  g.timing = {10, 10};  // 10 Hz, 100 ms old
  g.horizontal_sigma_m = 1.0;
  r.extra_sensors.gnss = g;
  return r;
}

TEST(SensorChannelsTest, RatesLatencyAndStamps) {
  RealismConfig r = all_sensors();
  r.extra_sensors.barometer->noise_sigma_Pa = 0.0;
  r.extra_sensors.barometer->timing.latency_ticks = 3;
  Rig rig(r);
  rig.run(200);
  EXPECT_EQ(rig.mag.size(), 200u);
  EXPECT_EQ(rig.baro.size(), 100u);
  EXPECT_EQ(rig.fix.size(), 20u);
  EXPECT_EQ(rig.vel.size(), 20u);
  EXPECT_EQ(rig.fix[3].header.stamp.to_ns(), 30 * 10'000'000LL);  // stamped at publication
  // With latency 3 the barometer's publications at ticks 0 and 2 both measure tick 0 (max(k - 3, 0)),
  // where the vehicle is at its initial 5 m: the ISA inverse of the pressure gives 5 m back,
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(sensors::isa_pressure_altitude(rig.baro[static_cast<std::size_t>(i)].fluid_pressure), 5.0, 1e-8) << i;
  }
  // and the one at tick 40 measures tick 37: 5 m + 0.37 s x 1 m/s.
  EXPECT_NEAR(sensors::isa_pressure_altitude(rig.baro[20].fluid_pressure), 5.37, 1e-6);
  EXPECT_EQ(rig.fix[0].status.status, msg::NavSatStatus::kStatusFix);
}

TEST(SensorChannelsTest, ALockstepRepeatPublishesTheSameSamples) {
  Rig once(all_sensors()), twice(all_sensors());
  once.run(100);
  twice.run(100, /*repeat_each=*/true);
  ASSERT_EQ(twice.mag.size(), 2 * once.mag.size());
  for (std::size_t k = 0; k < once.mag.size(); ++k) {
    EXPECT_EQ(once.mag[k].magnetic_field.x, twice.mag[2 * k].magnetic_field.x);
    EXPECT_EQ(twice.mag[2 * k].magnetic_field.x, twice.mag[2 * k + 1].magnetic_field.x);
  }
  for (std::size_t k = 0; k < once.fix.size(); ++k) {
    EXPECT_EQ(once.fix[k].latitude, twice.fix[2 * k].latitude);
    EXPECT_EQ(twice.fix[2 * k].latitude, twice.fix[2 * k + 1].latitude);
  }
  EXPECT_NE(once.mag[1].magnetic_field.x, once.mag[2].magnetic_field.x);  // the noise is there
}

TEST(SensorChannelsTest, ASensorsNumbersDoNotDependOnTheOthers) {
  RealismConfig only_gnss;
  only_gnss.seed = 5;
  only_gnss.extra_sensors.gnss = all_sensors().extra_sensors.gnss;
  Rig all(all_sensors()), alone(only_gnss);
  all.run(100);
  alone.run(100);
  EXPECT_TRUE(alone.mag.empty() && alone.baro.empty());
  ASSERT_EQ(all.fix.size(), alone.fix.size());
  for (std::size_t k = 0; k < all.fix.size(); ++k) {
    EXPECT_EQ(all.fix[k].latitude, alone.fix[k].latitude) << k;
    EXPECT_EQ(all.fix[k].longitude, alone.fix[k].longitude) << k;
  }
}

}  // namespace
}  // namespace quadcosim::sim
