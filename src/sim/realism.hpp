// What makes the simulated flight less ideal than the paper's: sensor noise, rates and latency;
// wind and gusts; rotor failures. The plant node owns one PlantRealism when any of it is configured
// (or the vehicle has aerodynamic drag); without one the plant is exactly the paper's.
//
// Randomness: every source draws from its own stream, seeded by model::stream_seed(seed, namespace,
// source name) (model/random.hpp), so adding a source never changes another's numbers.
// Determinism over DDS: a tick's sensor sample is drawn once; publishing the same tick again (a
// lockstep repeat) publishes the same sample. Nothing here allocates per tick.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "model/quadrotor.hpp"
#include "model/sensor_noise.hpp"
#include "model/wind.hpp"
#include "sensors/sensor_set.hpp"
#include "sensors/timing.hpp"
#include "sim/clock.hpp"
#include "sim/messages.hpp"

namespace quadcosim::sim {

/// When a sensor samples and how old its sample is when published (sensors/timing.hpp).
using SensorTiming = sensors::Timing;

struct ImuConfig {
  SensorTiming timing;
  double gyro_noise_density = 0.0;      ///< [rad/s/√Hz]
  double gyro_bias_random_walk = 0.0;   ///< [rad/s²/√Hz] (= rad/s/√s)
  double gyro_bias_initial = 0.0;       ///< turn-on bias sigma [rad/s]
  double accel_noise_density = 0.0;     ///< [m/s²/√Hz]
  double accel_bias_random_walk = 0.0;  ///< [m/s³/√Hz]
  double accel_bias_initial = 0.0;      ///< turn-on bias sigma [m/s²]
  double orientation_sigma_rad = 0.0;   ///< attitude estimate noise per axis [rad]
};

struct PoseConfig {
  SensorTiming timing;
  double position_sigma_m = 0.0;       ///< per axis [m]
  double orientation_sigma_rad = 0.0;  ///< per axis [rad]
};

struct VelocityConfig {
  SensorTiming timing;
  double linear_sigma_m_s = 0.0;     ///< per axis [m/s]
  double angular_sigma_rad_s = 0.0;  ///< per axis [rad/s]
};

/// From tick `tick` on, rotor `rotor` (0-based) gives `efficiency` times its nominal thrust and drag
/// torque (0: failed).
struct RotorFault {
  Tick tick = 0;
  int rotor = 0;
  double efficiency = 1.0;
};

struct RealismConfig {
  std::uint64_t seed = 0;
  ImuConfig imu;
  PoseConfig pose;
  VelocityConfig velocity;
  model::WindParams wind;
  std::vector<RotorFault> faults;  ///< in tick order
  /// Magnetometer, barometer, GNSS (sensors/sensor_set.hpp): each off unless configured; published
  /// by the plant's sensor channels (sim/sensor_channels.hpp), not part of active().
  sensors::SensorSet extra_sensors;

  /// True when any sensor, wind or fault setting differs from the ideal plant.
  bool active() const;
};

class PlantRealism {
 public:
  PlantRealism(const RealismConfig& config, const model::VehicleParams& vehicle, const std::string& ns,
               const TickClock& clock);

  /// The environment over tick k (wind, rotor efficiencies). Ticks are visited in order.
  const model::Environment& environment(Tick k);

  struct Due {
    bool pose, velocity, imu;
  };
  /// Records the true outputs of tick k and fills the sensor fields of the three messages (headers
  /// untouched) with the sample each sensor publishes at tick k; says which are due. Called again for
  /// the same tick, it returns the same sample (nothing new is drawn).
  Due measure(Tick k, const model::Outputs& truth, msg::PoseStamped& pose, msg::TwistStamped& twist, msg::Imu& imu);

  const RealismConfig& config() const { return config_; }
  /// The discrete per-sample standard deviations the IMU uses (for the message covariances).
  double gyro_sigma() const { return gyro_.white_sigma; }
  double accel_sigma() const { return accel_.white_sigma; }

 private:
  const model::Outputs& truth_at(Tick k) const;

  RealismConfig config_;
  model::WindField wind_;
  model::Environment env_;
  Tick env_tick_ = -1;
  std::size_t next_fault_ = 0;

  model::NoiseSpec gyro_, accel_;
  model::Vector3Noise gyro_noise_, accel_noise_, position_noise_, linear_noise_, angular_noise_;
  model::Rng imu_attitude_rng_, pose_attitude_rng_;

  std::vector<model::Outputs> history_;  ///< ring buffer of true outputs, latency + 1 deep
  Tick last_tick_ = -1;
  msg::PoseStamped pose_;
  msg::TwistStamped twist_;
  msg::Imu imu_;
  Due due_{};
};

}  // namespace quadcosim::sim
