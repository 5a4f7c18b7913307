#!/usr/bin/env python3
"""A paper-style rclpy controller node, written as a ROS 2 user writes one, and nothing of quadcosim.

The twin of tests/ros2/rclcpp_controller/src/attitude_controller.cpp: the same parameters, topics,
timer on the node's clock (ROS time with use_sim_time:=true) and control law, computed in the same
order, so both fly the same trajectory to the last bit. Run:

    attitude_controller.py --ros-args -p use_sim_time:=true [-p log_file:=steps.log]

Other node shapes, for the tests of how lockstep treats them (tests/ros2/ros2_cases.sh):
    -p shape:=pose_callback    step from the Pose subscription callback instead of a timer
    -p rate_hz:=100.0          a timer at another rate
    -p executor_threads:=2     spin in a MultiThreadedExecutor with that many threads (default 1:
                               rclpy.spin, a SingleThreadedExecutor)
    -p slow_step_ms:=80        every 25th step waits that long (wall clock) before it publishes
    -p label:=true             label each command "rotors@<ns>" with the oldest header stamp of the
                               three samples its step used (docs/ros2.md, "Labelled commands")
"""
import math
import sys
import time

import rclpy
import rclpy.executors
from rclpy.impl.implementation_singleton import rclpy_implementation
from geometry_msgs.msg import PoseStamped, TwistStamped
from rclpy.node import Node
from rcl_interfaces.msg import SetParametersResult
from sensor_msgs.msg import Imu
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

MASS, GRAVITY = 1.96, 9.81
IXX, IYY, IZZ = 0.0149, 0.0153, 0.0532
ARM, THRUST, DRAG, OMEGA_MAX = 0.59, 2.06e-7, 1.01e-10, 12000.0


def to_ns(stamp):
    return stamp.sec * 1000000000 + stamp.nanosec


class AttitudeControllerNode(Node):
    def __init__(self):
        super().__init__("attitude_controller")
        self.z_des = self.declare_parameter("z_des", 0.0).value
        self.kp_z = self.declare_parameter("kp_z", 4.0).value
        self.kd_z = self.declare_parameter("kd_z", 2.7).value
        self.kp_att = self.declare_parameter("kp_att", 36.0).value
        self.kd_att = self.declare_parameter("kd_att", 12.0).value
        rate_hz = self.declare_parameter("rate_hz", 50.0).value
        log_file = self.declare_parameter("log_file", "").value
        shape = self.declare_parameter("shape", "timer").value
        self.executor_threads = self.declare_parameter("executor_threads", 1).value
        self.slow_step_s = self.declare_parameter("slow_step_ms", 0).value * 1e-3
        self.label = self.declare_parameter("label", False).value
        self.steps = 0
        if shape not in ("timer", "pose_callback"):
            raise ValueError("shape must be timer or pose_callback, not %r" % shape)
        self.add_on_set_parameters_callback(self.on_set)
        self.log = open(log_file, "w") if log_file else None
        self.pose, self.vel, self.imu = PoseStamped(), TwistStamped(), Imu()
        self.create_subscription(PoseStamped, "/drone/Pose", self.on_pose, 10)
        self.create_subscription(TwistStamped, "/drone/Velocity", self.on_vel, 10)
        self.create_subscription(Imu, "/drone/Imu", self.on_imu, 10)
        self.pub = self.create_publisher(Float64MultiArray, "/drone/motor_commands", 10)
        self.step_on_pose = shape == "pose_callback"
        if not self.step_on_pose:
            self.create_timer(round(1e9 / rate_hz) * 1e-9, self.step)

    def on_set(self, params):
        for p in params:
            if p.name in ("z_des", "kp_z", "kd_z"):
                setattr(self, p.name, p.value)
        return SetParametersResult(successful=True)

    def on_pose(self, m):
        self.pose = m
        if self.step_on_pose:
            self.step()

    def on_vel(self, m):
        self.vel = m

    def on_imu(self, m):
        self.imu = m

    def step(self):
        now_ns = self.get_clock().now().nanoseconds
        q = self.pose.pose.orientation
        roll = math.atan2(2.0 * (q.w * q.x + q.y * q.z), 1.0 - 2.0 * (q.x * q.x + q.y * q.y))
        pitch = math.asin(min(max(2.0 * (q.w * q.y - q.z * q.x), -1.0), 1.0))
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        w = self.imu.angular_velocity
        u1 = MASS * (GRAVITY + self.kp_z * (self.z_des - self.pose.pose.position.z) - self.kd_z * self.vel.twist.linear.z)
        u2 = IXX * (-self.kp_att * roll - self.kd_att * w.x)
        u3 = IYY * (-self.kp_att * pitch - self.kd_att * w.y)
        u4 = IZZ * (-self.kp_att * yaw - self.kd_att * w.z)
        a = u1 / (4.0 * THRUST)
        b = u2 / (2.0 * THRUST * ARM)
        c = u3 / (2.0 * THRUST * ARM)
        d = u4 / (4.0 * DRAG)
        sq = (a - c + d, a - b - d, a + c + d, a + b - d)
        cmd = Float64MultiArray()
        cmd.data = [min(math.sqrt(max(s, 0.0)), OMEGA_MAX) for s in sq]
        if self.label:
            oldest = min(to_ns(self.pose.header.stamp), to_ns(self.vel.header.stamp), to_ns(self.imu.header.stamp))
            cmd.layout.dim = [MultiArrayDimension(label="rotors@%d" % oldest, size=4, stride=4)]
        self.steps += 1
        if self.slow_step_s > 0 and self.steps % 25 == 0:
            time.sleep(self.slow_step_s)
        self.pub.publish(cmd)
        if self.log:
            self.log.write("%d %d %d %d %s\n" % (now_ns, to_ns(self.pose.header.stamp), to_ns(self.vel.header.stamp),
                                                to_ns(self.imu.header.stamp), " ".join("%.17g" % v for v in cmd.data)))
            self.log.flush()


def main():
    rclpy.init(args=sys.argv)
    node = AttitudeControllerNode()
    executor = None  # rclpy's global SingleThreadedExecutor
    if node.executor_threads > 1:
        executor = rclpy.executors.MultiThreadedExecutor(num_threads=node.executor_threads)
    try:
        rclpy.spin(node, executor=executor)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    except rclpy_implementation.RCLError:
        # A SIGTERM's shutdown can invalidate the context while spin is inside its wait.
        if rclpy.ok():
            raise
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
