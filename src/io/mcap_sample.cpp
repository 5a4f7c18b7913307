// Test-only: writes an MCAP file of a simulated 100 Hz run the way the recorder does (the recorded
// topics and three of the sensor types (MagneticField, FluidPressure, NavSatFix), ros2 profile, CDR) and a JSON file of
// what it wrote, for mcap_interop_test.sh to compare with what the MCAP reference reader decodes.
//
//   mcap_sample full|plain|empty|killed OUT.mcap EXPECTED.json
//     full    200 ticks, 16 KiB zstd chunks (several chunks), closed normally
//     plain   the same, chunks uncompressed
//     empty   the channels and no message
//     killed  1 MiB chunks; ticks 0..99, flush(), ticks 100..149 (still in the open chunk), then the
//             process SIGKILLs itself without close(): EXPECTED.json describes ticks 0..99
//
// EXPECTED.json: {"profile", "library", "messages", "channels": {topic: {"schema", "count",
// "first"/"last": {"sequence", "log_time" (string, ns), "message" (ROS field names)}}}}.
#include <csignal>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "io/mcap_test_messages.hpp"
#include "io/mcap_writer.hpp"
#include "io/ros2_cdr.hpp"
#include "sim/topics.hpp"

namespace {

using nlohmann::json;
using namespace quadcosim;
namespace t = quadcosim::io::testing;

// The messages as ROS 2 field trees (what a ROS 2 decoder of the schema yields).
json j(const msg::Time& m) { return {{"sec", m.sec}, {"nanosec", m.nanosec}}; }
json j(const msg::Header& m) { return {{"stamp", j(m.stamp)}, {"frame_id", m.frame_id}}; }
json j(const msg::Vector3& m) { return {{"x", m.x}, {"y", m.y}, {"z", m.z}}; }
json j(const msg::Quaternion& m) { return {{"x", m.x}, {"y", m.y}, {"z", m.z}, {"w", m.w}}; }
json j(const msg::PoseStamped& m) {
  return {{"header", j(m.header)}, {"pose", {{"position", j(m.position)}, {"orientation", j(m.orientation)}}}};
}
json j(const msg::TwistStamped& m) {
  return {{"header", j(m.header)}, {"twist", {{"linear", j(m.linear)}, {"angular", j(m.angular)}}}};
}
json j(const msg::Imu& m) {
  return {{"header", j(m.header)},
          {"orientation", j(m.orientation)},
          {"orientation_covariance", m.orientation_covariance},
          {"angular_velocity", j(m.angular_velocity)},
          {"angular_velocity_covariance", m.angular_velocity_covariance},
          {"linear_acceleration", j(m.linear_acceleration)},
          {"linear_acceleration_covariance", m.linear_acceleration_covariance}};
}
json j(const msg::Float64MultiArray& m) {
  json dims = json::array();
  for (const auto& d : m.dim) dims.push_back({{"label", d.label}, {"size", d.size}, {"stride", d.stride}});
  return {{"layout", {{"dim", dims}, {"data_offset", m.data_offset}}}, {"data", m.data}};
}
json j(const msg::Clock& m) { return {{"clock", j(m.clock)}}; }
json j(const msg::ControllerStatus& m) {
  return {{"header", j(m.header)},
          {"controller", m.controller},
          {"mode", m.mode},
          {"setpoint", m.setpoint},
          {"u", m.u},
          {"position_error", m.position_error},
          {"yaw_error", m.yaw_error},
          {"attitude_error", m.attitude_error},
          {"rotor_saturated", m.rotor_saturated},
          {"tilt_saturated", m.tilt_saturated},
          {"safety", m.safety},
          {"rejected_non_finite", std::to_string(m.rejected_non_finite)},
          {"rejected_bad_quaternion", std::to_string(m.rejected_bad_quaternion)},
          {"rejected_bad_stamp", std::to_string(m.rejected_bad_stamp)},
          {"rejected_stamp_backwards", std::to_string(m.rejected_stamp_backwards)},
          {"rejected_stamp_ahead", std::to_string(m.rejected_stamp_ahead)},
          {"output_names", m.output_names},
          {"outputs", m.outputs}};
}
// uint64 fields as decimal strings: the reference reader decodes them as bigints, shown as strings.
json j(const msg::PlantStatus& m) {
  return {{"header", j(m.header)},
          {"commands_accepted", std::to_string(m.commands_accepted)},
          {"commands_clamped", std::to_string(m.commands_clamped)},
          {"commands_rejected_length", std::to_string(m.commands_rejected_length)},
          {"commands_rejected_non_finite", std::to_string(m.commands_rejected_non_finite)},
          {"last_problem", m.last_problem},
          {"watchdog_active", m.watchdog_active},
          {"watchdog_trips", std::to_string(m.watchdog_trips)},
          {"watchdog_ticks", std::to_string(m.watchdog_ticks)},
          {"commands_stale", std::to_string(m.commands_stale)},
          {"commands_foreign", std::to_string(m.commands_foreign)},
          {"commands_rejected_second_topic", std::to_string(m.commands_rejected_second_topic)},
          {"commands_rejected_bad_quaternion", std::to_string(m.commands_rejected_bad_quaternion)}};
}

json j(const msg::MagneticField& m) {
  return {{"header", j(m.header)},
          {"magnetic_field", j(m.magnetic_field)},
          {"magnetic_field_covariance", m.magnetic_field_covariance}};
}
json j(const msg::FluidPressure& m) {
  return {{"header", j(m.header)}, {"fluid_pressure", m.fluid_pressure}, {"variance", m.variance}};
}
json j(const msg::NavSatFix& m) {
  return {{"header", j(m.header)},
          {"status", {{"status", m.status.status}, {"service", m.status.service}}},
          {"latitude", m.latitude},
          {"longitude", m.longitude},
          {"altitude", m.altitude},
          {"position_covariance", m.position_covariance},
          {"position_covariance_type", m.position_covariance_type}};
}

// The sensor types at the rates and magnitudes of a magnetometer (50 Hz), a barometer (25 Hz) and a
// GNSS receiver (5 Hz); their topic names here are the sample's own.
const std::string kMagTopic = "/drone/sample/magnetic_field";
const std::string kBaroTopic = "/drone/sample/fluid_pressure";
const std::string kFixTopic = "/drone/sample/fix";
msg::MagneticField sample_mag(int i) {
  msg::MagneticField m;
  m.header = t::sample_header(i, "base_link");
  m.magnetic_field = {2.1e-5 + 1e-9 * i, -1.3e-6, 4.4e-5 - 2e-9 * i};
  for (int k = 0; k < 3; ++k) m.magnetic_field_covariance[4 * k] = 1e-14 * (k + 1);
  return m;
}
msg::FluidPressure sample_baro(int i) {
  msg::FluidPressure m;
  m.header = t::sample_header(i, "base_link");
  m.fluid_pressure = 101325.0 - 0.12 * i;
  m.variance = 0.25;
  return m;
}
msg::NavSatFix sample_fix(int i) {
  msg::NavSatFix m;
  m.header = t::sample_header(i, "gnss");
  m.status.status = i < 40 ? msg::NavSatStatus::kStatusNoFix : msg::NavSatStatus::kStatusSbasFix;
  m.status.service = msg::NavSatStatus::kServiceGps | msg::NavSatStatus::kServiceGalileo;
  m.latitude = 47.3977419 + 1e-8 * i;
  m.longitude = 8.5455938 - 1e-8 * i;
  m.altitude = 488.1 + 0.01 * i;
  m.position_covariance = {0.5625, 0, 0, 0, 0.5625, 0, 0, 0, 2.25};
  m.position_covariance_type = msg::NavSatFix::kCovarianceTypeDiagonalKnown;
  return m;
}

// One recorded topic: its channel and what has been written on it.
struct Topic {
  std::uint16_t channel = 0;
  std::string schema;
  std::uint32_t count = 0;
  json first, last;
};

class Recorder {
 public:
  Recorder(const std::string& path, io::McapOptions options) : writer_(path, std::move(options)) {}

