#include "sim/sensor_channels.hpp"

#include "sim/sensor_wire.hpp"

namespace quadcosim::sim {

class SensorChannels::Channel {
 public:
  virtual ~Channel() = default;
  /// Publishes the suite's sample of tick k when the sensor was due at k.
  virtual void publish(const sensors::Suite& suite, Tick k, const msg::Time& stamp) = 0;
};

namespace {

/// A sensor's wire form (sim/sensor_wire.hpp) as a channel: fills its messages once per sample,
/// publishes them on every visit of a due tick.
template <class Wire>
class ChannelOf final : public SensorChannels::Channel {
 public:
  ChannelOf(Transport& t, const std::string& ns, const std::string& world_frame) : wire_(t, ns, world_frame) {}
  void publish(const sensors::Suite& suite, Tick k, const msg::Time& stamp) override {
    if (!suite.due<typename Wire::Kind>(k)) return;
    if (k != filled_) {
      filled_ = k;
      wire_.fill(suite.slot<typename Wire::Kind>()->sample, stamp);
    }
    wire_.publish();
  }

 private:
  Wire wire_;
  Tick filled_ = -1;
};

}  // namespace

SensorChannels::SensorChannels(const sensors::SensorSet& set, std::uint64_t seed, const std::string& ns,
                               const TickClock& clock, Transport& transport, const std::string& world_frame)
    : suite_(set, seed, ns, clock.period_ns) {
  for_each_sensor(set, [&]<class Wire>(const auto&) {
    channels_.push_back(std::make_unique<ChannelOf<Wire>>(transport, ns, world_frame));
  });
}

SensorChannels::~SensorChannels() = default;

void SensorChannels::publish(Tick k, const model::Outputs& y, const msg::Time& stamp) {
  if (!suite_.step(k, y)) return;
  for (const auto& c : channels_) c->publish(suite_, k, stamp);
}

}  // namespace quadcosim::sim
