// The sensors a vehicle carries beyond the paper's Pose, Velocity and Imu. Each is off unless the
// scenario configures it (sensors.<name>), so a plant without them is the paper's, bit for bit.
//
// To add a sensor (docs/sensors.md, "Add a sensor"): its model (sensors/<name>.{hpp,cpp}: a config
// from datasheet parameters, truth -> an SI sample, its own random stream), a line here, its kind
// (sensors/registry.hpp: with its scenario keys) and its wire form (sim/sensor_wire.hpp: topics,
// messages, fill and read).
#pragma once

#include <optional>

#include "sensors/barometer.hpp"
#include "sensors/gnss.hpp"
#include "sensors/magnetometer.hpp"

namespace quadcosim::sensors {

struct SensorSet {
  std::optional<MagnetometerConfig> magnetometer;
  std::optional<BarometerConfig> barometer;
  std::optional<GnssConfig> gnss;

  bool any() const { return magnetometer || barometer || gnss; }
};

}  // namespace quadcosim::sensors
