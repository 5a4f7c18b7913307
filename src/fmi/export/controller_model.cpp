// The controller FMU: a control::Controller stepped as sim::ControllerNode steps it. Its period is
// controller_divider plant periods; doStep(t, h) with h = n periods runs n control steps of
// dt = plant period (s) * divider on the inputs as they were set before the call (held over the
// step), and the outputs after it are the command of the last of them. A master that sets the
// sensor inputs at t, steps the controller, then passes its command to the plant for [t, t + h)
// (Gauss-Seidel) flies it as a quadcosim run does. Beside the command it outputs what the last step
// tracked (roll_des, pitch_des, yaw_des, tilt_saturated) and the controller's own figures, by the names
// a controller that decides rotor speeds reports them (control::ReportedOutputs).
//
// The observation is built as the node builds it (the attitude's Z-Y-X angles from q_WB by
// model::euler_from_quaternion) and is always fresh: the node's stale-data safety has no counterpart
// here (inputs cannot be missing; a NaN input is refused when it is set).
//
// The reference: with a trajectory in the configuration (an export from a scenario that has one), the
// trajectory's flat outputs at each control step's own time, (k + i) * period for the i-th step of a
// doStep from period k, in position mode, as sim::ControllerCore computes them from the step's
// time; the ref.* inputs are then ignored unless the parameter ref.external is true, which makes them
// the reference (position mode) for the whole run. Without a trajectory, the ref.* inputs in the mode
// of the configured setpoint.
#include <cmath>
#include <optional>
#include <vector>

#include "controllers/registry.hpp"
#include "fmi/export/slave.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "model/attitude.hpp"
#include "sim/validation.hpp"

namespace quadcosim::fmi::exported {

namespace {

class ControllerModel final : public Model {
 public:
  ControllerModel(const FmuConfig& c, const ModelDescription& md)
      : period_ns_(c.plant_period_ns * c.controller_divider),
        dt_s_(sim::TickClock{c.plant_period_ns}.period_s() * c.controller_divider),  // as sim::Simulation
        mode_(c.setpoint.mode),
        p_(find_vrs(md, names::kPosition)),
        v_(find_vrs(md, names::kVelocity)),
        q_(find_vrs(md, names::kAttitude)),
        w_(find_vrs(md, names::kRates)),
        f_(find_vrs(md, names::kSpecificForce)),
        ref_p_(find_vrs(md, names::kRefPosition)),
        ref_v_(find_vrs(md, names::kRefVelocity)),
        ref_a_(find_vrs(md, names::kRefAcceleration)),
        ref_j_(find_vrs<3>(md, {"ref.j_W[1]", "ref.j_W[2]", "ref.j_W[3]"})),
        ref_yaw_(find_vr(md, names::kRefYaw)),
        ref_yaw_rate_(find_vr(md, "ref.yaw_rate")),
        ref_roll_(find_vr(md, "ref.roll")),
        ref_pitch_(find_vr(md, "ref.pitch")),
        omega_cmd_(find_vrs(md, names::omega_cmd(c.vehicle.rotor_count))),
        attitude_des_(find_vrs(md, names::kReportedAttitude)),
        tilt_saturated_(find_vr(md, names::kTiltSaturated)) {
    if (c.trajectory) {
      try {
        trajectory_ = trajectory::make_trajectory(*c.trajectory);
      } catch (const std::invalid_argument& e) {
        throw FmuError(std::string("trajectory: ") + e.what());
      }
      mode_ = control::Mode::kPosition;
      ref_external_ = find_vr(md, names::kRefExternal);
    }
    try {
      controller_ = controllers::make_config(c.controller_type, c.vehicle).controller->clone();
    } catch (const std::exception& e) {
      throw FmuError(std::string("controller: ") + e.what());
    }
    if (std::string err = controller_->set_parameters(c.controller_parameters); !err.empty()) {
      throw FmuError("controller parameter refused: " + err);
    }
    for (const control::ParameterSpec& s : controller_->parameters()) {
      parameters_.push_back({find_vr(md, std::string(names::kControllerPrefix) + std::string(s.name)),
                             std::string(s.name), s.is_choice()});
    }
    output_.outputs.assign(controller_->output_names().size(), 0.0);
    for (const std::string& name : controller_->output_names()) figures_.push_back(find_vr(md, name));
  }
  ControllerModel(const ControllerModel& o)
      : period_ns_(o.period_ns_),
        dt_s_(o.dt_s_),
        mode_(o.mode_),
        p_(o.p_),
        v_(o.v_),
        q_(o.q_),
        w_(o.w_),
        f_(o.f_),
        ref_p_(o.ref_p_),
        ref_v_(o.ref_v_),
        ref_a_(o.ref_a_),
        ref_j_(o.ref_j_),
        ref_yaw_(o.ref_yaw_),
        ref_yaw_rate_(o.ref_yaw_rate_),
        ref_roll_(o.ref_roll_),
        ref_pitch_(o.ref_pitch_),
        omega_cmd_(o.omega_cmd_),
        attitude_des_(o.attitude_des_),
        tilt_saturated_(o.tilt_saturated_),
        figures_(o.figures_),
        trajectory_(o.trajectory_),
        ref_external_(o.ref_external_),
        external_(o.external_),
        parameters_(o.parameters_),
        controller_(o.controller_->clone()),
        output_(o.output_) {}

  std::unique_ptr<Model> clone() const override { return std::make_unique<ControllerModel>(*this); }
  std::int64_t period_ns() const override { return period_ns_; }

