// A stranger on the domain: a participant that is neither the plant nor the controller of the run and
// publishes on their topics, to show that it bends nothing. It pairs with no one (no pairing token).
//   usage: stranger commands|sensors|answer_every_sample SECONDS
// commands: every 2 ms a motor command cycling through NaN, three values, valid but unlabelled, and
//   one labelled 2e9 s ahead; and at each new Pose stamp (a tick of the run), at once, a NaN command and
//   an all-zero command labelled with that tick, as if answering it.
// sensors: every 10 ms a Pose, Velocity and Imu and a ControllerStatus stamped 2e9 s ahead (well
//   formed otherwise).
// answer_every_sample: not a stranger but a controller of the wrong shape: it publishes a hover
//   command (unlabelled, as a plain ROS 2 node's) on every Pose, Velocity and Imu sample it receives (as a
//   node that answers from its sensor callbacks does), so several per control period.
// Runs for SECONDS of wall time, then prints what it sent: "sent commands N labelled M",
// "sent sensors N statuses M" or "sent answers N".
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <thread>

#include "dds/dds_transport.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"

int main(int argc, char** argv) {
  using namespace quadcosim;
  const bool answers = argc == 3 && std::strcmp(argv[1], "answer_every_sample") == 0;
  if (argc != 3 || (std::strcmp(argv[1], "commands") != 0 && std::strcmp(argv[1], "sensors") != 0 && !answers)) {
    std::fprintf(stderr, "usage: stranger commands|sensors|answer_every_sample SECONDS\n");
    return 2;
  }
  const bool commands = std::strcmp(argv[1], "commands") == 0;
  const double seconds = std::atof(argv[2]);
  dds::DdsTransport transport(dds::read_ros_environment());
  const sim::Topics topics = sim::Topics::for_namespace("/drone");
  constexpr std::int64_t kFuture = 2'000'000'000LL * 1'000'000'000LL;  // 2e9 s [ns]
  const double nan = std::numeric_limits<double>::quiet_NaN();
  long sent = 0, labelled = 0;
  auto cmd = transport.advertise<msg::Float64MultiArray>(topics.motor_commands);
  if (answers) {
    auto answer = [&](const msg::Time&) {
      msg::Float64MultiArray m;
      m.data = {4830.0, 4830.0, 4830.0, 4830.0};  // unlabelled, as a plain ROS 2 node sends it
      cmd.publish(m);
      ++sent;
    };
    transport.subscribe<msg::PoseStamped>(topics.pose, [&](const msg::PoseStamped& p) { answer(p.header.stamp); });
    transport.subscribe<msg::TwistStamped>(topics.velocity,
                                           [&](const msg::TwistStamped& v) { answer(v.header.stamp); });
    transport.subscribe<msg::Imu>(topics.imu, [&](const msg::Imu& u) { answer(u.header.stamp); });
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) transport.spin_once(10'000'000);
    std::printf("sent answers %ld\n", sent);
    return 0;
  }
  auto pose = transport.advertise<msg::PoseStamped>(topics.pose);
  auto velocity = transport.advertise<msg::TwistStamped>(topics.velocity);
  auto imu = transport.advertise<msg::Imu>(topics.imu);
  auto status = transport.advertise<msg::ControllerStatus>(topics.controller_status);
  std::int64_t last_tick = -1;
  if (commands) {
    transport.subscribe<msg::PoseStamped>(topics.pose, [&](const msg::PoseStamped& p) {
      const std::int64_t t = p.header.stamp.to_ns();
      if (t == last_tick || t >= kFuture) return;
      last_tick = t;
      msg::Float64MultiArray m;
      m.dim = {{"", 4, 4}};
      m.data = {nan, 1.0, 1.0, 1.0};
      msg::write_command_label(m.dim[0].label, t);
      cmd.publish(m);
      m.data = {0.0, 0.0, 0.0, 0.0};
      cmd.publish(m);
      labelled += 2;
    });
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (long i = 0; std::chrono::steady_clock::now() < end; ++i) {
    if (commands) {
      msg::Float64MultiArray m;
      switch (i % 4) {
        case 0: m.data = {nan, 4830.0, 4830.0, 4830.0}; break;
        case 1: m.data = {4830.0, 4830.0, 4830.0}; break;
        case 2: m.data = {6000.0, 6000.0, 6000.0, 6000.0}; break;
        default:
          m.dim = {{"", 4, 4}};
          m.data = {0.0, 0.0, 0.0, 0.0};
          msg::write_command_label(m.dim[0].label, kFuture);
          break;
      }
      cmd.publish(m);
      ++sent;
      transport.spin_once(2'000'000);
    } else {
      const msg::Time t = msg::Time::from_ns(kFuture + i * 10'000'000LL);
      msg::PoseStamped p;
      p.header.stamp = t;
      p.header.frame_id = "world";
      p.orientation.w = 1.0;
      pose.publish(p);
      msg::TwistStamped v;
      v.header.stamp = t;
      velocity.publish(v);
      msg::Imu u;
      u.header.stamp = t;
      u.orientation.w = 1.0;
      imu.publish(u);
      msg::ControllerStatus s;
      s.header.stamp = t;
      status.publish(s);
      ++sent;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  if (commands) {
    std::printf("sent commands %ld labelled %ld\n", sent, labelled);
  } else {
    std::printf("sent sensors %ld statuses %ld\n", sent, sent);
  }
  return 0;
}
