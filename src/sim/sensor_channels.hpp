// The plant's extra sensors on the bus: for each sensor the scenario configures, its wire form
// (sim/sensor_wire.hpp) that publishes the vehicle's sample (the sensors::Suite the plant's core steps)
// as its ROS message(s).
//
// Determinism: a tick's samples are drawn once (the suite's rule); publishing the same tick again (a
// lockstep repeat) publishes the same samples.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "model/quadrotor.hpp"
#include "sensors/suite.hpp"
#include "sim/clock.hpp"
#include "sim/messages.hpp"
#include "sim/transport.hpp"

namespace quadcosim::sim {

class SensorChannels {
 public:
  /// Advertises the topic(s) of each configured sensor of `set` under `ns` ("/drone"); `world_frame` is
  /// the frame id of world-frame data (the GNSS velocity).
  SensorChannels(const sensors::SensorSet& set, const std::string& ns, Transport& transport,
                 const std::string& world_frame);
  ~SensorChannels();
  SensorChannels(const SensorChannels&) = delete;
  SensorChannels& operator=(const SensorChannels&) = delete;

  /// Publishes the sample of each sensor of `suite` due at tick k (stamped `stamp`); the suite has
  /// stepped to k. A tick published again publishes the same samples.
  void publish(const sensors::Suite& suite, Tick k, const msg::Time& stamp);

  /// One configured sensor's wire form (sensor_channels.cpp).
  class Channel;

 private:
  std::vector<std::unique_ptr<Channel>> channels_;
};

}  // namespace quadcosim::sim