  // How the recorder registers a topic: schema = the ROS type with its ros2msg text, channel with
  // the publisher's offered QoS.
  template <class T>
  void add(const std::string& topic) {
    const std::string type(T::kRosType);
    const auto schema = writer_.add_schema(type, "ros2msg", io::ros2msg_definition(type));
    topics_[topic].channel =
        writer_.add_channel(topic, schema, "cdr", {{"offered_qos_profiles", io::ros2_offered_qos_profiles(10, true)}});
    topics_[topic].schema = type;
  }

  // How the recorder writes one received message: CDR bytes, per-topic sequence, log time = the
  // message's simulated time (publish time the same).
  template <class T>
  void write(const std::string& topic, const T& m, std::int64_t t_ns) {
    Topic& tp = topics_.at(topic);
    const auto bytes = io::to_cdr(m);
    ++tp.count;
    const auto time = static_cast<std::uint64_t>(t_ns);
    writer_.write(tp.channel, tp.count, time, time, bytes.data(), bytes.size());
    const json entry = {{"sequence", tp.count}, {"log_time", std::to_string(time)}, {"message", j(m)}};
    if (tp.count == 1) tp.first = entry;
    tp.last = entry;
  }

  void ticks(const sim::Topics& topics, int from, int to) {
    for (int i = from; i < to; ++i) {
      const std::int64_t ns = t::tick_ns(i);
      write(topics.clock, t::sample_clock(i), ns);
      write(topics.pose, t::sample_pose(i), ns);
      write(topics.velocity, t::sample_twist(i), ns);
      write(topics.imu, t::sample_imu(i), ns);
      if (i % 100 == 0 || i % 37 == 5) write(topics.plant_status, t::sample_plant_status(i), ns);
      if (i % 2 == 0) write(kMagTopic, sample_mag(i), ns);
      if (i % 4 == 1) write(kBaroTopic, sample_baro(i), ns);
      if (i % 20 == 3) write(kFixTopic, sample_fix(i), ns);
      if (i % 2 == 0) {  // the controller at 50 Hz
        write(topics.controller_status, t::sample_status(i), ns);
        write(topics.motor_commands, t::sample_command(i), ns);
      }
    }
  }

