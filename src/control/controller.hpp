// The interface every flight controller implements (docs/controllers.md). A controller is a step
// function with explicit state: from what the sensors observed and what the vehicle is asked to do
// (the reference), over one control period, to one rotor speed command per rotor and the figures it wants
// recorded. It declares its parameters in a table (name, unit, range, meaning), which become the
// ROS 2 parameters of the controller node, the keys of a scenario's `controller:` section and the
// sweepable `controller.*` keys. The node around it (sim::ControllerNode) keeps the latest sensor
// samples, applies the stale-data safety of Algorithm 1 for every controller, evaluates the reference
// and publishes the command and status; a controller never sees stale or non-finite observations.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "control/command_level.hpp"
#include "control/parameters.hpp"
#include "model/rotor_vector.hpp"
#include "sensors/readings.hpp"

namespace quadcosim::model {
class Quadrotor;
}

namespace quadcosim::control {

enum class Mode {
  kAttitude,  ///< roll, pitch, yaw setpoints + altitude hold (the paper's tests)
  kPosition,  ///< position, velocity, acceleration, jerk and yaw to follow (steps and trajectories)
};

/// What the controller observes: the latest measurements the node took from its sensor topics, as
/// received (no filtering: not an estimate), and how old they are.
struct Observation {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();               ///< [m], from Pose
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();               ///< [m/s], from Velocity
  Eigen::Quaterniond q_WB = Eigen::Quaterniond::Identity();    ///< attitude body -> world, from the Imu
  double roll_rad = 0.0, pitch_rad = 0.0, yaw_rad = 0.0;       ///< Z-Y-X angles of q_WB
  Eigen::Vector3d w_B = Eigen::Vector3d::Zero();               ///< body rates [rad/s], from the Imu
  Eigen::Vector3d specific_force_B = Eigen::Vector3d::Zero();  ///< accelerometer [m/s^2], from the Imu
  /// Header stamps [ns] (simulated time) of the samples above; -1 for a topic never received.
  std::int64_t pose_stamp_ns = -1, velocity_stamp_ns = -1, imu_stamp_ns = -1;
  /// Age of the oldest of the inputs above [s]; +inf when any input never arrived.
  double age_s = std::numeric_limits<double>::infinity();
  /// The extra sensors the vehicle carries (magnetometer, barometer, GNSS: the scenario's `sensors:`),
  /// each its newest sample and stamp: `sensors.get<sensors::GnssKind>()`, null for one not carried.
  /// They are not part of age_s or the stale-data safety: each has its own rate (a 10 Hz GNSS), and a
  /// controller that uses one judges its stamp (docs/sensors.md, "In the controller").
  sensors::Readings sensors;
};

/// What the vehicle is asked to do at this step: a flat-output setpoint (position and its first three
/// derivatives, yaw and yaw rate) for position mode, plus the paper's attitude setpoints for attitude
/// mode (with z for its altitude hold). A step setpoint has zero derivatives; a trajectory fills them.
struct Reference {
  Mode mode = Mode::kAttitude;
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< [m]; in attitude mode only z is held
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();  ///< [m/s]
  Eigen::Vector3d a_W = Eigen::Vector3d::Zero();  ///< [m/s^2]
  Eigen::Vector3d j_W = Eigen::Vector3d::Zero();  ///< jerk [m/s^3]
  double yaw_rad = 0.0;
  double yaw_rate_rad_s = 0.0;
  double roll_rad = 0.0;   ///< attitude mode
  double pitch_rad = 0.0;  ///< attitude mode
};

/// Everything one step decided. The node publishes omega_rad_s as the motor command and the rest in
/// the controller's status (quadcosim_msgs/ControllerStatus). A controller that commands at a level
/// above rotor speeds (control/command_level.hpp) sets `level` and `setpoint`: the node then publishes
/// the setpoint at that level, and the plant's inner loops (control/inner_loops.hpp) turn it into rotor
/// speeds on every plant tick; omega_rad_s is then not sent.
struct ControllerOutput {
  /// Rotor speed commands [rad/s], one per rotor of the vehicle (4, 6 or 8 ...).
  model::RotorVector omega_rad_s = model::RotorVector::Zero(4);
  /// The level commanded; rotor speeds (omega_rad_s) unless the controller says otherwise.
  CommandLevel level = CommandLevel::kRotorSpeeds;
  Eigen::Vector4d setpoint = Eigen::Vector4d::Zero();  ///< the values of `level` (not rotor speeds)
  Eigen::Vector4d U = Eigen::Vector4d::Zero();         ///< requested U1 [N], U2..U4 [N m]
  /// The attitude actually tracked (Z-Y-X angles of the desired attitude R_d) [rad]. In attitude mode
  /// a controller reports the reference's roll and pitch here.
  double roll_des_rad = 0.0, pitch_des_rad = 0.0, yaw_des_rad = 0.0;
  /// Psi = 1/2 tr(I - R_d^T R) in [0, 2], for a controller that has a desired attitude R_d; NaN if not.
  double attitude_error = std::numeric_limits<double>::quiet_NaN();
  model::RotorFlags rotor_saturated;  ///< the allocation clamped rotor i at omega_min or omega_max
  bool tilt_saturated = false;        ///< a tilt limit cut the commanded attitude
  bool safety = false;                ///< set by the node: the stale-data safety command was sent
  /// The controller's own figures, in the order of Controller::output_names() (sized by the node).
  std::vector<double> outputs;
};

/// One parameter assignment, as from a scenario file, a schedule or `ros2 param set`.
struct Setting {
  std::string name;
  ParameterValue value;
};

/// A controller's step failed: it threw (a Python controller that raised or returned garbage, an FMU
/// whose step failed, a controller process that crashed). The message is the controller's own: it names
/// the controller, the step and its time. Every command exits 5 for it (app/exit_codes.hpp).
class ControllerFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Controller {
 public:
  virtual ~Controller() = default;

