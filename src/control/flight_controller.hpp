// The paper's hierarchical flight controller (Algorithm 1) as one step function with explicit state:
// stale-data safety, LQR attitude, PD altitude, PID position (position mode), allocation.
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>

#include "control/allocation.hpp"
#include "control/altitude_pd.hpp"
#include "control/attitude_lqr.hpp"
#include "control/position_pid.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::control {

enum class Mode {
  kAttitude,  ///< roll, pitch, yaw setpoints + altitude hold (the paper's tests)
  kPosition,  ///< x, y, z, yaw setpoints; the position PID sets roll and pitch
};

/// What the controller commands when its sensor data is stale or missing (Algorithm 1, lines 3-5).
enum class SafetyMode {
  kStop,   ///< all rotors to omega_min (default: a vehicle on the ground stays there)
  kHover,  ///< all rotors at the nominal hover speed (level, uncontrolled)
};

struct Setpoint {
  Mode mode = Mode::kAttitude;
  Eigen::Vector3d p_des_W = Eigen::Vector3d::Zero();  ///< [m]; x, y used in position mode
  double roll_des_rad = 0.0;                          ///< used in attitude mode
  double pitch_des_rad = 0.0;                         ///< used in attitude mode
  double yaw_des_rad = 0.0;
};

struct ControllerParams {
  /// The controller's knowledge of the vehicle: mass, g, inertia (LQR design), mixer, motor limits.
  model::VehicleParams vehicle;
  LqrWeights roll{1.3, 2.4, 100.0};
  LqrWeights pitch{1.3, 2.4, 100.0};
  LqrWeights yaw{0.16, 0.65, 100.0};
  AltitudeGains altitude;
  PositionGains position;
  double stale_limit_s = 0.1;  ///< sensor data older than this triggers the safety command [s]
  SafetyMode safety = SafetyMode::kStop;
};

/// What the controller observes: the latest measurements the node took from its sensor topics, as
/// received (no filtering: not an estimate), and how old they are.
struct Observation {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();          ///< [m], from Pose
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();          ///< [m/s], from Velocity
  double roll_rad = 0.0, pitch_rad = 0.0, yaw_rad = 0.0;  ///< from the IMU quaternion
  Eigen::Vector3d w_B = Eigen::Vector3d::Zero();          ///< body rates [rad/s], from the IMU
  /// Age of the oldest of the inputs above [s]; +inf when any input never arrived.
  double age_s = std::numeric_limits<double>::infinity();
};

/// Everything one step decided, for the command topic and the controller's status.
struct ControllerOutput {
  Eigen::Vector4d omega_rad_s = Eigen::Vector4d::Zero();              ///< rotor speed commands [rad/s]
  Eigen::Vector4d U = Eigen::Vector4d::Zero();                        ///< requested U1 [N], U2..U4 [N m]
  double roll_des_rad = 0.0, pitch_des_rad = 0.0, yaw_des_rad = 0.0;  ///< attitude actually tracked
  Eigen::Vector4d error = Eigen::Vector4d::Zero();                    ///< e_z [m], e_roll, e_pitch, e_yaw [rad]
  std::array<bool, 4> rotor_saturated{};
  bool tilt_saturated = false;
  bool safety = false;  ///< the stale-data safety command was sent
};

class FlightController {
 public:
  /// Designs the three LQR axes from the params; throws CareError if a design has no solution.
  explicit FlightController(const ControllerParams& params);

  /// Replaces gains and weights between steps (re-solves the LQR); the integrator state is kept.
  void set_params(const ControllerParams& params);
  const ControllerParams& params() const { return params_; }
  const AxisLqr& axis(int i) const { return axes_[i]; }  ///< 0 roll, 1 pitch, 2 yaw

  /// One control period. dt_s is the controller period [s].
  ControllerOutput step(const Observation& observation, const Setpoint& setpoint, double dt_s);

  /// Clears the integrators (e.g. after a restart).
  void reset() { position_state_ = {}; }
  const PositionPidState& position_state() const { return position_state_; }

 private:
  ControllerOutput safety_command() const;

  ControllerParams params_;
  std::array<AxisLqr, 3> axes_;
  Eigen::Matrix4d mixer_inverse_;
  PositionPidState position_state_;
};

const char* to_string(Mode mode);
const char* to_string(SafetyMode mode);

}  // namespace quadcosim::control
