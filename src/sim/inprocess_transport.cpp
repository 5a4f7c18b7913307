#include "sim/inprocess_transport.hpp"

#include <iterator>
#include <stdexcept>

namespace quadcosim::sim {

InProcessTransport::Channel& InProcessTransport::channel(const std::string& topic, const TopicType& type) {
  auto [it, inserted] = channels_.try_emplace(topic, nullptr);
  if (inserted) {
    it->second =
        inline_used_ < kInlineChannels ? &inline_channels_[inline_used_++] : &overflow_channels_.emplace_back();
  }
  Channel& c = *it->second;
  if (inserted) {
    c.ros_type = type.ros_type;
    c.cpp_type = type.cpp_type;
    c.clone = type.clone;
    if (auto f = faults_.topics.find(topic); f != faults_.topics.end() && f->second.active()) {
      c.faults = f->second;
      c.stream = std::make_unique<FaultStream>(faults_.seed, topic);
    }
  } else if (c.cpp_type != type.cpp_type) {
    throw std::logic_error("topic '" + topic + "' is already used with type " + std::string(c.ros_type) + ", not " +
                           std::string(type.ros_type));
  }
  return c;
}

std::function<void(const void*)> InProcessTransport::make_sink(const std::string& topic, const TopicType& type,
                                                               const QosChoice&) {  // no QoS in process
  Channel* c = &channel(topic, type);
  return [this, c](const void* message) {
    if (!c->stream) return deliver(*c, message);
    publish_with_faults(*c, message);
  };
}

// Out of line, so that the common path above (no faults) stays a test and a loop.
[[gnu::noinline]] void InProcessTransport::publish_with_faults(Channel& c, const void* message) {
  // One draw per message whatever happens to it, so a topic's faults do not depend on the others.
  if (c.stream->uniform() < c.faults.drop_probability) {
    ++c.dropped;
    return;
  }
  if (c.faults.delay_ticks == 0) return deliver(c, message);
  const Tick due = tick_ + c.faults.delay_ticks;
  // Keep due order across topics with different delays: insert after every message due no later.
  auto at = delayed_.end();
  while (at != delayed_.begin() && std::prev(at)->due > due) --at;
  delayed_.insert(at, Delayed{due, &c, c.clone(message)});
}

void InProcessTransport::deliver(Channel& c, const void* message) {
  ++c.delivered;
  if (!c.first) return;
  c.first(message);
  if (!c.second) return;
  c.second(message);
  for (const auto& d : c.more) d(message);
}

void InProcessTransport::set_faults(const FaultConfig& faults) {
  faults_ = faults;
  for (auto& [topic, channel] : channels_) {
    Channel& c = *channel;
    const auto f = faults_.topics.find(topic);
    c.faults = f == faults_.topics.end() ? TopicFaults{} : f->second;
    if (c.faults.active()) {
      c.stream = std::make_unique<FaultStream>(faults_.seed, topic);
    } else {
      c.stream.reset();
    }
  }
}

void InProcessTransport::advance_to(Tick k) {
  tick_ = k;
  while (!delayed_.empty() && delayed_.front().due <= k) {
    const Delayed d = std::move(delayed_.front());
    delayed_.pop_front();
    deliver(*d.channel, d.message.get());
  }
}

std::uint64_t InProcessTransport::dropped(const std::string& topic) const {
  auto it = channels_.find(topic);
  return it == channels_.end() ? 0 : it->second->dropped;
}

void InProcessTransport::add_subscription(const std::string& topic, const TopicType& type, const QosChoice&,
                                          std::function<void(const void*)> deliver) {
  Channel& c = channel(topic, type);
  if (!c.first) {
    c.first = std::move(deliver);
  } else if (!c.second) {
    c.second = std::move(deliver);
  } else {
    c.more.push_back(std::move(deliver));
  }
}

std::uint64_t InProcessTransport::delivered(const std::string& topic) const {
  auto it = channels_.find(topic);
  return it == channels_.end() ? 0 : it->second->delivered;
}

}  // namespace quadcosim::sim