  /// The registry name of its type ("paper", "se3", ...).
  virtual std::string_view type() const = 0;
  /// True for a controller whose step can block or run long in ways its host cannot bound (one written
  /// in Python: the interpreter's lock, a step that never returns). A host whose thread also serves
  /// other work (DDS discovery, parameter services, a stop) then runs it on a thread of its own
  /// (sim::ControllerNode::run_controller_on_thread). Compiled controllers step in bounded time.
  virtual bool wants_own_thread() const { return false; }
  /// A copy with the same parameters and state (each node flies its own copy of a configured one).
  virtual std::unique_ptr<Controller> clone() const = 0;

  /// The declared parameter table, in a stable documented order.
  virtual std::span<const ParameterSpec> parameters() const = 0;
  /// The current value of a declared parameter, or nothing for an unknown name.
  virtual std::optional<ParameterValue> get_parameter(std::string_view name) const = 0;
  /// Checks and applies the settings together (all or nothing: a gain change and the design it needs
  /// happen once). Returns "" on success, else why the first refused one was refused, naming it; then
  /// nothing changed. Internal state (integrators) is kept.
  virtual std::string set_parameters(std::span<const Setting> settings) = 0;

  /// Names of the figures step() writes into ControllerOutput::outputs ("error.z", ...).
  virtual std::span<const std::string> output_names() const = 0;

  /// Clears internal state (integrators, filters), as after a restart.
  virtual void reset() = 0;

  /// One control period of dt_s [s]. The observation is finite and fresh (the node checked it);
  /// `out.outputs` has output_names().size() entries. Writes every field of `out` except safety.
  virtual void step(const Observation& observation, const Reference& reference, double dt_s, ControllerOutput& out) = 0;
};

/// The parameter plumbing of a controller whose parameters live in one struct P, declared by a
/// ParameterTable<P>: clone, parameters, get_parameter and set_parameters (all-or-nothing, one
/// configure() per call). Derived implements table(), configure() and the rest of Controller.
template <class Derived, class P>
class ControllerWith : public Controller {
 public:
  std::unique_ptr<Controller> clone() const override {
    return std::make_unique<Derived>(static_cast<const Derived&>(*this));
  }
  std::span<const ParameterSpec> parameters() const override { return table().specs(); }
  std::optional<ParameterValue> get_parameter(std::string_view name) const override {
    return table().get(params_, name);
  }
  std::string set_parameters(std::span<const Setting> settings) override {
    P next = params_;
    for (const Setting& s : settings) {
      if (std::string err = table().set(next, s.name, s.value); !err.empty()) return err;
    }
    try {
      configure(next);
    } catch (const std::exception& e) {
      std::string names;
      for (const Setting& s : settings) names += (names.empty() ? "" : ", ") + s.name;
      return names + ": " + e.what();
    }
    params_ = next;
    return {};
  }
  const P& params() const { return params_; }

 protected:
  explicit ControllerWith(const P& params) : params_(params) {}
  /// The declared table.
  virtual const ParameterTable<P>& table() const = 0;
  /// Takes parameters that passed the table's checks (designs gains from them); throws to refuse,
  /// leaving the controller unchanged. params() still holds the previous values during the call.
  virtual void configure(const P& next) = 0;

 private:
  P params_;
};

/// The outputs a controller that decides only rotor speeds (a Python class, an FMU) may declare to say
/// what it does (docs/controllers.md): "roll_des", "pitch_des", "yaw_des" [rad], the attitude it tracks,
/// and "tilt_saturated" (non-zero while its tilt limit acts). Their places among its output names, -1 for
/// one it does not declare; found once, read every step.
struct ReportedOutputs {
  static constexpr std::string_view kRollDes = "roll_des", kPitchDes = "pitch_des", kYawDes = "yaw_des",
                                    kTiltSaturated = "tilt_saturated";
  static ReportedOutputs find(std::span<const std::string> output_names);
  int roll_des = -1, pitch_des = -1, yaw_des = -1, tilt_saturated = -1;
};

/// The output of a controller that decides only rotor speeds (an FMU, a Python class): `omega_rad_s`, U
/// = the wrench those speeds make on `model` (eq. (4)), attitude_error NaN. The tracked attitude is the
/// one the controller reports in `out.outputs` (ReportedOutputs); else the reference's in attitude mode
/// and its yaw in position mode, with roll and pitch NaN there (unknown, not 0). A rotor is saturated
/// when its command is at or beyond the vehicle's speed limits (omega_min, omega_max); the tilt flag is
/// the reported one, else false. Leaves `out.outputs` as it is.
void rotor_speeds_output(const model::Quadrotor& model, const Reference& reference,
                         const model::RotorVector& omega_rad_s, const ReportedOutputs& reported, ControllerOutput& out);

/// Psi = 1/2 tr(I - R_d^T R), the attitude error of Lee, Leok and McClamroch (2010), in [0, 2]:
/// 1 - cos(angle of the rotation between them).
double attitude_error(const Eigen::Quaterniond& q_des, const Eigen::Quaterniond& q);

const char* to_string(Mode mode);

}  // namespace quadcosim::control
