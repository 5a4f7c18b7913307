// What the long-running node processes (`plant`, `controller`) share: the wall clock they pace and
// measure with, how they find their scenario, and the sensor-data QoS option.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "dds/dds_transport.hpp"
#include "io/scenario.hpp"
#include "sim/topics.hpp"

namespace quadcosim::app {

constexpr std::int64_t kMs = 1'000'000;  ///< [ns]

/// Monotonic wall clock [ns]; only the real-time loops and the latency figures read it.
inline std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// The scenario at `path` (the built-in defaults when empty), its vehicle replaced by the one in
/// `vehicle_file` when given. Throws io::ConfigError.
io::Scenario scenario_or_defaults(const std::string& path, const std::string& vehicle_file);

/// ROS sensor-data QoS (KEEP_LAST 5, BEST_EFFORT) on the three sensor topics.
void use_sensor_qos(dds::DdsTransport& transport, const sim::Topics& topics);

}  // namespace quadcosim::app
