#include "sim/inprocess_transport.hpp"

#include <stdexcept>

namespace quadcosim::sim {

InProcessTransport::Channel& InProcessTransport::channel(const std::string& topic, const TopicType& type) {
  auto [it, inserted] = channels_.try_emplace(topic);
  Channel& c = it->second;
  if (inserted) {
    c.ros_type = type.ros_type;
    c.cpp_type = type.cpp_type;
  } else if (c.cpp_type != type.cpp_type) {
    throw std::logic_error("topic '" + topic + "' is already used with type " +
                           std::string(c.ros_type) + ", not " + std::string(type.ros_type));
  }
  return c;
}

std::function<void(const void*)> InProcessTransport::make_sink(const std::string& topic,
                                                                const TopicType& type) {
  Channel* c = &channel(topic, type);
  return [c](const void* message) {
    ++c->delivered;
    for (const auto& deliver : c->subscribers) deliver(message);
  };
}

void InProcessTransport::add_subscription(const std::string& topic, const TopicType& type,
                                          std::function<void(const void*)> deliver) {
  channel(topic, type).subscribers.push_back(std::move(deliver));
}

std::uint64_t InProcessTransport::delivered(const std::string& topic) const {
  auto it = channels_.find(topic);
  return it == channels_.end() ? 0 : it->second.delivered;
}

}  // namespace quadcosim::sim
