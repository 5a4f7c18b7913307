// The plant FMU against sim::PlantNode itself, the plant of every quadcosim run: with drag, wind,
// gusts, a rotor fault and sensor noise, rates and latencies, the FMU's outputs after each 0.02 s
// step are the node's published sensor messages of that tick, bit for bit; with a magnetometer, a
// barometer and a GNSS receiver, their outputs are the node's MagneticField, FluidPressure, NavSatFix
// and NavSatVelocity messages of that tick.
#include <cmath>
#include <cstring>
#include <numbers>

#include "fmi/export/fmu_test_support.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "sensors/barometer.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"

namespace quadcosim::fmi::test {
namespace {

sim::RealismConfig rough_air() {
  sim::RealismConfig r;
  r.seed = 42;
  r.imu.timing = {2, 1};
  r.imu.gyro_noise_density = 0.002;
  r.imu.gyro_bias_random_walk = 1e-4;
  r.imu.accel_noise_density = 0.02;
  r.imu.accel_bias_initial = 0.05;
  r.imu.orientation_sigma_rad = 0.01;
  r.pose.timing = {5, 3};
  r.pose.position_sigma_m = 0.02;
  r.pose.orientation_sigma_rad = 0.01;
  r.velocity.linear_sigma_m_s = 0.05;
  r.velocity.angular_sigma_rad_s = 0.01;
  r.wind.mean_W_m_s = {2.0, -1.0, 0.0};
  r.wind.gusts.enabled = true;
  r.faults.push_back({150, 2, 0.8});
  return r;
}

/// Runs the FMU and a PlantNode side by side for 3 s under the same commands and compares, after
/// every FMU step, its outputs with what the node last published.
void compare_with_plant_node(FmuConfig c, bool sensor_noise) {
  c.vehicle.aero.linear_drag_N_s_m = {0.1, 0.1, 0.2};
  c.vehicle.motor.model = model::MotorModel::kFirstOrder;
  c.initial.p_W = {0.0, 0.0, 2.0};
  c.initial.omega_rad_s.setConstant(c.vehicle.hover_omega_rad_s());
  c.guid = make_guid(c);

  sim::InProcessTransport transport;
  const sim::Topics topics = sim::Topics::for_namespace(c.realism_namespace);
  sim::PlantOptions o;
  o.clock = {c.plant_period_ns};
  o.substeps = c.substeps;
  o.watchdog_ticks = 0;
  o.realism = c.realism;
  if (!sensor_noise) o.realism.imu = {}, o.realism.pose = {}, o.realism.velocity = {};
  sim::PlantNode node(transport, topics, c.vehicle, o, c.initial);
  node.set_log([](const std::string&) {});
  msg::PoseStamped pose;
  msg::TwistStamped twist;
  msg::Imu imu;
  transport.subscribe<msg::PoseStamped>(topics.pose, [&](const msg::PoseStamped& m) { pose = m; });
  transport.subscribe<msg::TwistStamped>(topics.velocity, [&](const msg::TwistStamped& m) { twist = m; });
  transport.subscribe<msg::Imu>(topics.imu, [&](const msg::Imu& m) { imu = m; });
  msg::MagneticField mag;
  msg::FluidPressure baro;
  msg::NavSatFix fix;
  msg::TwistStamped gnss_v;
  const std::string& ns = c.realism_namespace;
  transport.subscribe<msg::MagneticField>(ns + "/MagneticField", [&](const msg::MagneticField& m) { mag = m; });
  transport.subscribe<msg::FluidPressure>(ns + "/FluidPressure", [&](const msg::FluidPressure& m) { baro = m; });
  transport.subscribe<msg::NavSatFix>(ns + "/NavSatFix", [&](const msg::NavSatFix& m) { fix = m; });
  transport.subscribe<msg::TwistStamped>(ns + "/NavSatVelocity", [&](const msg::TwistStamped& m) { gnss_v = m; });
  const bool extra = c.realism.extra_sensors.any();
  auto commands = transport.advertise<msg::Float64MultiArray>(topics.motor_commands);

  Fmi2Instance plant("plant", c);
  const fmi2Component fmu = plant.c_;
  const Log& log = plant.log_;
  ASSERT_EQ(plant.set_boolean("realism.sensor_noise", sensor_noise), fmi2OK) << log.last();
  ASSERT_NO_FATAL_FAILURE(plant.init());

  std::vector<fmi2ValueReference> outputs, cmd_vrs;
  for (auto names : {names::kPosition, names::kVelocity, names::kRates, names::kSpecificForce}) {
    for (auto n : names) outputs.push_back(vr_of(c, n));
  }
  for (auto n : names::kAttitude) outputs.push_back(vr_of(c, n));
  const int rotors = c.vehicle.rotor_count;
  for (auto n : names::rotor_speed(rotors)) outputs.push_back(vr_of(c, n));
  for (auto n : names::omega_cmd(rotors)) cmd_vrs.push_back(vr_of(c, n));
  if (extra) {
    for (const char* n : {"magnetometer.field[1]", "magnetometer.field[2]", "magnetometer.field[3]",
                          "barometer.pressure", "barometer.altitude", "gnss.fix", "gnss.latitude_deg",
                          "gnss.longitude_deg", "gnss.altitude_m", "gnss.v[1]", "gnss.v[2]", "gnss.v[3]"}) {
      outputs.push_back(vr_of(c, n));
    }
  }

  const double hover = c.vehicle.hover_omega_rad_s();
  for (sim::Tick k = 0; k <= 300; ++k) {
    node.publish_outputs(k);
    if (k % 2 == 0) {
      std::vector<double> got(outputs.size());
      ASSERT_EQ(QC_FMI(fmi2GetReal)(fmu, outputs.data(), outputs.size(), got.data()), fmi2OK) << log.last();
      const auto& s = node.state().omega_rad_s;
      std::vector<double> want = {pose.position.x,
                                  pose.position.y,
                                  pose.position.z,
                                  twist.linear.x,
                                  twist.linear.y,
                                  twist.linear.z,
                                  imu.angular_velocity.x,
                                  imu.angular_velocity.y,
                                  imu.angular_velocity.z,
                                  imu.linear_acceleration.x,
                                  imu.linear_acceleration.y,
                                  imu.linear_acceleration.z,
                                  imu.orientation.w,
                                  imu.orientation.x,
                                  imu.orientation.y,
                                  imu.orientation.z};
      want.insert(want.end(), s.data(), s.data() + s.size());
      if (extra) {  // the messages' fields, in the messages' units (degrees), the altitude by the ISA
        const double p0 = c.realism.extra_sensors.barometer->sea_level_pressure_Pa;
        for (const double x : {mag.magnetic_field.x, mag.magnetic_field.y, mag.magnetic_field.z, baro.fluid_pressure,
                               sensors::isa_pressure_altitude(baro.fluid_pressure, p0),
                               fix.status.status >= msg::NavSatStatus::kStatusFix ? 1.0 : 0.0, fix.latitude,
                               fix.longitude, fix.altitude, gnss_v.linear.x, gnss_v.linear.y, gnss_v.linear.z}) {
          want.push_back(x);
        }
        if (k == 60) {
          EXPECT_TRUE(std::isnan(got[want.size() - 5])) << "no GNSS fix before fix_after_s";
        }
        if (k == 300) {
          EXPECT_EQ(got[want.size() - 7], 1.0) << "a GNSS fix by the end";
        }
      }
      for (std::size_t i = 0; i < want.size(); ++i) {
        if (std::isnan(got[i]) && std::isnan(want[i])) continue;  // a GNSS without a fix
        ASSERT_EQ(std::memcmp(&got[i], &want[i], sizeof(double)), 0)
            << "output " << i << " at tick " << k << ": " << got[i] << " vs " << want[i];
      }
      // The next command, to both: a slow wobble around hover, on every other rotor.
      const double w = hover * (1.0 + 0.01 * std::sin(0.05 * static_cast<double>(k)));
      std::vector<double> cmd;
      for (int i = 0; i < rotors; ++i) cmd.push_back(i % 2 == 0 ? w : hover);
      commands.publish(msg::Float64MultiArray{cmd, {}, 0});
      ASSERT_EQ(QC_FMI(fmi2SetReal)(fmu, cmd_vrs.data(), cmd.size(), cmd.data()), fmi2OK);
      if (k < 300) {
        ASSERT_EQ(QC_FMI(fmi2DoStep)(fmu, o.clock.seconds(k), 0.02, fmi2True), fmi2OK) << log.last();
      }
    }
    node.latch_command(k);
    node.integrate(k);
  }
  EXPECT_GT(std::abs(node.state().p_W.x()), 0.01);  // the wind moved it
}

TEST(FmuPlantNode, SensorNoiseLeftToTheMasterKeepsTheTrueStateOfANoisyNode) {
  // What a quadcosim run with the FMU as its plant does when the scenario has sensor noise: the node
  // adds the noise, the FMU (realism.sensor_noise off) reports the truth, which must be the native
  // node's state bit for bit.
  FmuConfig c = config_for(FmuKind::kPlant);
  c.realism.seed = 3;
  c.realism.imu.gyro_noise_density = 0.01;
  c.realism.pose.position_sigma_m = 0.1;
  c.initial.p_W = {0.0, 0.0, 1.0};
  c.initial.omega_rad_s.setConstant(c.vehicle.hover_omega_rad_s() * 1.01);
  c.guid = make_guid(c);

  sim::InProcessTransport transport;
  const sim::Topics topics = sim::Topics::for_namespace(c.realism_namespace);
  sim::PlantOptions o;
  o.watchdog_ticks = 0;
  o.realism = c.realism;
  sim::PlantNode node(transport, topics, c.vehicle, o, c.initial);

  Fmi2Instance plant("plant", c);
  const fmi2Component fmu = plant.c_;
  const Log& log = plant.log_;
  ASSERT_EQ(plant.set_boolean("realism.sensor_noise", false), fmi2OK) << log.last();
  ASSERT_NO_FATAL_FAILURE(plant.init(/*setup_experiment=*/false));
  std::vector<fmi2ValueReference> vrs;
  for (auto names : {names::kPosition, names::kVelocity, names::kRates}) {
    for (auto n : names) vrs.push_back(vr_of(c, n));
  }
  for (auto n : names::kAttitude) vrs.push_back(vr_of(c, n));
  for (sim::Tick k = 0; k <= 200; ++k) {
    node.publish_outputs(k);
    if (k % 2 == 0) {
      std::vector<double> got(vrs.size());
      ASSERT_EQ(QC_FMI(fmi2GetReal)(fmu, vrs.data(), vrs.size(), got.data()), fmi2OK);
      const model::State& x = node.state();
      const std::vector<double> want = {x.p_W.x(), x.p_W.y(), x.p_W.z(),  x.v_W.x(),  x.v_W.y(),  x.v_W.z(), x.w_B.x(),
                                        x.w_B.y(), x.w_B.z(), x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z()};
      for (std::size_t i = 0; i < want.size(); ++i) {
        ASSERT_EQ(std::memcmp(&got[i], &want[i], sizeof(double)), 0) << "output " << i << " at tick " << k;
      }
      if (k < 200) {
        ASSERT_EQ(QC_FMI(fmi2DoStep)(fmu, o.clock.seconds(k), 0.02, fmi2True), fmi2OK) << log.last();
      }
    }
    node.latch_command(k);
    node.integrate(k);
  }
  EXPECT_GT(node.state().p_W.z(), 1.1);  // it climbed on the initial speeds
}

TEST(FmuPlantNode, WindGustsFaultsAndDragGiveThePlantNodesNumbers) {
  FmuConfig c = config_for(FmuKind::kPlant);
  c.realism = rough_air();
  compare_with_plant_node(c, /*sensor_noise=*/false);
}

TEST(FmuPlantNode, AHexarotorInWindGustsAFaultAndSensorNoiseGivesThePlantNodesNumbers) {
  FmuConfig c = config_for(FmuKind::kPlant);
  c.vehicle.set_layout(model::RotorLayout::kHexX);
  c.initial.omega_rad_s = model::RotorVector::Zero(6);
  c.realism = rough_air();
  c.realism.faults.push_back({90, 5, 0.7});  // the sixth rotor, which a quadrotor's FMU does not have
  compare_with_plant_node(c, /*sensor_noise=*/true);
}

TEST(FmuPlantNode, WithSensorNoiseTheOutputsAreThePublishedSamples) {
  FmuConfig c = config_for(FmuKind::kPlant);
  c.realism = rough_air();
  compare_with_plant_node(c, /*sensor_noise=*/true);
}

TEST(FmuPlantNode, TheMagnetometerBarometerAndGnssOutputsAreThePublishedSamples) {
  // Each at a rate of its own (the barometer's off the FMU's 0.02 s steps: its samples inside a step
  // are drawn too), the GNSS 50 ms late and without a fix for its first 0.8 s.
  FmuConfig c = config_for(FmuKind::kPlant);
  c.realism = rough_air();
  auto& e = c.realism.extra_sensors;
  e.magnetometer.emplace();
  e.magnetometer->noise_sigma_T = 0.3e-6;
  e.magnetometer->hard_iron_T = {1e-6, -2e-6, 0.5e-6};
  e.barometer.emplace();
  e.barometer->timing = {3, 0};
  e.barometer->site_altitude_m = 488.0;
  e.barometer->noise_sigma_Pa = 1.2;
  e.barometer->drift_Pa_sqrt_s = 0.1;
  e.barometer->bias_initial_Pa = 20.0;
  e.gnss.emplace();
  e.gnss->timing = {10, 5};
  e.gnss->site = {47.397742 * std::numbers::pi / 180.0, 8.545594 * std::numbers::pi / 180.0, 535.0};
  e.gnss->horizontal_sigma_m = 0.8;
  e.gnss->vertical_sigma_m = 1.5;
  e.gnss->velocity_sigma_m_s = 0.05;
  e.gnss->fix_after_s = 0.8;
  compare_with_plant_node(c, /*sensor_noise=*/true);
}

}  // namespace
}  // namespace quadcosim::fmi::test
