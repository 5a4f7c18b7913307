// The plant FMU: the plant node's core (sim::PlantCore: the model's state, the realism, the extra
// sensors) without the node. Time is the integer tick of the communication point; each tick is
// PlantCore::integrate and the outputs at tick k are PlantCore::outputs with the command that acted
// over the tick before, as PlantNode publishes them, so that a run with this FMU as its plant gives
// the native plant's numbers bit for bit.
//
// The command (omega_cmd) is read at the start of each doStep and held over it (zero-order hold);
// the model clamps it to [omega_min, omega_max]. Before the first step the command acting is
// initial.omega. With realism.sensor_noise the sensor outputs are what sim::PlantRealism samples
// every tick (as the plant node publishes them): p_W from the pose, v_W from the velocity's linear
// part, q_WB, w_B and f_B from the IMU (the samples the controller node uses), each held between its
// sensor's ticks; euler is computed from that q_WB and omega stays the true rotor speeds.
//
// The extra sensors the scenario configured (magnetometer, barometer, GNSS: sensors/registry.hpp) are
// the vehicle's sensor suite (sensors/suite.hpp), stepped on every tick as the plant node steps it;
// their outputs ("barometer.pressure", "gnss.v[1]", ...) hold the newest sample. They do not depend on
// realism.sensor_noise (they are sensors, not the state).
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "fmi/export/slave.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "model/attitude.hpp"
#include "sensors/suite.hpp"
#include "sim/plant_core.hpp"
#include "sim/realism.hpp"

namespace quadcosim::fmi::exported {

namespace {

class PlantModel final : public Model {
 public:
  PlantModel(const FmuConfig& c, const ModelDescription& md)
      : config_(c),
        clock_{c.plant_period_ns},
        omega_cmd_(find_vrs(md, names::omega_cmd(c.vehicle.rotor_count))),
        p_(find_vrs(md, names::kPosition)),
        v_(find_vrs(md, names::kVelocity)),
        q_(find_vrs(md, names::kAttitude)),
        euler_(find_vrs(md, names::kEuler)),
        w_(find_vrs(md, names::kRates)),
        f_(find_vrs(md, names::kSpecificForce)),
        omega_(find_vrs(md, names::rotor_speed(c.vehicle.rotor_count))),
        init_p_(initial_vrs(md, names::kPosition)),
        init_v_(initial_vrs(md, names::kVelocity)),
        init_q_(initial_vrs(md, names::kAttitude)),
        init_w_(initial_vrs(md, names::kRates)),
        init_omega_(find_vrs(md, names::rotor_speed(c.vehicle.rotor_count), names::kInitialPrefix)),
        wind_(find_vr(md, "realism.wind")),
        faults_(find_vr(md, "realism.rotor_faults")),
        noise_(find_vr(md, "realism.sensor_noise")),
        seed_(find_vr(md, "realism.seed")) {
    for (const auto& p : model::vehicle_parameters()) {
      if (p.kind == model::VehicleParameter::Kind::kNumber) {
        vehicle_.push_back({&p, find_vr(md, std::string(names::kVehiclePrefix) + std::string(p.name))});
      }
    }
    sensors::for_each_configured(c.realism.extra_sensors, [&]<class Kind>(const typename Kind::Config&) {
      std::vector<ValueReference>& vrs = extra_vrs_[sensors::kind_index<Kind>()];
      for (const auto& col : Kind::kColumns) {
        for (int i = 0; i < col.width; ++i)
          vrs.push_back(find_vr(md, names::sensor_variable(Kind::kName, col.name, col.width, i)));
      }
    });
  }

  std::unique_ptr<Model> clone() const override { return std::make_unique<PlantModel>(*this); }
  std::int64_t period_ns() const override { return clock_.period_ns; }

  // The Euler angles are computed when they are read (from the attitude outputs as they are then),
  // not on every step: a master that maps only the quaternion pays nothing for them.
  void complete_outputs(const ValueReference* vr, std::size_t n, Values& v) const override {
    for (std::size_t i = 0; i < n; ++i) {
      if (vr[i] < euler_.front() || vr[i] > euler_.back()) continue;
      const Eigen::Quaterniond q(v.number[q_[0]], v.number[q_[1]], v.number[q_[2]], v.number[q_[3]]);
      const model::Euler e = model::euler_from_quaternion(q);
      put(v, euler_, Eigen::Vector3d(e.roll_rad, e.pitch_rad, e.yaw_rad));
      return;
    }
  }
  std::string set_tunable(const std::vector<ValueReference>&, const Values&) override { return {}; }
  std::string check_inputs(const Values&) const override { return {}; }  // checked when set

