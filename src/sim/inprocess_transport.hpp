// Deterministic in-process transport: publish() delivers synchronously to every subscriber of the
// topic, in subscription order. No threads, no clocks, no copies beyond the caller's message.
// Optionally injects faults (sim/faults.hpp): seeded drops, and delays of whole ticks, for which the
// message is copied and delivered by advance_to() at the start of its tick.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "sim/clock.hpp"
#include "sim/faults.hpp"
#include "sim/transport.hpp"

namespace quadcosim::sim {

class InProcessTransport final : public Transport {
 public:
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
  std::function<void(const void*)> make_sink(const std::string& topic, const TopicType& type) override;
  void add_subscription(const std::string& topic, const TopicType& type,
                        std::function<void(const void*)> deliver) override;

 private:
  struct Channel {
    std::string_view ros_type;
    std::type_index cpp_type = std::type_index(typeid(void));
    std::shared_ptr<const void> (*clone)(const void*) = nullptr;
    std::vector<std::function<void(const void*)>> subscribers;
    std::uint64_t delivered = 0;
    std::uint64_t dropped = 0;
    TopicFaults faults;
    std::optional<FaultStream> stream;
  };
  struct Delayed {
    Tick due;
    Channel* channel;
    std::shared_ptr<const void> message;
  };
  static void deliver(Channel& c, const void* message);
  void publish_with_faults(Channel& c, const void* message);
  Channel& channel(const std::string& topic, const TopicType& type);

  // std::map: node-stable addresses, so sinks may keep a pointer to their channel.
  std::map<std::string, Channel> channels_;
  FaultConfig faults_;
  Tick tick_ = 0;
  std::deque<Delayed> delayed_;  ///< in due order: every topic's delay is fixed, ties keep publication order
};

}  // namespace quadcosim::sim
