// A "foreign" ROS 2 participant: plays the part of an rclcpp node on rmw_cyclonedds_cpp, written only
// from the wire facts in docs/ros2.md, "What is on the wire" (topic names rt/..., type names pkg::msg::dds_::Name_,
// final XCDR1 types without type information, ROS QoS, USER_DATA "enclave=/;", the LOCALHOST
// discovery configuration). It includes and links nothing of quadcosim: its types come from its own
// IDL (tests/foreign/idl) through idlc, and it talks through the plain Cyclone DDS C API.
//
// Usage: foreign_controller SECONDS [NO_DATA_TIMEOUT_S]
//   Subscribes rt/drone/Pose, rt/drone/Velocity, rt/drone/Imu (ROS default QoS) and rt/clock (best
//   effort, depth 1, as rclcpp's clock subscription), and publishes rt/drone/motor_commands
//   (std_msgs/Float64MultiArray, 4 rotor speeds [rad/s], empty layout) at 50 Hz of wall-clock time
//   from its own altitude PD to z = 2 m with gravity feed-forward, equal speeds on all rotors.
//   Runs SECONDS of wall time (or until SIGINT/SIGTERM), then prints one JSON line to stdout with
//   what it saw. Exit 0 when it received Pose samples; 3 with a message on stderr when nothing
//   arrived on rt/drone/Pose within NO_DATA_TIMEOUT_S (default 5 s); 2 on bad usage or a DDS error.
#include <dds/dds.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "foreign_participant.hpp"
#include "geometry_msgs.h"
#include "rosgraph_msgs.h"
#include "sensor_msgs.h"
#include "std_msgs.h"

using namespace foreign;

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) { g_stop = 1; }

// The vehicle of the paper and the controller's gains.
constexpr double kMass = 1.96;                         // [kg]
constexpr double kGravity = 9.81;                      // [m/s^2]
constexpr double kThrust = 2.06e-7;                    // k_t [N/(rad/s)^2]
constexpr double kZDes = 2.0;                          // [m]
constexpr double kKp = 4.0;                            // [N/m]
constexpr double kKd = 2.7;                            // [N s/m]
constexpr std::int64_t kControlPeriodNs = 20'000'000;  // 50 Hz

// Every QoS policy rmw_cyclonedds sets, set explicitly (Cyclone's own defaults differ).
dds_qos_t* ros_qos(bool reliable, int32_t depth) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  if (reliable) {
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_INFINITY);
  } else {
    dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
  }
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_INFINITY);
  dds_qset_writer_data_lifecycle(q, false);
  const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q, 1, xcdr1);
  return q;
}

double stamp_s(const builtin_interfaces_msg_dds__Time_& t) {
  return static_cast<double>(t.sec) + static_cast<double>(t.nanosec) * 1e-9;
}
std::int64_t stamp_ns(const builtin_interfaces_msg_dds__Time_& t) {
  return static_cast<std::int64_t>(t.sec) * 1'000'000'000 + t.nanosec;
}

