#include "sim/realism.hpp"

#include <algorithm>
#include <utility>

#include "sim/msg_eigen.hpp"

namespace quadcosim::sim {

namespace {

void set_diagonal(std::array<double, 9>& cov, double sigma) {
  cov = {};
  if (sigma > 0.0) cov[0] = cov[4] = cov[8] = sigma * sigma;
}

/// `to` becomes `from` but keeps its own header (the caller stamps it). Moving the header out and
/// back keeps its frame_id's buffer: no allocation per tick.
template <class Message>
void copy_but_header(const Message& from, Message& to) {
  msg::Header header = std::move(to.header);
  to = from;
  to.header = std::move(header);
}
}  // namespace

bool RealismConfig::active() const {
  const auto& i = imu;
  return i.gyro_noise_density > 0.0 || i.gyro_bias_random_walk > 0.0 || i.gyro_bias_initial > 0.0 ||
         i.accel_noise_density > 0.0 || i.accel_bias_random_walk > 0.0 || i.accel_bias_initial > 0.0 ||
         i.orientation_sigma_rad > 0.0 || i.timing.active() || pose.position_sigma_m > 0.0 ||
         pose.orientation_sigma_rad > 0.0 || pose.timing.active() || velocity.linear_sigma_m_s > 0.0 ||
         velocity.angular_sigma_rad_s > 0.0 || velocity.timing.active() || wind.active() || !faults.empty();
}

PlantRealism::PlantRealism(const RealismConfig& c, const model::VehicleParams& /*vehicle*/, const std::string& ns,
                           const TickClock& clock)
    : config_(c) {
  auto rng = [&](const char* source) { return model::Rng(model::stream_seed(c.seed, ns, source)); };
  const double T = clock.period_s();
  wind_ = model::WindField(c.wind, T, rng("wind.gusts"));

  const double imu_period = T * c.imu.timing.divider;
  gyro_ = {model::discrete_sigma(c.imu.gyro_noise_density, 1.0 / imu_period),
           model::bias_step_sigma(c.imu.gyro_bias_random_walk, imu_period), c.imu.gyro_bias_initial};
  accel_ = {model::discrete_sigma(c.imu.accel_noise_density, 1.0 / imu_period),
            model::bias_step_sigma(c.imu.accel_bias_random_walk, imu_period), c.imu.accel_bias_initial};
  gyro_noise_ = model::Vector3Noise(gyro_, rng("imu.gyro"));
  accel_noise_ = model::Vector3Noise(accel_, rng("imu.accel"));
  imu_attitude_rng_ = rng("imu.orientation");
  position_noise_ = model::Vector3Noise({c.pose.position_sigma_m, 0.0, 0.0}, rng("pose.position"));
  pose_attitude_rng_ = rng("pose.orientation");
  linear_noise_ = model::Vector3Noise({c.velocity.linear_sigma_m_s, 0.0, 0.0}, rng("velocity.linear"));
  angular_noise_ = model::Vector3Noise({c.velocity.angular_sigma_rad_s, 0.0, 0.0}, rng("velocity.angular"));

  const int depth =
      1 + std::max({c.imu.timing.latency_ticks, c.pose.timing.latency_ticks, c.velocity.timing.latency_ticks});
  history_.resize(static_cast<std::size_t>(depth));

  // The covariances the messages carry: the white-noise variance of each published quantity (the
  // biases are not in them: sensor_msgs/Imu has no field for an unknown slowly varying offset).
  set_diagonal(imu_.orientation_covariance, c.imu.orientation_sigma_rad);
  set_diagonal(imu_.angular_velocity_covariance, gyro_.white_sigma);
  set_diagonal(imu_.linear_acceleration_covariance, accel_.white_sigma);
}

const model::Environment& PlantRealism::environment(Tick k) {
  if (k != env_tick_) {
    env_tick_ = k;
    env_.wind_W = wind_.at_tick(k);
    for (; next_fault_ < config_.faults.size() && config_.faults[next_fault_].tick <= k; ++next_fault_) {
      const RotorFault& f = config_.faults[next_fault_];
      env_.rotor_efficiency[f.rotor] = f.efficiency;
    }
  }
  return env_;
}

const model::Outputs& PlantRealism::truth_at(Tick k) const {
  return history_[static_cast<std::size_t>(k % static_cast<Tick>(history_.size()))];
}

PlantRealism::Due PlantRealism::measure(Tick k, const model::Outputs& truth, msg::PoseStamped& pose,
                                        msg::TwistStamped& twist, msg::Imu& imu) {
  if (k != last_tick_) {
    last_tick_ = k;
    history_[static_cast<std::size_t>(k % static_cast<Tick>(history_.size()))] = truth;
    auto sample_of = [&](const SensorTiming& t) -> const model::Outputs& {
      return truth_at(std::max<Tick>(k - t.latency_ticks, 0));
    };
    due_ = {k % config_.pose.timing.divider == 0, k % config_.velocity.timing.divider == 0,
            k % config_.imu.timing.divider == 0};
    if (due_.pose) {
      const model::Outputs& y = sample_of(config_.pose.timing);
      pose_.position = to_msg(position_noise_.sample(y.p_W));
      pose_.orientation =
          to_msg(model::perturb_attitude(y.q_WB, config_.pose.orientation_sigma_rad, pose_attitude_rng_));
    }
    if (due_.velocity) {
      const model::Outputs& y = sample_of(config_.velocity.timing);
      twist_.linear = to_msg(linear_noise_.sample(y.v_W));
      twist_.angular = to_msg(angular_noise_.sample(y.w_B));
    }
    if (due_.imu) {
      const model::Outputs& y = sample_of(config_.imu.timing);
      imu_.orientation = to_msg(model::perturb_attitude(y.q_WB, config_.imu.orientation_sigma_rad, imu_attitude_rng_));
      imu_.angular_velocity = to_msg(gyro_noise_.sample(y.w_B));
      imu_.linear_acceleration = to_msg(accel_noise_.sample(y.specific_force_B));
    }
  }
  copy_but_header(pose_, pose);
  copy_but_header(twist_, twist);
  copy_but_header(imu_, imu);
  return due_;
}

}  // namespace quadcosim::sim
