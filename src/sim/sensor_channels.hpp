// The plant's extra sensors on the bus: the vehicle's sensor suite (sensors/suite.hpp: each sensor the
// scenario configures, sampled at its rate and latency) and, for each sensor, its wire form
// (sim/sensor_wire.hpp) that publishes the sample as its ROS message(s).
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
  /// Advertises the topic(s) of each configured sensor of `set` under `ns` ("/drone"), which also names
  /// the noise streams; `world_frame` is the frame id of world-frame data (the GNSS velocity).
  SensorChannels(const sensors::SensorSet& set, std::uint64_t seed, const std::string& ns, const TickClock& clock,
                 Transport& transport, const std::string& world_frame);
  ~SensorChannels();
  SensorChannels(const SensorChannels&) = delete;
  SensorChannels& operator=(const SensorChannels&) = delete;

  /// Tick k's truth `y`: publishes the sample of each sensor due at k (stamped `stamp`), measured on the
  /// truth of tick max(k - latency, 0). Ticks are visited in order; a tick visited again publishes the
  /// same samples.
  void publish(Tick k, const model::Outputs& y, const msg::Time& stamp);

  /// The samples (the newest of each sensor and its tick), as published.
  const sensors::Suite& suite() const { return suite_; }

  /// One configured sensor's wire form (sensor_channels.cpp).
  class Channel;

 private:
  sensors::Suite suite_;
  std::vector<std::unique_ptr<Channel>> channels_;
};

}  // namespace quadcosim::sim
