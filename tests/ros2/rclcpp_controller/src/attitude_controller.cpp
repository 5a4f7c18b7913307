// A paper-style rclcpp controller node, written as a ROS 2 user writes one, and nothing of quadcosim:
// parameters, three sensor subscriptions, a timer at its own rate on the node's clock (ROS time with
// use_sim_time:=true), Float64MultiArray rotor speeds out, spun by rclcpp::spin. quadcosim's ROS 2
// tests fly it in lockstep.
//
// Control law (the paper's vehicle, '+' layout, rotor i at -i * 90 degrees from the nose):
//   U1 = m (g + kp_z (z_des - z) - kd_z vz)                      collective thrust [N]
//   U2 = Ixx (-kp_att roll - kd_att p), U3 = Iyy (...pitch, q), U4 = Izz (...yaw, r)
//   rotor speeds from the inverse of the '+' mixer, clamped at 0 and omega_max.
// tests/ros2/rclpy_controller/attitude_controller.py computes the same numbers in the same order.
//
// Parameters: z_des [m], kp_z, kd_z, kp_att, kd_att, rate_hz, log_file: when set, one line per step
// "now_ns pose_ns velocity_ns imu_ns w1 w2 w3 w4", so a test can check which samples each step used.
// Flag --no-clock-thread (before --ros-args): NodeOptions::use_clock_thread(false).
// Other node shapes, for the tests of how lockstep treats them (tests/ros2/ros2_cases.sh): parameter
// shape "timer" (default) or "pose_callback" (step from the Pose subscription callback, no timer);
// executor_threads N > 1: spin in a MultiThreadedExecutor with N threads instead of rclcpp::spin.
// Parameter label (default false): label each command "rotors@<ns>" with the oldest header stamp of
// the three samples its step used (one std_msgs/MultiArrayDimension), so the plant can tell a step
// on older samples (docs/ros2.md, "Labelled commands").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "geometry_msgs/msg/pose_stamped.hpp"
#include "geometry_msgs/msg/twist_stamped.hpp"
#include "rclcpp/rclcpp.hpp"
#include "sensor_msgs/msg/imu.hpp"
#include "std_msgs/msg/float64_multi_array.hpp"

namespace {

constexpr double kMass = 1.96, kGravity = 9.81;
constexpr double kIxx = 0.0149, kIyy = 0.0153, kIzz = 0.0532;
constexpr double kArm = 0.59, kThrust = 2.06e-7, kDrag = 1.01e-10, kOmegaMax = 12000.0;

std::int64_t to_ns(const builtin_interfaces::msg::Time& t) {
  return static_cast<std::int64_t>(t.sec) * 1000000000 + t.nanosec;
}

class AttitudeControllerNode : public rclcpp::Node {
 public:
  explicit AttitudeControllerNode(const rclcpp::NodeOptions& options) : Node("attitude_controller", options) {
    z_des_ = declare_parameter("z_des", 0.0);
    kp_z_ = declare_parameter("kp_z", 4.0);
    kd_z_ = declare_parameter("kd_z", 2.7);
    kp_att_ = declare_parameter("kp_att", 36.0);
    kd_att_ = declare_parameter("kd_att", 12.0);
    const double rate_hz = declare_parameter("rate_hz", 50.0);
    const std::string log_file = declare_parameter("log_file", std::string());
    const std::string shape = declare_parameter("shape", std::string("timer"));
    executor_threads_ = declare_parameter("executor_threads", 1);
    label_ = declare_parameter("label", false);
    if (shape != "timer" && shape != "pose_callback") {
      throw std::invalid_argument("shape must be timer or pose_callback, not '" + shape + "'");
    }
    const bool step_on_pose = shape == "pose_callback";
    param_cb_ = add_on_set_parameters_callback([this](const std::vector<rclcpp::Parameter>& ps) {
      for (const auto& p : ps) {
        if (p.get_name() == "z_des") z_des_ = p.as_double();
        if (p.get_name() == "kp_z") kp_z_ = p.as_double();
        if (p.get_name() == "kd_z") kd_z_ = p.as_double();
      }
      rcl_interfaces::msg::SetParametersResult r;
      r.successful = true;
      return r;
    });
    if (!log_file.empty()) log_ = std::fopen(log_file.c_str(), "w");

    const auto qos = rclcpp::QoS(10);
    pose_sub_ = create_subscription<geometry_msgs::msg::PoseStamped>(
        "/drone/Pose", qos, [this, step_on_pose](const geometry_msgs::msg::PoseStamped& m) {
          pose_ = m;
          if (step_on_pose) step();
        });
    vel_sub_ = create_subscription<geometry_msgs::msg::TwistStamped>(
        "/drone/Velocity", qos, [this](const geometry_msgs::msg::TwistStamped& m) { vel_ = m; });
    imu_sub_ = create_subscription<sensor_msgs::msg::Imu>("/drone/Imu", qos,
                                                          [this](const sensor_msgs::msg::Imu& m) { imu_ = m; });
    cmd_pub_ = create_publisher<std_msgs::msg::Float64MultiArray>("/drone/motor_commands", qos);
    const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(std::llround(1e9 / rate_hz)));
    if (!step_on_pose) timer_ = create_timer(period, [this] { step(); });
  }
  std::int64_t executor_threads() const { return executor_threads_; }
  ~AttitudeControllerNode() override {
    if (log_ != nullptr) std::fclose(log_);
  }