std::string json_string(const char* s) {
  std::string out = "\"";
  for (const char* p = s ? s : ""; *p; ++p) {
    const unsigned char c = static_cast<unsigned char>(*p);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// What one subscription saw.
struct Seen {
  long count = 0;
  long stamp_errors = 0;  // nanosec >= 1e9 or a stamp not after the previous one
  std::int64_t last_stamp_ns = -1;
  double last_stamp_s = NAN;
  std::string frame_id;
  void stamp(const builtin_interfaces_msg_dds__Time_& t) {
    ++count;
    const std::int64_t ns = stamp_ns(t);
    if (t.nanosec >= 1'000'000'000u || ns <= last_stamp_ns) ++stamp_errors;
    last_stamp_ns = ns;
    last_stamp_s = stamp_s(t);
  }
};

// What the other side announced in discovery (the DDS built-in topics), as a JSON object:
// {"participants":[user_data...], "endpoints":[{topic, kind, type, reliable, transient_local, xcdr}]}
// for the remote endpoints on the topics we use. All of it is what any ROS 2 tool would see.
std::string remote_discovery(dds_entity_t participant) {
  dds_guid_t own;
  dds_get_guid(participant, &own);
  std::string parts, ends;
  const dds_entity_t rp = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr);
  if (rp >= 0) {
    void* samples[64] = {};
    dds_sample_info_t infos[64];
    const dds_return_t n = dds_read(rp, samples, infos, 64, 64);
    for (int i = 0; i < n; ++i) {
      const auto* p = static_cast<const dds_builtintopic_participant_t*>(samples[i]);
      if (!infos[i].valid_data || std::memcmp(&p->key, &own, sizeof own) == 0) continue;
      void* ud = nullptr;
      size_t sz = 0;
      std::string u;
      if (dds_qget_userdata(p->qos, &ud, &sz) && ud != nullptr) u.assign(static_cast<const char*>(ud), sz);
      dds_free(ud);
      parts += (parts.empty() ? "" : ",") + json_string(u.c_str());
    }
    if (n > 0) dds_return_loan(rp, samples, n);
  }
  const dds_entity_t kinds[2] = {DDS_BUILTIN_TOPIC_DCPSPUBLICATION, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION};
  for (int k = 0; k < 2; ++k) {
    const dds_entity_t r = dds_create_reader(participant, kinds[k], nullptr, nullptr);
    if (r < 0) continue;
    void* samples[256] = {};
    dds_sample_info_t infos[256];
    const dds_return_t n = dds_read(r, samples, infos, 256, 256);
    for (int i = 0; i < n; ++i) {
      const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      if (!infos[i].valid_data || std::memcmp(&e->participant_key, &own, sizeof own) == 0) continue;
      const std::string topic = e->topic_name ? e->topic_name : "";
      if (topic.rfind("rt/drone/", 0) != 0 && topic != "rt/clock") continue;
      dds_reliability_kind_t rel = DDS_RELIABILITY_BEST_EFFORT;
      dds_duration_t blocking = 0;
      dds_qget_reliability(e->qos, &rel, &blocking);
      dds_durability_kind_t dur = DDS_DURABILITY_VOLATILE;
      dds_qget_durability(e->qos, &dur);
      uint32_t nrep = 0;
      dds_data_representation_id_t* reps = nullptr;
      std::string xcdr;
      if (dds_qget_data_representation(e->qos, &nrep, &reps)) {
        for (uint32_t j = 0; j < nrep; ++j) {
          if (j > 0) xcdr += ',';
          xcdr += reps[j] == DDS_DATA_REPRESENTATION_XCDR1 ? '1' : '2';
        }
      }
      dds_free(reps);
      ends += std::string(ends.empty() ? "" : ",") + "{\"topic\":" + json_string(topic.c_str()) + ",\"kind\":\"" +
              (k == 0 ? "writer" : "reader") + "\",\"type\":" + json_string(e->type_name) +
              ",\"reliable\":" + (rel == DDS_RELIABILITY_RELIABLE ? "true" : "false") +
              ",\"transient_local\":" + (dur == DDS_DURABILITY_VOLATILE ? "false" : "true") + ",\"xcdr\":[" + xcdr +
              "]}";
    }
    if (n > 0) dds_return_loan(r, samples, n);
  }
  return "{\"participants\":[" + parts + "],\"endpoints\":[" + ends + "]}";
}

}  // namespace

int main(int argc, char** argv) {
  foreign::program = "foreign_controller";
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s SECONDS [NO_DATA_TIMEOUT_S]\n", argv[0]);
    return 2;
  }
  const double run_s = std::atof(argv[1]);
  const double wait_s = argc > 2 ? std::atof(argv[2]) : 5.0;
  if (!(run_s > 0.0) || !(wait_s > 0.0)) {
    std::fprintf(stderr, "foreign_controller: SECONDS and NO_DATA_TIMEOUT_S must be > 0\n");
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  const dds_domainid_t domain = ros_domain_id();
  const std::string config = localhost_config();
  const dds_entity_t dom = check(dds_create_domain(domain, config.c_str()), "dds_create_domain");

  dds_qos_t* pqos = dds_create_qos();
  static const char kEnclave[] = "enclave=/;";
  dds_qset_userdata(pqos, kEnclave, sizeof kEnclave - 1);
  const dds_entity_t participant = check(dds_create_participant(domain, pqos, nullptr), "dds_create_participant");
  dds_delete_qos(pqos);

  const dds_entity_t t_pose =
      check(dds_create_topic(participant, &geometry_msgs_msg_dds__PoseStamped__desc, "rt/drone/Pose", nullptr, nullptr),
            "dds_create_topic rt/drone/Pose");
  const dds_entity_t t_vel = check(
      dds_create_topic(participant, &geometry_msgs_msg_dds__TwistStamped__desc, "rt/drone/Velocity", nullptr, nullptr),
      "dds_create_topic rt/drone/Velocity");
  const dds_entity_t t_imu =
      check(dds_create_topic(participant, &sensor_msgs_msg_dds__Imu__desc, "rt/drone/Imu", nullptr, nullptr),
            "dds_create_topic rt/drone/Imu");
  const dds_entity_t t_clock =
      check(dds_create_topic(participant, &rosgraph_msgs_msg_dds__Clock__desc, "rt/clock", nullptr, nullptr),
            "dds_create_topic rt/clock");
  const dds_entity_t t_cmd = check(dds_create_topic(participant, &std_msgs_msg_dds__Float64MultiArray__desc,
                                                    "rt/drone/motor_commands", nullptr, nullptr),
                                   "dds_create_topic rt/drone/motor_commands");

  dds_qos_t* dflt = ros_qos(true, 10);    // ROS default profile
  dds_qos_t* clockq = ros_qos(false, 1);  // rclcpp ClockQoS
  const dds_entity_t r_pose = check(dds_create_reader(participant, t_pose, dflt, nullptr), "reader Pose");
  const dds_entity_t r_vel = check(dds_create_reader(participant, t_vel, dflt, nullptr), "reader Velocity");
  const dds_entity_t r_imu = check(dds_create_reader(participant, t_imu, dflt, nullptr), "reader Imu");
  const dds_entity_t r_clock = check(dds_create_reader(participant, t_clock, clockq, nullptr), "reader clock");
  const dds_entity_t w_cmd = check(dds_create_writer(participant, t_cmd, dflt, nullptr), "writer motor_commands");
  dds_delete_qos(dflt);
  dds_delete_qos(clockq);

  const dds_entity_t ws = check(dds_create_waitset(participant), "dds_create_waitset");
  const dds_entity_t readers[] = {r_pose, r_vel, r_imu, r_clock};
  for (const dds_entity_t r : readers) {
    const dds_entity_t rc = check(dds_create_readcondition(r, DDS_ANY_STATE), "dds_create_readcondition");
    if (const dds_return_t a = dds_waitset_attach(ws, rc, r); a < 0) die("dds_waitset_attach", a);
  }

  Seen pose, vel, imu, clk;
  double z = NAN, vz = 0.0, quat_norm = NAN, imu_quat_norm = NAN, imu_az = NAN;
  long commands_sent = 0;
  double last_command = NAN;

  const std::int64_t start = steady_ns();
  const std::int64_t end = start + static_cast<std::int64_t>(run_s * 1e9);
  const std::int64_t no_data_deadline = start + static_cast<std::int64_t>(wait_s * 1e9);
  std::int64_t next_control = start;
  bool no_data = false;

  while (!g_stop) {
    const std::int64_t now = steady_ns();
    if (now >= end) break;
    if (pose.count == 0 && now >= no_data_deadline) {
      no_data = true;
      break;
    }
    const std::int64_t wake = std::min({end, next_control, pose.count == 0 ? no_data_deadline : end});
    // At most 20 ms per wait, so a signal is noticed promptly.
    const dds_return_t w = dds_waitset_wait(ws, nullptr, 0, std::max<std::int64_t>(0, wake - now));
    if (w < 0) die("dds_waitset_wait", w);

    take_all<geometry_msgs_msg_dds__PoseStamped_>(r_pose, [&](const geometry_msgs_msg_dds__PoseStamped_& m) {
      pose.stamp(m.header.stamp);
      pose.frame_id = m.header.frame_id ? m.header.frame_id : "";
      z = m.pose.position.z;
      const auto& q = m.pose.orientation;
      quat_norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    });
    take_all<geometry_msgs_msg_dds__TwistStamped_>(r_vel, [&](const geometry_msgs_msg_dds__TwistStamped_& m) {
      vel.stamp(m.header.stamp);
      vel.frame_id = m.header.frame_id ? m.header.frame_id : "";
      vz = m.twist.linear.z;
    });
    take_all<sensor_msgs_msg_dds__Imu_>(r_imu, [&](const sensor_msgs_msg_dds__Imu_& m) {
      imu.stamp(m.header.stamp);
      imu.frame_id = m.header.frame_id ? m.header.frame_id : "";
      imu_az = m.linear_acceleration.z;
      const auto& q = m.orientation;
      imu_quat_norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    });
    take_all<rosgraph_msgs_msg_dds__Clock_>(r_clock,
                                            [&](const rosgraph_msgs_msg_dds__Clock_& m) { clk.stamp(m.clock); });

    const std::int64_t t = steady_ns();
    if (t >= next_control) {
      // Our own 50 Hz wall-clock timer; skip missed ticks instead of bursting.
      while (next_control <= t) next_control += kControlPeriodNs;
      if (pose.count > 0) {  // no state, no command
        const double force = kMass * kGravity + kKp * (kZDes - z) - kKd * vz;
        const double w_rotor = std::sqrt(std::max(0.0, force / (4.0 * kThrust)));
        double data[4] = {w_rotor, w_rotor, w_rotor, w_rotor};
        std_msgs_msg_dds__Float64MultiArray_ cmd;
        std::memset(&cmd, 0, sizeof cmd);
        cmd.layout.dim._length = 0;  // empty layout: no dimensions, data_offset 0
        cmd.layout.dim._maximum = 0;
        cmd.layout.dim._buffer = nullptr;
        cmd.layout.data_offset = 0;
        cmd.data._length = 4;
        cmd.data._maximum = 4;
        cmd.data._buffer = data;
        cmd.data._release = false;
        if (const dds_return_t rc = dds_write(w_cmd, &cmd); rc < 0) die("dds_write", rc);
        ++commands_sent;
        last_command = w_rotor;
      }
    }
  }

  dds_publication_matched_status_t pm{};
  dds_get_publication_matched_status(w_cmd, &pm);
  long matched[4] = {};
  for (int i = 0; i < 4; ++i) {
    dds_subscription_matched_status_t sm{};
    dds_get_subscription_matched_status(readers[i], &sm);
    matched[i] = static_cast<long>(sm.total_count);
  }

  std::string j = "{";
  j += "\"domain\":" + std::to_string(domain);
  j += ",\"counts\":{\"pose\":" + std::to_string(pose.count) + ",\"velocity\":" + std::to_string(vel.count) +
       ",\"imu\":" + std::to_string(imu.count) + ",\"clock\":" + std::to_string(clk.count) + "}";
  j += ",\"stamp_errors\":{\"pose\":" + std::to_string(pose.stamp_errors) +
       ",\"velocity\":" + std::to_string(vel.stamp_errors) + ",\"imu\":" + std::to_string(imu.stamp_errors) +
       ",\"clock\":" + std::to_string(clk.stamp_errors) + "}";
  j += ",\"last_z\":" + num(z) + ",\"last_vz\":" + num(vz);
  j += ",\"last_stamp\":" + num(pose.last_stamp_s) + ",\"last_clock\":" + num(clk.last_stamp_s);
  j += ",\"frame_ids\":{\"pose\":" + json_string(pose.frame_id.c_str()) +
       ",\"velocity\":" + json_string(vel.frame_id.c_str()) + ",\"imu\":" + json_string(imu.frame_id.c_str()) + "}";
  j += ",\"imu_linear_acceleration_z\":" + num(imu_az);
  j += ",\"quaternion_norm\":" + num(quat_norm) + ",\"imu_quaternion_norm\":" + num(imu_quat_norm);
  j += ",\"commands_sent\":" + std::to_string(commands_sent) + ",\"last_command\":" + num(last_command);
  j += ",\"matched\":{\"pose\":" + std::to_string(matched[0]) + ",\"velocity\":" + std::to_string(matched[1]) +
       ",\"imu\":" + std::to_string(matched[2]) + ",\"clock\":" + std::to_string(matched[3]) +
       ",\"motor_commands\":" + std::to_string(pm.total_count) + "}";
  j += ",\"remote\":" + remote_discovery(participant);
  j += ",\"stopped_by_signal\":" + std::string(g_stop ? "true" : "false");
  j += "}";
  std::printf("%s\n", j.c_str());
  std::fflush(stdout);

  dds_delete(participant);
  dds_delete(dom);

  if (no_data || pose.count == 0) {
    std::fprintf(stderr,
                 "foreign_controller: no sample on rt/drone/Pose %s %g s on domain %u "
                 "(matched publishers: Pose %ld, Velocity %ld, Imu %ld, clock %ld)\n",
                 no_data ? "within" : "before being stopped after", (steady_ns() - start) / 1e9,
                 static_cast<unsigned>(domain), matched[0], matched[1], matched[2], matched[3]);
    return 3;
  }
  return 0;
}