  std::string initialize(sim::Tick, Values& v) override {
    for (const ValueReference vr : omega_cmd_) v.number[vr] = 0.0;  // no command before the first step
    for (const ValueReference vr : attitude_des_) v.number[vr] = 0.0;
    v.number[tilt_saturated_] = 0.0;
    for (const ValueReference vr : figures_) v.number[vr] = 0.0;
    external_ = ref_external_ && v.number[*ref_external_] != 0.0;
    return {};
  }

  std::string check_inputs(const Values& v) const override {
    const double norm = vector<4>(v, q_).norm();
    if (!(std::abs(norm - 1.0) <= sim::kQuaternionNormTolerance)) {
      return "q_WB is not a unit quaternion (norm " + std::to_string(norm) + "): set the attitude inputs first";
    }
    return {};
  }

  std::string step(sim::Tick k, std::int64_t n, Values& v) override {
    control::Observation o;
    o.p_W = vector<3>(v, p_);
    o.v_W = vector<3>(v, v_);
    const Eigen::Vector4d q = vector<4>(v, q_);
    o.q_WB = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    const model::Euler e = model::euler_from_quaternion(o.q_WB);
    o.roll_rad = e.roll_rad;
    o.pitch_rad = e.pitch_rad;
    o.yaw_rad = e.yaw_rad;
    o.w_B = vector<3>(v, w_);
    o.specific_force_B = vector<3>(v, f_);
    o.age_s = 0.0;

    control::Reference r;
    r.mode = mode_;
    r.p_W = vector<3>(v, ref_p_);
    r.v_W = vector<3>(v, ref_v_);
    r.a_W = vector<3>(v, ref_a_);
    r.j_W = vector<3>(v, ref_j_);
    r.yaw_rad = v.number[ref_yaw_];
    r.yaw_rate_rad_s = v.number[ref_yaw_rate_];
    r.roll_rad = v.number[ref_roll_];
    r.pitch_rad = v.number[ref_pitch_];

    for (std::int64_t i = 0; i < n; ++i) {
      if (trajectory_ && !external_) {
        // The step's time in integer nanoseconds, then seconds: the same double the node computes.
        r = control::trajectory_reference(trajectory_->at(static_cast<double>((k + i) * period_ns_) / 1e9));
      }
      controller_->step(o, r, dt_s_, output_);
    }
    if (static_cast<std::size_t>(output_.omega_rad_s.size()) != omega_cmd_.size()) {
      return "the controller's command has " + std::to_string(output_.omega_rad_s.size()) + " values for " +
             std::to_string(omega_cmd_.size()) + " rotors (omega_cmd[1.." + std::to_string(omega_cmd_.size()) + "])";
    }
    for (std::size_t i = 0; i < omega_cmd_.size(); ++i) {
      v.number[omega_cmd_[i]] = output_.omega_rad_s[static_cast<Eigen::Index>(i)];
    }
    v.number[attitude_des_[0]] = output_.roll_des_rad;
    v.number[attitude_des_[1]] = output_.pitch_des_rad;
    v.number[attitude_des_[2]] = output_.yaw_des_rad;
    v.number[tilt_saturated_] = output_.tilt_saturated ? 1.0 : 0.0;
    for (std::size_t i = 0; i < figures_.size(); ++i) v.number[figures_[i]] = output_.outputs[i];
    if (!output_.omega_rad_s.allFinite()) return "the controller's command is not finite";
    return {};
  }

  std::string set_tunable(const std::vector<ValueReference>& vrs, const Values& next) override {
    std::vector<control::Setting> settings;
    for (const ValueReference vr : vrs) {
      for (const Parameter& p : parameters_) {
        if (p.vr != vr) continue;
        settings.push_back(
            {p.name, p.choice ? control::ParameterValue(next.text[vr]) : control::ParameterValue(next.number[vr])});
      }
    }
    if (std::string err = controller_->set_parameters(settings); !err.empty()) {
      return "controller parameter refused: " + std::string(names::kControllerPrefix) + err;
    }
    return {};
  }

 private:
  template <int N>
  static Eigen::Matrix<double, N, 1> vector(const Values& v, const std::array<ValueReference, N>& vrs) {
    Eigen::Matrix<double, N, 1> x;
    for (int i = 0; i < N; ++i) x[i] = v.number[vrs[static_cast<std::size_t>(i)]];
    return x;
  }

  std::int64_t period_ns_;
  double dt_s_;
  control::Mode mode_;
  std::array<ValueReference, 3> p_, v_;
  std::array<ValueReference, 4> q_;
  std::array<ValueReference, 3> w_, f_, ref_p_, ref_v_, ref_a_, ref_j_;
  ValueReference ref_yaw_, ref_yaw_rate_, ref_roll_, ref_pitch_;
  std::vector<ValueReference> omega_cmd_;       ///< omega_cmd[1..N], one per rotor
  std::array<ValueReference, 3> attitude_des_;  ///< roll_des, pitch_des, yaw_des
  ValueReference tilt_saturated_;
  std::vector<ValueReference> figures_;  ///< the controller's output_names(), in order
  /// The trajectory the configuration carries (null: none), and the parameter ref.external: its
  /// value reference and its value at initialisation.
  std::shared_ptr<const trajectory::Trajectory> trajectory_;
  std::optional<ValueReference> ref_external_;
  bool external_ = false;
  struct Parameter {
    ValueReference vr;
    std::string name;  ///< without the prefix
    bool choice;       ///< a String variable
  };
  std::vector<Parameter> parameters_;
  std::unique_ptr<control::Controller> controller_;
  control::ControllerOutput output_;
};

}  // namespace

std::unique_ptr<Model> make_controller_model(const FmuConfig& config, const ModelDescription& md) {
  return std::make_unique<ControllerModel>(config, md);
}

}  // namespace quadcosim::fmi::exported
