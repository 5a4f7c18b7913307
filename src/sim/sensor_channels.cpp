#include "sim/sensor_channels.hpp"

#include <algorithm>

#include "sim/sensor_wire.hpp"

namespace quadcosim::sim {

class SensorChannels::Channel {
 public:
  virtual ~Channel() = default;
  virtual const sensors::Timing& timing() const = 0;
  /// Publishes at tick k when due; `truth` is the state of tick max(k - latency, 0), at `truth_t_s`.
  virtual void publish(Tick k, const model::Outputs& truth, double truth_t_s, const msg::Time& stamp) = 0;
};

namespace {

/// A sensor model and its wire form (sim/sensor_wire.hpp) as a channel: samples once per due tick,
/// publishes on every visit of it.
template <class Wire>
class ChannelOf final : public SensorChannels::Channel {
 public:
  ChannelOf(typename Wire::Model model, Transport& t, const std::string& ns, const std::string& world_frame)
      : model_(std::move(model)), wire_(t, ns, world_frame) {}
  const sensors::Timing& timing() const override { return model_.config().timing; }
  void publish(Tick k, const model::Outputs& truth, double truth_t_s, const msg::Time& stamp) override {
    if (k % timing().divider != 0) return;
    if (k != sampled_) {
      sampled_ = k;
      if constexpr (requires { model_.measure(truth, truth_t_s); }) {
        wire_.fill(model_.measure(truth, truth_t_s), stamp);
      } else {
        wire_.fill(model_.measure(truth), stamp);
      }
    }
    wire_.publish();
  }

 private:
  typename Wire::Model model_;
  Wire wire_;
  Tick sampled_ = -1;
};

}  // namespace

SensorChannels::SensorChannels(const sensors::SensorSet& set, std::uint64_t seed, const std::string& ns,
                               const TickClock& clock, Transport& transport, const std::string& world_frame)
    : clock_(clock) {
  for_each_sensor(set, [&]<class Wire>(const auto& config) {
    const model::Rng rng(model::stream_seed(seed, ns, Wire::kName));
    channels_.push_back(std::make_unique<ChannelOf<Wire>>(Wire::make(config, rng, clock), transport, ns, world_frame));
  });
  int depth = 1;
  for (const auto& c : channels_) depth = std::max(depth, 1 + c->timing().latency_ticks);
  history_.resize(static_cast<std::size_t>(depth));
}

SensorChannels::~SensorChannels() = default;

const model::Outputs& SensorChannels::truth_at(Tick k) const {
  return history_[static_cast<std::size_t>(k % static_cast<Tick>(history_.size()))];
}

void SensorChannels::publish(Tick k, const model::Outputs& y, const msg::Time& stamp) {
  if (k != last_tick_) {
    last_tick_ = k;
    history_[static_cast<std::size_t>(k % static_cast<Tick>(history_.size()))] = y;
  }
  for (const auto& c : channels_) {
    const Tick measured = std::max<Tick>(k - c->timing().latency_ticks, 0);
    c->publish(k, truth_at(measured), clock_.seconds(measured), stamp);
  }
}

}  // namespace quadcosim::sim
