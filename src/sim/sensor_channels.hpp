// The plant's extra sensors on the bus: each sensor the scenario configures (sensors::SensorSet,
// registered in sim/sensor_wire.hpp) is a channel that samples its model at its rate and latency and
// publishes the sample as its ROS message(s).
//
// Determinism: a tick's samples are drawn once; publishing the same tick again (a lockstep repeat)
// publishes the same samples. Each sensor draws from its own stream, model::stream_seed(seed, vehicle,
// sensor name), so adding one never changes the numbers of another or of the paper's sensors.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "model/quadrotor.hpp"
#include "sensors/sensor_set.hpp"
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

  /// One configured sensor on the bus (sensor_channels.cpp).
  class Channel;

 private:
  const model::Outputs& truth_at(Tick k) const;

  TickClock clock_;
  std::vector<std::unique_ptr<Channel>> channels_;
  std::vector<model::Outputs> history_;  ///< ring buffer of true outputs, max latency + 1 deep
  Tick last_tick_ = -1;
};

}  // namespace quadcosim::sim
