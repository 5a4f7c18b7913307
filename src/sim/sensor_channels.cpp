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
  ChannelOf(Transport& t, const std::string& ns, const std::string& world_frame) {
    Wire::init(messages_, world_frame);
    for_each_message<Wire>(ns, [&]<std::size_t I, class Message>(const std::string& topic) {
      std::get<I>(publishers_) = t.advertise<Message>(topic);
    });
  }
  void publish(const sensors::Suite& suite, Tick k, const msg::Time& stamp) override {
    if (!suite.due<typename Wire::Kind>(k)) return;
    if (k != filled_) {
      filled_ = k;
      Wire::fill(suite.slot<typename Wire::Kind>()->sample, stamp, messages_);
    }
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (std::get<I>(publishers_).publish(std::get<I>(messages_)), ...);
    }
    (std::make_index_sequence<std::tuple_size_v<typename Wire::Messages>>{});
  }

 private:
  template <class... M>
  static std::tuple<Publisher<M>...> publishers_of(std::tuple<M...>*);

  typename Wire::Messages messages_;
  decltype(publishers_of(static_cast<typename Wire::Messages*>(nullptr))) publishers_;
  Tick filled_ = -1;
};

}  // namespace

SensorChannels::SensorChannels(const sensors::SensorSet& set, const std::string& ns, Transport& transport,
                               const std::string& world_frame) {
  for_each_sensor(set, [&]<class Wire>(const auto&) {
    channels_.push_back(std::make_unique<ChannelOf<Wire>>(transport, ns, world_frame));
  });
}

SensorChannels::~SensorChannels() = default;

void SensorChannels::publish(const sensors::Suite& suite, Tick k, const msg::Time& stamp) {
  for (const auto& c : channels_) c->publish(suite, k, stamp);
}

}  // namespace quadcosim::sim
