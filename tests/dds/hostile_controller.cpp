// A misbehaving controller for the plant over DDS: it answers every control tick's Pose (even ticks,
// each stamp once) with one unlabelled motor command, cycling through four kinds by answer index i:
// i % 4 == 0 four hover speeds (valid), 1 three values (wrong length), 2 a NaN speed, 3 a negative
// and a too-fast speed (to be clamped). Exits when no Pose has come for `idle_s` seconds after the
// first, printing how many of each kind it sent.
//   usage: hostile_controller IDLE_S
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "dds/dds_transport.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"

int main(int argc, char** argv) {
  using namespace quadcosim;
  const double idle_s = argc > 1 ? std::atof(argv[1]) : 3.0;
  dds::DdsTransport transport(dds::read_ros_environment());
  const sim::Topics topics = sim::Topics::for_namespace("/drone");
  auto commands = transport.advertise<msg::Float64MultiArray>(topics.motor_commands);
  const double hover = 4830.6;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  long sent[4] = {0, 0, 0, 0};
  std::int64_t last_answered = -1;
  bool any = false;
  auto last_pose = std::chrono::steady_clock::now();
  transport.subscribe<msg::PoseStamped>(topics.pose, [&](const msg::PoseStamped& pose) {
    const std::int64_t t_ns = pose.header.stamp.to_ns();
    any = true;
    last_pose = std::chrono::steady_clock::now();
    if (t_ns <= last_answered || (t_ns / 10'000'000) % 2 != 0) return;  // a repeat, or not a control tick
    last_answered = t_ns;
    const long i = sent[0] + sent[1] + sent[2] + sent[3];
    msg::Float64MultiArray m;
    switch (i % 4) {
      case 0: m.data = {hover, hover, hover, hover}; break;
      case 1: m.data = {hover, hover, hover}; break;
      case 2: m.data = {hover, nan, hover, hover}; break;
      case 3: m.data = {-100.0, 1e9, hover, hover}; break;
    }
    ++sent[i % 4];
    commands.publish(m);
  });
  // Read the other sensor topics too: the plant waits until a controller reads all three.
  transport.subscribe<msg::TwistStamped>(topics.velocity, [](const msg::TwistStamped&) {});
  transport.subscribe<msg::Imu>(topics.imu, [](const msg::Imu&) {});
  // Until the plant is done: no Pose for idle_s (after the first; 30 s at most before it).
  const auto start = std::chrono::steady_clock::now();
  const auto idle = std::chrono::duration<double>(idle_s);
  while (any ? std::chrono::steady_clock::now() - last_pose < idle
             : std::chrono::steady_clock::now() - start < std::chrono::seconds(30)) {
    transport.spin_once(100'000'000);
  }
  std::printf("sent valid %ld short %ld nan %ld clamp %ld\n", sent[0], sent[1], sent[2], sent[3]);
  return any ? 0 : 1;
}