  std::string initialize(sim::Tick k, Values& v) override {
    model::VehicleParams vehicle = config_.vehicle;
    for (const auto& [p, vr] : vehicle_) p->ref(vehicle) = v.number[vr];
    if (std::string err = model::validate(vehicle); !err.empty()) return "vehicle parameter refused: vehicle." + err;
    if (std::string err = model::validate_step(vehicle, clock_.period_s(), config_.substeps); !err.empty()) {
      return "vehicle parameters refused: " + err;
    }
    model::State x;
    x.p_W = vector<3>(v, init_p_);
    x.v_W = vector<3>(v, init_v_);
    const Eigen::Vector4d q = vector<4>(v, init_q_);
    if (!(std::abs(q.norm() - 1.0) <= 1e-6)) {
      return "initial.q_WB is not a unit quaternion (norm " + std::to_string(q.norm()) + ")";
    }
    x.q_WB = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    x.w_B = vector<3>(v, init_w_);
    x.omega_rad_s = rotors(v, init_omega_);

    sim::RealismConfig realism = config_.realism;
    if (v.number[wind_] == 0.0) realism.wind = {};
    if (v.number[faults_] == 0.0) realism.faults.clear();
    sensor_noise_ = v.number[noise_] != 0.0;
    if (!sensor_noise_) {
      realism.imu = {};
      realism.pose = {};
      realism.velocity = {};
    }
    realism.seed = static_cast<std::uint64_t>(v.number[seed_]);

    // The realism is present whenever the plant node would have one (the configured realism, not what
    // the switches left of it): the model then takes the same path through an Environment, whatever it
    // holds. The extra sensors are named, seeded and timed as the plant node's.
    core_ = sim::PlantCore(vehicle, realism, clock_, x, config_.realism_namespace, config_.realism.active());
    sensor_noise_ = sensor_noise_ && core_.has_realism();
    write_outputs(k, v);
    return {};
  }

  std::string step(sim::Tick k, std::int64_t n, Values& v) override {
    core_.set_latched(rotors(v, omega_cmd_));
    for (sim::Tick i = k; i < k + n; ++i) {
      core_.integrate(clock_, i, config_.substeps);
      // The sensors sample every tick (their rates and latencies count ticks), also inside a step.
      if ((sensor_noise_ || core_.extra_sensors()) && i + 1 < k + n) measure(i + 1);
    }
    write_outputs(k + n, v);
    const model::State& x = core_.state();
    if (!x.p_W.allFinite() || !x.v_W.allFinite() || !x.q_WB.coeffs().allFinite() || !x.w_B.allFinite()) {
      return "the plant's state is no longer finite at t = " + std::to_string(clock_.seconds(k + n)) + " s";
    }
    return {};
  }

 private:
  template <std::size_t N>
  static std::array<ValueReference, N> initial_vrs(const ModelDescription& md,
                                                   const std::array<std::string_view, N>& outputs) {
    std::array<ValueReference, N> vrs{};
    for (std::size_t i = 0; i < N; ++i) {
      vrs[i] = find_vr(md, std::string(names::kInitialPrefix) + std::string(outputs[i]));
    }
    return vrs;
  }
  template <int N>
  static Eigen::Matrix<double, N, 1> vector(const Values& v, const std::array<ValueReference, N>& vrs) {
    Eigen::Matrix<double, N, 1> x;
    for (int i = 0; i < N; ++i) x[i] = v.number[vrs[static_cast<std::size_t>(i)]];
    return x;
  }
  template <std::size_t N, class V>
  static void put(Values& v, const std::array<ValueReference, N>& vrs, const V& x) {
    for (std::size_t i = 0; i < N; ++i) v.number[vrs[i]] = x[static_cast<Eigen::Index>(i)];
  }
  /// One value per rotor.
  static model::RotorVector rotors(const Values& v, const std::vector<ValueReference>& vrs) {
    model::RotorVector x(static_cast<Eigen::Index>(vrs.size()));
    for (std::size_t i = 0; i < vrs.size(); ++i) x[static_cast<Eigen::Index>(i)] = v.number[vrs[i]];
    return x;
  }
  static void put(Values& v, const std::vector<ValueReference>& vrs, const model::RotorVector& x) {
    for (std::size_t i = 0; i < vrs.size(); ++i) v.number[vrs[i]] = x[static_cast<Eigen::Index>(i)];
  }