 private:
  void step() {
    const std::int64_t now_ns = now().nanoseconds();
    const auto& q = pose_.pose.orientation;
    const double roll = std::atan2(2.0 * (q.w * q.x + q.y * q.z), 1.0 - 2.0 * (q.x * q.x + q.y * q.y));
    const double pitch = std::asin(std::clamp(2.0 * (q.w * q.y - q.z * q.x), -1.0, 1.0));
    const double yaw = std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
    const auto& w = imu_.angular_velocity;
    const double u1 = kMass * (kGravity + kp_z_ * (z_des_ - pose_.pose.position.z) - kd_z_ * vel_.twist.linear.z);
    const double u2 = kIxx * (-kp_att_ * roll - kd_att_ * w.x);
    const double u3 = kIyy * (-kp_att_ * pitch - kd_att_ * w.y);
    const double u4 = kIzz * (-kp_att_ * yaw - kd_att_ * w.z);
    const double a = u1 / (4.0 * kThrust), b = u2 / (2.0 * kThrust * kArm), c = u3 / (2.0 * kThrust * kArm),
                 d = u4 / (4.0 * kDrag);
    const double sq[4] = {a - c + d, a - b - d, a + c + d, a + b - d};
    std_msgs::msg::Float64MultiArray cmd;
    cmd.data.resize(4);
    if (label_) {
      const std::int64_t oldest =
          std::min({to_ns(pose_.header.stamp), to_ns(vel_.header.stamp), to_ns(imu_.header.stamp)});
      cmd.layout.dim.resize(1);
      cmd.layout.dim[0].label = "rotors@" + std::to_string(oldest);
      cmd.layout.dim[0].size = 4;
      cmd.layout.dim[0].stride = 4;
    }
    for (int i = 0; i < 4; ++i) cmd.data[i] = std::min(std::sqrt(std::max(sq[i], 0.0)), kOmegaMax);
    cmd_pub_->publish(cmd);
    if (log_ != nullptr) {
      std::fprintf(log_, "%lld %lld %lld %lld %.17g %.17g %.17g %.17g\n", static_cast<long long>(now_ns),
                   static_cast<long long>(to_ns(pose_.header.stamp)), static_cast<long long>(to_ns(vel_.header.stamp)),
                   static_cast<long long>(to_ns(imu_.header.stamp)), cmd.data[0], cmd.data[1], cmd.data[2],
                   cmd.data[3]);
      std::fflush(log_);
    }
  }

  double z_des_, kp_z_, kd_z_, kp_att_, kd_att_;
  std::int64_t executor_threads_ = 1;
  bool label_ = false;
  std::FILE* log_ = nullptr;
  geometry_msgs::msg::PoseStamped pose_;
  geometry_msgs::msg::TwistStamped vel_;
  sensor_msgs::msg::Imu imu_;
  rclcpp::Subscription<geometry_msgs::msg::PoseStamped>::SharedPtr pose_sub_;
  rclcpp::Subscription<geometry_msgs::msg::TwistStamped>::SharedPtr vel_sub_;
  rclcpp::Subscription<sensor_msgs::msg::Imu>::SharedPtr imu_sub_;
  rclcpp::Publisher<std_msgs::msg::Float64MultiArray>::SharedPtr cmd_pub_;
  rclcpp::TimerBase::SharedPtr timer_;
  rclcpp::node_interfaces::OnSetParametersCallbackHandle::SharedPtr param_cb_;
};

}  // namespace

int main(int argc, char** argv) {
  rclcpp::init(argc, argv);
  // --no-clock-thread (before --ros-args): /clock handled in the node's own executor, not on
  // rclcpp's clock thread (the default).
  bool clock_thread = true;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--ros-args") == 0) break;
    if (std::strcmp(argv[i], "--no-clock-thread") == 0) clock_thread = false;
  }
  auto node = std::make_shared<AttitudeControllerNode>(rclcpp::NodeOptions().use_clock_thread(clock_thread));
  if (node->executor_threads() > 1) {
    rclcpp::executors::MultiThreadedExecutor executor(rclcpp::ExecutorOptions(),
                                                      static_cast<std::size_t>(node->executor_threads()));
    executor.add_node(node);
    executor.spin();
  } else {
    rclcpp::spin(node);
  }
  rclcpp::shutdown();
  return 0;
}
