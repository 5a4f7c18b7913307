// Deterministic in-process transport: publish() delivers synchronously to every subscriber of the
// topic, in subscription order. No threads, no clocks, no copies beyond the caller's message.
// Optionally injects faults (sim/faults.hpp): seeded drops, and delays of whole ticks, for which the
// message is copied and delivered by advance_to() at the start of its tick.
#pragma once

#include <array>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sim/clock.hpp"
#include "sim/faults.hpp"
#include "sim/transport.hpp"

namespace quadcosim::sim {

class InProcessTransport final : public Transport {
 public:
  InProcessTransport() = default;
  // channels_ and the sinks point into inline_channels_: a copy or move would leave them pointing at
  // the original.
  InProcessTransport(const InProcessTransport&) = delete;
  InProcessTransport& operator=(const InProcessTransport&) = delete;
  /// Messages delivered so far, per topic.
  std::uint64_t delivered(const std::string& topic) const;

  /// Injects `faults` into every later publication on their topics (call before publishing).
  void set_faults(const FaultConfig& faults);
  /// Delivers the delayed messages due by tick k, oldest first; publications after this call belong
  /// to tick k. Without delays it only sets the tick.
  void advance_to(Tick k);
  /// Messages lost to injected faults so far on `topic`.
  std::uint64_t dropped(const std::string& topic) const;

 protected:
  std::function<void(const void*)> make_sink(const std::string& topic, const TopicType& type,
                                             const QosChoice& qos) override;
  void add_subscription(const std::string& topic, const TopicType& type, const QosChoice& qos,
                        std::function<void(const void*)> deliver) override;

 private:
  // A topic's channel, its per-message fields first and the first two subscribers in place: a
  // publication reads two cache lines of it, no heap block, when the topic has no faults (a batch of
  // many vehicles stepped a control period at a time is bound by the cache lines each vehicle
  // touches; a vehicle's sensor topics there have two subscribers, the controller and the batch).
  struct alignas(64) Channel {
    std::unique_ptr<FaultStream> stream;  ///< present while the topic has active faults
    std::uint64_t delivered = 0;
    std::function<void(const void*)> first, second;      ///< the first two subscribers
    std::vector<std::function<void(const void*)>> more;  ///< the later ones, in order
    std::string_view ros_type;
    std::type_index cpp_type = std::type_index(typeid(void));
    std::shared_ptr<const void> (*clone)(const void*) = nullptr;
    std::uint64_t dropped = 0;
    TopicFaults faults;
  };
  struct Delayed {
    Tick due;
    Channel* channel;
    std::shared_ptr<const void> message;
  };
  static void deliver(Channel& c, const void* message);
  void publish_with_faults(Channel& c, const void* message);
  Channel& channel(const std::string& topic, const TopicType& type);

  // The first kInlineChannels topics' channels live in the transport itself (one vehicle's topics:
  // no heap block per topic), later ones in overflow_; both keep their addresses, so sinks may keep a
  // pointer to their channel. channels_ finds them by name.
  static constexpr std::size_t kInlineChannels = 8;
  std::array<Channel, kInlineChannels> inline_channels_;
  std::size_t inline_used_ = 0;
  std::deque<Channel> overflow_channels_;
  std::map<std::string, Channel*, std::less<>> channels_;
  FaultConfig faults_;
  Tick tick_ = 0;
  std::deque<Delayed> delayed_;  ///< in due order: every topic's delay is fixed, ties keep publication order
};

}  // namespace quadcosim::sim
