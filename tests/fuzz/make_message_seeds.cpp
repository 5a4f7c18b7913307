// Writes seed inputs for fuzz_messages (format in fuzz_messages.cpp) into the directory given: valid
// traffic of a few ticks, and a few of the invalid messages the nodes must refuse.
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "io/ros2_cdr.hpp"

namespace {

using namespace quadcosim;
using Bytes = std::vector<std::uint8_t>;

void record(Bytes& out, int kind, const Bytes& cdr) {
  out.push_back(static_cast<std::uint8_t>(kind));
  out.push_back(static_cast<std::uint8_t>(cdr.size() & 0xff));
  out.push_back(static_cast<std::uint8_t>(cdr.size() >> 8));
  out.insert(out.end(), cdr.begin(), cdr.end());
}

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
  std::ofstream(dir + "/" + name, std::ios::binary).write(reinterpret_cast<const char*>(b.data()),
                                                           static_cast<std::streamsize>(b.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " OUT_DIR\n";
    return 2;
  }
  const std::string dir = argv[1];
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
  return 0;
}