  void save_expected(const std::string& path, const std::string& profile) const {
    json channels = json::object();
    std::uint64_t total = 0;
    for (const auto& [name, tp] : topics_) {
      channels[name] = {{"schema", tp.schema}, {"count", tp.count}, {"first", tp.first}, {"last", tp.last}};
      total += tp.count;
    }
    const json out = {{"profile", profile},
                      {"library", std::string("quadcosim ") + QUADCOSIM_VERSION},
                      {"messages", total},
                      {"channels", channels}};
    std::ofstream(path) << out.dump(1) << "\n";
  }

  io::McapWriter& writer() { return writer_; }

 private:
  io::McapWriter writer_;
  std::map<std::string, Topic> topics_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: " << argv[0] << " full|plain|empty|killed OUT.mcap EXPECTED.json\n";
    return 2;
  }
  const std::string mode = argv[1];
  if (mode != "full" && mode != "plain" && mode != "empty" && mode != "killed") {
    std::cerr << "mcap_sample: unknown mode '" << mode << "'\n";
    return 2;
  }
  try {
    io::McapOptions options;
    if (mode != "killed") options.chunk_size = 16 * 1024;
    options.compress = mode != "plain";
    Recorder rec(argv[2], options);
    const sim::Topics topics = sim::Topics::for_namespace("/drone");
    rec.add<msg::Clock>(topics.clock);
    rec.add<msg::PoseStamped>(topics.pose);
    rec.add<msg::TwistStamped>(topics.velocity);
    rec.add<msg::Imu>(topics.imu);
    rec.add<msg::ControllerStatus>(topics.controller_status);
    rec.add<msg::PlantStatus>(topics.plant_status);
    rec.add<msg::Float64MultiArray>(topics.motor_commands);
    rec.add<msg::MagneticField>(kMagTopic);
    rec.add<msg::FluidPressure>(kBaroTopic);
    rec.add<msg::NavSatFix>(kFixTopic);
    if (mode == "killed") {
      rec.ticks(topics, 0, 100);
      rec.writer().flush();
      rec.save_expected(argv[3], options.profile);
      rec.ticks(topics, 100, 150);
      std::cout.flush();
      std::raise(SIGKILL);  // no close(), no destructors: what `kill -9` of the recorder leaves
    }
    rec.ticks(topics, 0, mode == "empty" ? 0 : 200);
    rec.writer().close();
    rec.save_expected(argv[3], options.profile);
  } catch (const std::exception& e) {
    std::cerr << "mcap_sample: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
