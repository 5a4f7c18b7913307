// Deterministic in-process transport: publish() delivers synchronously to every subscriber of the
// topic, in subscription order. No threads, no clocks, no copies beyond the caller's message.
#pragma once

#include <map>
#include <vector>

#include "sim/transport.hpp"

namespace quadcosim::sim {

class InProcessTransport final : public Transport {
 public:
  /// Messages delivered so far, per topic.
  std::uint64_t delivered(const std::string& topic) const;

 protected:
  std::function<void(const void*)> make_sink(const std::string& topic, const TopicType& type) override;
  void add_subscription(const std::string& topic, const TopicType& type,
                        std::function<void(const void*)> deliver) override;

 private:
  struct Channel {
    std::string_view ros_type;
    std::type_index cpp_type = std::type_index(typeid(void));
    std::vector<std::function<void(const void*)>> subscribers;
    std::uint64_t delivered = 0;
  };
  Channel& channel(const std::string& topic, const TopicType& type);

  // std::map: node-stable addresses, so sinks may keep a pointer to their channel.
  std::map<std::string, Channel> channels_;
};

}  // namespace quadcosim::sim