  /// The true outputs at tick k; with sensor noise, also the sensors' samples of tick k.
  model::Outputs measure(sim::Tick k) {
    const model::Outputs y = core_.outputs(clock_, k);
    if (sensor_noise_) core_.measure(k, y, pose_, twist_, imu_);
    core_.sense_extra(k, y);
    return y;
  }

  /// The extra sensors' outputs: the newest sample of each, column by column.
  void write_extra_outputs(Values& v) const {
    const sensors::Suite* extra = core_.extra_sensors();
    if (!extra) return;
    sensors::for_each_kind([&]<class Kind>() {
      const sensors::Slot<Kind>* slot = extra->slot<Kind>();
      if (!slot) return;
      const std::vector<ValueReference>& vrs = extra_vrs_[sensors::kind_index<Kind>()];
      std::array<double, sensors::sample_width<Kind>()> values{};
      sensors::write_sample<Kind>(slot->sample, values.data());
      for (std::size_t i = 0; i < vrs.size(); ++i) v.number[vrs[i]] = values[i];
    });
  }

  void write_outputs(sim::Tick k, Values& v) {
    model::Outputs y = measure(k);
    if (sensor_noise_) {
      y.p_W = Eigen::Vector3d(pose_.position.x, pose_.position.y, pose_.position.z);
      y.v_W = Eigen::Vector3d(twist_.linear.x, twist_.linear.y, twist_.linear.z);
      const auto& o = imu_.orientation;
      y.q_WB = Eigen::Quaterniond(o.w, o.x, o.y, o.z);
      y.w_B = Eigen::Vector3d(imu_.angular_velocity.x, imu_.angular_velocity.y, imu_.angular_velocity.z);
      y.specific_force_B =
          Eigen::Vector3d(imu_.linear_acceleration.x, imu_.linear_acceleration.y, imu_.linear_acceleration.z);
    }
    put(v, p_, y.p_W);
    put(v, v_, y.v_W);
    put(v, q_, Eigen::Vector4d(y.q_WB.w(), y.q_WB.x(), y.q_WB.y(), y.q_WB.z()));
    put(v, w_, y.w_B);
    put(v, f_, y.specific_force_B);
    put(v, omega_, core_.state().omega_rad_s);
    write_extra_outputs(v);
  }

  FmuConfig config_;
  sim::TickClock clock_;
  std::vector<ValueReference> omega_cmd_;  ///< omega_cmd[1..N], one per rotor
  std::array<ValueReference, 3> p_, v_;
  std::array<ValueReference, 4> q_;
  std::array<ValueReference, 3> euler_, w_, f_;
  std::vector<ValueReference> omega_;  ///< omega[1..N]
  std::array<ValueReference, 3> init_p_, init_v_;
  std::array<ValueReference, 4> init_q_;
  std::array<ValueReference, 3> init_w_;
  std::vector<ValueReference> init_omega_;  ///< initial.omega[1..N]
  ValueReference wind_, faults_, noise_, seed_;
  std::vector<std::pair<const model::VehicleParameter*, ValueReference>> vehicle_;
  std::array<std::vector<ValueReference>, std::tuple_size_v<sensors::Kinds>> extra_vrs_;  ///< by kind, per number

  sim::PlantCore core_;  ///< the plant: made by initialize
  bool sensor_noise_ = false;
  msg::PoseStamped pose_;
  msg::TwistStamped twist_;
  msg::Imu imu_;
};

}  // namespace

std::unique_ptr<Model> make_plant_model(const FmuConfig& config, const ModelDescription& md) {
  return std::make_unique<PlantModel>(config, md);
}

}  // namespace quadcosim::fmi::exported
