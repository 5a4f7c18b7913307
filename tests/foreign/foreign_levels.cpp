// A "foreign" ROS 2 participant commanding `quadcosim plant` on the typed command topics in lockstep,
// written only from the wire facts in docs/ros2.md ("What is on the wire", "Commands at every level")
// and the .msg files of ros2/quadcosim_msgs: its types come from its own IDL (tests/foreign/idl)
// through idlc; it includes and links nothing of quadcosim and talks through the plain Cyclone C API.
//
// Usage: foreign_levels MODE END_S
//   fly-ctbr      answers every control tick (50 Hz: a Pose and Velocity pair stamped a multiple of
//                 20 ms) with quadcosim_msgs/ThrustRates on rt/drone/cmd/ctbr: thrust
//                 m g + kp (z_des - z) - kd v_z, body rates 0 (an altitude step to z_des = 2 m)
//   fly-velocity  the same with quadcosim_msgs/VelocityYaw on rt/drone/cmd/velocity: v = (0, 0,
//                 kv (z_des - z)), yaw 0
//   reject        as fly-ctbr, but the control tick at t = 0 gets a NaN thrust, t = 0.02 s a RotorThrusts
//                 of 3 values (rt/drone/cmd/rotor_thrusts), t = 0.04 s is answered on ctbr and then on
//                 rt/drone/cmd/velocity too, t = 1 s gets a ThrustAttitude (rt/drone/cmd/ctatt) whose
//                 quaternion has norm 0.5 (apart from the others: plant_status.last_problem names the
//                 newest, and the second topic's refusal may come a tick late)
// header.stamp of each command is the stamp of the samples it answers (the control tick's time). Each
// tick is answered once, after the writers have matched the plant's readers. The participant ends
// once it answered the tick at END_S and nothing arrived for 1 s (or after 60 s of wall time), and
// prints one JSON line: {"answered": N, "last_stamp_ns": ..., "status": {newest plant status counts,
// "problems": [every distinct last_problem seen]}}. Exit 0 when it answered the tick at END_S, 3 if not,
// 2 on bad usage or a DDS error.
#include <dds/dds.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "foreign_participant.hpp"
#include "geometry_msgs.h"
#include "quadcosim_msgs.h"
#include "std_msgs.h"

using namespace foreign;

namespace {

// The vehicle of the paper and the law's gains (the same numbers as typed_levels_reference).
constexpr double kMass = 1.96;                         // [kg]
constexpr double kGravity = 9.81;                      // [m/s^2]
constexpr double kZDes = 2.0;                          // [m]
constexpr double kKp = 4.0;                            // [N/m]
constexpr double kKd = 2.7;                            // [N s/m]
constexpr double kKv = 1.2;                            // [1/s]
constexpr std::int64_t kControlPeriodNs = 20'000'000;  // 50 Hz

// The ROS default profile, every policy rmw_cyclonedds sets, set explicitly.
dds_qos_t* ros_default_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_INFINITY);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_INFINITY);
  dds_qset_writer_data_lifecycle(q, false);
  const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q, 1, xcdr1);
  return q;
}

std::int64_t stamp_ns(const builtin_interfaces_msg_dds__Time_& t) {
  return static_cast<std::int64_t>(t.sec) * 1'000'000'000 + t.nanosec;
}
builtin_interfaces_msg_dds__Time_ time_of(std::int64_t ns) {
  return {static_cast<std::int32_t>(ns / 1'000'000'000), static_cast<std::uint32_t>(ns % 1'000'000'000)};
}

std::string json_string(const char* s) {
  std::string out = "\"";
  for (const char* p = s ? s : ""; *p; ++p) {
    if (*p == '"' || *p == '\\') out += '\\';
    out += *p;
  }
  return out + "\"";
}

struct Endpoints {
  dds_entity_t participant = 0;
  dds_entity_t ctbr = 0, velocity = 0, thrusts = 0, attitude = 0;  // writers
  dds_entity_t topic(const char* name, const dds_topic_descriptor_t* desc) const {
    return check(dds_create_topic(participant, desc, name, nullptr, nullptr), name);
  }
};

bool matched(dds_entity_t writer) {
  dds_publication_matched_status_t s{};
  dds_get_publication_matched_status(writer, &s);
  return s.current_count > 0;
}

