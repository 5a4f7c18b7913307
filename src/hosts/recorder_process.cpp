// The recorder process (`quadcosim record`): like `ros2 bag record`, for runs where quadcosim is only
// one side.
#include "hosts/recorder_process.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>

#include "dds/dds_transport.hpp"
#include "hosts/exit_code.hpp"
#include "hosts/recording.hpp"
#include "hosts/signals.hpp"
#include "sim/topics.hpp"

namespace quadcosim::hosts {

int run_recorder(const RecorderOptions& o) {
  install_stop_handlers();
  if (std::string err = sim::validate_namespace(o.ns); !err.empty()) {
    std::cerr << "error: --namespace: " << err << '\n';
    return exit_code::kBadInput;
  }
  const sim::Topics topics = sim::Topics::for_namespace(o.ns);
  std::vector<std::string> known = {
      topics.clock,        topics.pose,           topics.velocity, topics.imu, topics.controller_status,
      topics.plant_status, topics.motor_commands, topics.tf};
  known.insert(known.end(), topics.level_commands.begin(), topics.level_commands.end());
  for (const auto& t : o.topics) {
    if (std::find(known.begin(), known.end(), t) == known.end()) {
      std::string list;
      for (const auto& k : known) list += " " + k;
      std::cerr << "error: --topics: cannot record '" << t << "'; known topics:" << list << '\n';
      return exit_code::kBadInput;
    }
  }
  const std::filesystem::path parent = std::filesystem::path(o.out).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);  // a bag folder, as ros2 bag makes
  dds::DdsTransport transport(dds::read_ros_environment(o.enclave));
  RecordingOptions ro;
  ro.mcap = o.out;
  ro.ns = o.ns;
  ro.topics = o.topics;
  ro.live = true;  // no plant ticks here: written a second of simulated time behind the newest message
  io::Recording recording = make_recording(ro, &transport);
  std::cerr << fmt::format("record: domain {}, writing {} (Ctrl-C to stop)\n", transport.participant().domain_id(),
                           o.out);
  const auto start = std::chrono::steady_clock::now();
  while (!stop_requested()) {
    if (o.duration_s >= 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= o.duration_s) {
      break;
    }
    transport.spin_once(100'000'000);
    recording.idle();
  }
  while (transport.spin_once(0) > 0) {
  }
  recording.finish(true);
  std::cerr << fmt::format("record: {} messages\n", recording.mcap()->messages());
  return exit_code::kOk;
}

}  // namespace quadcosim::hosts
