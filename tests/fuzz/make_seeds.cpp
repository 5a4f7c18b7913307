// Writes the seed inputs of fuzz_messages and fuzz_parameters (formats in their sources) into
// CORPUS_DIR/fuzz_messages and CORPUS_DIR/fuzz_parameters: valid traffic of a few ticks and a few of
// the invalid messages the nodes must refuse; one request of each parameter service, valid and not.
// Messages are serialised by io::to_cdr (byte-identical to Cyclone), requests by Cyclone itself.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "cyclone_bytes.hpp"
#include "dds/parameter_wire.hpp"
#include "io/ros2_cdr.hpp"

namespace {

using namespace quadcosim;
using Bytes = std::vector<std::uint8_t>;

void record(Bytes& out, int kind, const Bytes& cdr) { fuzz::append_record(out, kind, cdr); }

msg::Float64MultiArray command(std::vector<double> w, std::int64_t stamp_ns) {
  msg::Float64MultiArray m;
  m.data = std::move(w);
  m.dim = {{msg::command_label(stamp_ns), 4, 4}};
  return m;
}

msg::Header header(std::int64_t ns, const char* frame) { return {msg::Time::from_ns(ns), frame}; }

// One plant tick of sensor data as the plant sends it, at height z.
void sensors(Bytes& out, std::int64_t ns, double z, double q_w = 1.0) {
  msg::PoseStamped p;
  p.header = header(ns, "world");
  p.position = {0.0, 0.0, z};
  p.orientation.w = q_w;
  record(out, 1, io::to_cdr(p));
  msg::TwistStamped t;
  t.header = header(ns, "world");
  record(out, 2, io::to_cdr(t));
  msg::Imu i;
  i.header = header(ns, "base_link");
  i.orientation.w = q_w;
  i.linear_acceleration.z = 9.81;
  record(out, 3, io::to_cdr(i));
}

void save(const std::string& dir, const std::string& name, const Bytes& b) {
  std::ofstream(dir + "/" + name, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

// One request per service as `ros2 param` would send it, and some the node must refuse.
void write_parameter_seeds(const std::string& dir) {
  using dds::ParamService;
  using dds::ParamValue;
  auto participant = fuzz::isolated_participant();
  auto request = [&](ParamService service, auto fill) {
    const dds_topic_descriptor_t* desc = dds::wire::service_types(service).request;
    const fuzz::LocalTopic topic(*participant, desc,
                                 "rq/seed/" + std::string(dds::service_suffix(service)) + "Request");
    auto sample = dds::wire::new_sample(desc);
    fill(sample.get());
    Bytes out;
    record(out, static_cast<int>(service), topic.to_bytes(sample.get()));
    return out;
  };
  auto names = [](std::vector<std::string> v) { return v; };
  auto set = [&](ParamService service, std::vector<dds::Param> params) {
    return request(service, [&](void* s) {
      if (service == ParamService::kSet) {
        auto& rq = *static_cast<rcl_interfaces_srv_dds__SetParameters_Request_*>(s);
        rq.guid = 1;
        rq.seq = 1;
        dds::wire::to_c(params, rq.parameters);
      } else {
        auto& rq = *static_cast<rcl_interfaces_srv_dds__SetParametersAtomically_Request_*>(s);
        rq.guid = 1;
        rq.seq = 2;
        dds::wire::to_c(params, rq.parameters);
      }
    });
  };
  const Bytes get = request(ParamService::kGet, [&](void* s) {
    auto& rq = *static_cast<rcl_interfaces_srv_dds__GetParameters_Request_*>(s);
    dds::wire::to_c(names({"z_des", "lqr.roll.r", "mode"}), rq.names);
  });
  const Bytes types = request(ParamService::kGetTypes, [&](void* s) {
    auto& rq = *static_cast<rcl_interfaces_srv_dds__GetParameterTypes_Request_*>(s);
    dds::wire::to_c(names({"z_des", "safety_mode", "nope"}), rq.names);
  });
  const Bytes describe = request(ParamService::kDescribe, [&](void* s) {
    auto& rq = *static_cast<rcl_interfaces_srv_dds__DescribeParameters_Request_*>(s);
    dds::wire::to_c(names({"altitude.kp", "position.max_tilt"}), rq.names);
  });
  const Bytes list = request(ParamService::kList, [&](void* s) {
    auto& rq = *static_cast<rcl_interfaces_srv_dds__ListParameters_Request_*>(s);
    dds::wire::to_c(names({"lqr"}), rq.prefixes);
    rq.depth = 0;
  });
  const Bytes good_set = set(ParamService::kSet, {{"z_des", ParamValue::of_double(2.0)},
                                                  {"lqr.pitch.r", ParamValue::of_integer(50)},
                                                  {"mode", ParamValue::of_string("position")}});
  const Bytes bad_set = set(ParamService::kSet, {{"z_des", ParamValue::of_double(1e300)},
                                                 {"mode", ParamValue::of_string("hover")},
                                                 {"safety_mode", ParamValue::of_bool(true)},
                                                 {"lqr.roll.r", ParamValue::of_double(0.0)},
                                                 {"no_such", ParamValue::of_double(1.0)}});
  const Bytes atomic = set(ParamService::kSetAtomically,
                           {{"altitude.kp", ParamValue::of_double(6.0)}, {"altitude.kd", ParamValue::of_double(-1.0)}});
  save(dir, "queries", [&] {
    Bytes b = get;
    for (const Bytes* x : {&types, &describe, &list}) b.insert(b.end(), x->begin(), x->end());
    return b;
  }());
  save(dir, "set_valid", good_set);
  save(dir, "set_refused", bad_set);
  save(dir, "set_atomically", atomic);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " CORPUS_DIR\n";
    return 2;
  }
  const std::string dir = std::string(argv[1]) + "/fuzz_messages";
  std::filesystem::create_directories(dir);
  std::filesystem::create_directories(std::string(argv[1]) + "/fuzz_parameters");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double hover = 4830.6;

  Bytes valid;
  for (int k = 0; k < 6; ++k) {
    sensors(valid, k * 10'000'000LL, 1.0 + 0.01 * k);
    record(valid, 0, io::to_cdr(command({hover, hover, hover, hover}, k * 10'000'000LL)));
  }
  save(dir, "valid_ticks", valid);

  Bytes bad_commands;
  record(bad_commands, 0, io::to_cdr(command({1, 2, 3}, 0)));
  record(bad_commands, 0, io::to_cdr(command({}, 0)));
  record(bad_commands, 0, io::to_cdr(command({hover, nan, hover, hover}, 0)));
  record(bad_commands, 0, io::to_cdr(command({-1.0, 1e9, hover, hover}, 0)));
  save(dir, "bad_commands", bad_commands);

  Bytes bad_sensors;
  sensors(bad_sensors, 20'000'000, 1.0, 0.0);  // zero quaternion
  sensors(bad_sensors, 10'000'000, 1.0);       // stamp backwards after the next valid one
  sensors(bad_sensors, 30'000'000, nan);       // NaN position
  save(dir, "bad_sensors", bad_sensors);

  write_parameter_seeds(std::string(argv[1]) + "/fuzz_parameters");
  return 0;
}