void send_ctbr(const Endpoints& e, std::int64_t stamp, double thrust_n) {
  quadcosim_msgs_msg_dds__ThrustRates_ m{};
  m.header.stamp = time_of(stamp);
  m.header.frame_id = const_cast<char*>("base_link");
  m.thrust_n = thrust_n;
  m.body_rates_rad_s = {0.0, 0.0, 0.0};
  if (const dds_return_t rc = dds_write(e.ctbr, &m); rc < 0) die("dds_write ctbr", rc);
}

void send_velocity(const Endpoints& e, std::int64_t stamp, double vz_m_s) {
  quadcosim_msgs_msg_dds__VelocityYaw_ m{};
  m.header.stamp = time_of(stamp);
  m.header.frame_id = const_cast<char*>("world");
  m.velocity_m_s = {0.0, 0.0, vz_m_s};
  m.yaw_rad = 0.0;
  if (const dds_return_t rc = dds_write(e.velocity, &m); rc < 0) die("dds_write velocity", rc);
}

}  // namespace

int main(int argc, char** argv) {
  foreign::program = "foreign_levels";
  const std::string mode = argc == 3 ? argv[1] : "";
  if (mode != "fly-ctbr" && mode != "fly-velocity" && mode != "reject") {
    std::fprintf(stderr, "usage: %s fly-ctbr|fly-velocity|reject END_S\n", argv[0]);
    return 2;
  }
  const auto end_ns = static_cast<std::int64_t>(std::llround(std::atof(argv[2]) * 1e9));

  const dds_domainid_t domain = ros_domain_id();
  const dds_entity_t dom = check(dds_create_domain(domain, localhost_config().c_str()), "dds_create_domain");
  dds_qos_t* pqos = dds_create_qos();
  static const char kEnclave[] = "enclave=/;";
  dds_qset_userdata(pqos, kEnclave, sizeof kEnclave - 1);
  Endpoints e;
  e.participant = check(dds_create_participant(domain, pqos, nullptr), "dds_create_participant");
  dds_delete_qos(pqos);

  dds_qos_t* q = ros_default_qos();
  const dds_entity_t r_pose = check(
      dds_create_reader(e.participant, e.topic("rt/drone/Pose", &geometry_msgs_msg_dds__PoseStamped__desc), q, nullptr),
      "reader Pose");
  const dds_entity_t r_vel =
      check(dds_create_reader(e.participant, e.topic("rt/drone/Velocity", &geometry_msgs_msg_dds__TwistStamped__desc),
                              q, nullptr),
            "reader Velocity");
  const dds_entity_t r_status =
      check(dds_create_reader(e.participant,
                              e.topic("rt/drone/plant_status", &quadcosim_msgs_msg_dds__PlantStatus__desc), q, nullptr),
            "reader plant_status");
  std::vector<dds_entity_t> writers;
  const auto writer = [&](const char* name, const dds_topic_descriptor_t* desc) {
    writers.push_back(check(dds_create_writer(e.participant, e.topic(name, desc), q, nullptr), name));
    return writers.back();
  };
  if (mode != "fly-velocity") e.ctbr = writer("rt/drone/cmd/ctbr", &quadcosim_msgs_msg_dds__ThrustRates__desc);
  if (mode != "fly-ctbr") e.velocity = writer("rt/drone/cmd/velocity", &quadcosim_msgs_msg_dds__VelocityYaw__desc);
  if (mode == "reject") {
    e.thrusts = writer("rt/drone/cmd/rotor_thrusts", &quadcosim_msgs_msg_dds__RotorThrusts__desc);
    e.attitude = writer("rt/drone/cmd/ctatt", &quadcosim_msgs_msg_dds__ThrustAttitude__desc);
  }
  dds_delete_qos(q);

  const dds_entity_t ws = check(dds_create_waitset(e.participant), "dds_create_waitset");
  for (const dds_entity_t r : {r_pose, r_vel, r_status}) {
    const dds_entity_t rc = check(dds_create_readcondition(r, DDS_ANY_STATE), "dds_create_readcondition");
    if (const dds_return_t a = dds_waitset_attach(ws, rc, r); a < 0) die("dds_waitset_attach", a);
  }

  std::int64_t pose_stamp = -1, vel_stamp = -1, answered_stamp = -1;
  double z = 0.0, vz = 0.0;
  long answered = 0;
  quadcosim_msgs_msg_dds__PlantStatus_ status{};
  std::vector<std::string> problems;
  const std::int64_t start = steady_ns();
  std::int64_t last_data = start;
  while (steady_ns() - start < 60'000'000'000) {
    if (answered_stamp >= end_ns && steady_ns() - last_data > 1'000'000'000) break;
    const dds_return_t w = dds_waitset_wait(ws, nullptr, 0, DDS_MSECS(50));
    if (w < 0) die("dds_waitset_wait", w);
    take_all<geometry_msgs_msg_dds__PoseStamped_>(r_pose, [&](const geometry_msgs_msg_dds__PoseStamped_& m) {
      pose_stamp = stamp_ns(m.header.stamp);
      z = m.pose.position.z;
      last_data = steady_ns();
    });
    take_all<geometry_msgs_msg_dds__TwistStamped_>(r_vel, [&](const geometry_msgs_msg_dds__TwistStamped_& m) {
      vel_stamp = stamp_ns(m.header.stamp);
      vz = m.twist.linear.z;
      last_data = steady_ns();
    });
    take_all<quadcosim_msgs_msg_dds__PlantStatus_>(r_status, [&](const quadcosim_msgs_msg_dds__PlantStatus_& m) {
      status = m;
      status.last_problem = nullptr;  // the loaned string goes back with the sample
      const std::string p = m.last_problem ? m.last_problem : "";
      if (!p.empty() && std::find(problems.begin(), problems.end(), p) == problems.end()) problems.push_back(p);
    });
    // A control tick's samples, both in, not answered yet, and every writer matched (an answer sent
    // before would go to no one).
    const std::int64_t s = pose_stamp;
    if (s < 0 || s != vel_stamp || s % kControlPeriodNs != 0 || s <= answered_stamp) continue;
    if (!std::all_of(writers.begin(), writers.end(), matched)) continue;
    answered_stamp = s;
    ++answered;
    const double thrust_n = kMass * kGravity + kKp * (kZDes - z) - kKd * vz;
    if (mode == "fly-velocity") {
      send_velocity(e, s, kKv * (kZDes - z));
      continue;
    }
    if (mode == "reject" && s == 0) {
      send_ctbr(e, s, std::nan(""));
    } else if (mode == "reject" && s == kControlPeriodNs) {
      quadcosim_msgs_msg_dds__RotorThrusts_ m{};
      m.header.stamp = time_of(s);
      double three[3] = {5.0, 5.0, 5.0};
      m.thrust_n._length = m.thrust_n._maximum = 3;
      m.thrust_n._buffer = three;
      if (const dds_return_t rc = dds_write(e.thrusts, &m); rc < 0) die("dds_write rotor_thrusts", rc);
    } else if (mode == "reject" && s == 50 * kControlPeriodNs) {
      quadcosim_msgs_msg_dds__ThrustAttitude_ m{};
      m.header.stamp = time_of(s);
      m.thrust_n = thrust_n;
      m.attitude = {0.0, 0.0, 0.0, 0.5};
      if (const dds_return_t rc = dds_write(e.attitude, &m); rc < 0) die("dds_write ctatt", rc);
    } else {
      send_ctbr(e, s, thrust_n);
      // The same tick commanded on a second topic.
      if (mode == "reject" && s == 2 * kControlPeriodNs) send_velocity(e, s, 0.0);
    }
  }

  std::string j = "{\"answered\":" + std::to_string(answered) + ",\"last_stamp_ns\":" + std::to_string(answered_stamp);
  j += ",\"status\":{\"accepted\":" + std::to_string(status.commands_accepted) +
       ",\"rejected_length\":" + std::to_string(status.commands_rejected_length) +
       ",\"rejected_non_finite\":" + std::to_string(status.commands_rejected_non_finite) +
       ",\"rejected_second_topic\":" + std::to_string(status.commands_rejected_second_topic) +
       ",\"rejected_bad_quaternion\":" + std::to_string(status.commands_rejected_bad_quaternion) +
       ",\"stale\":" + std::to_string(status.commands_stale) + ",\"problems\":[";
  for (std::size_t i = 0; i < problems.size(); ++i) j += (i ? "," : "") + json_string(problems[i].c_str());
  j += "]}}";
  std::printf("%s\n", j.c_str());
  std::fflush(stdout);
  dds_delete(e.participant);
  dds_delete(dom);
  return answered_stamp >= end_ns ? 0 : 3;
}
