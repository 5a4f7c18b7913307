// The seam between nodes and whatever carries their messages. Nodes publish and subscribe by topic
// name and message type only; they never learn which transport is underneath.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <typeindex>

#include "sim/topic_qos.hpp"

namespace quadcosim::sim {

/// A message type as a transport sees it: its ROS 2 type name, its C++ identity, and how to copy
/// one (for a transport that holds messages back, e.g. to delay them).
struct TopicType {
  std::string_view ros_type;  ///< e.g. "geometry_msgs/msg/PoseStamped"
  std::type_index cpp_type;
  std::shared_ptr<const void> (*clone)(const void* message);
};

template <class T>
TopicType topic_type() {
  return {T::kRosType, std::type_index(typeid(T)), [](const void* m) -> std::shared_ptr<const void> {
            return std::make_shared<const T>(*static_cast<const T*>(m));
          }};
}

class Transport;

/// Who sent a delivered message, as far as the transport can tell: 0 when it cannot tell (in-process,
/// every message is the process's own); over DDS the instance handle of the writer, so a node can take
/// a topic from the peer it paired with and count everything else as foreign.
using SenderId = std::uint64_t;

/// A delivered message as it came over the wire, where the transport has it: its ROS 2 CDR bytes,
/// encapsulation header first, exactly what io::to_cdr makes of the message (DDS: the bytes the
/// writer serialised, without the trailing pad Cyclone adds). Empty where the message never was
/// serialised (in-process).
using WireBytes = std::span<const std::uint8_t>;

/// The QoS a publisher or subscriber is created with: stated by the host where it advertises or
/// subscribes, or (nullopt) the transport's own for the topic (over DDS: what set_qos gave it, else
/// the table TopicQos::for_topic). An in-process transport has no QoS and ignores it.
using QosChoice = std::optional<TopicQos>;

/// Typed handle for publishing on one topic.
template <class T>
class Publisher {
 public:
  Publisher() = default;
  void publish(const T& message) const { sink_(&message); }
  explicit operator bool() const { return static_cast<bool>(sink_); }

 private:
  friend class Transport;
  explicit Publisher(std::function<void(const void*)> sink) : sink_(std::move(sink)) {}
  std::function<void(const void*)> sink_;
};

class Transport {
 public:
  virtual ~Transport() = default;

  /// A publisher on `topic` with QoS `qos` (QosChoice).
  template <class T>
  Publisher<T> advertise(const std::string& topic, const QosChoice& qos = std::nullopt) {
    return Publisher<T>(make_sink(topic, topic_type<T>(), qos));
  }

  /// `callback` runs for every message on `topic`, in publication order. When it runs is up to the
  /// transport: in-process, during publish(); over a network, when the node polls.
  /// `callback` is any callable taking const T& (stored as it is: one indirect call per delivery).
  template <class T, class F>
  void subscribe(const std::string& topic, F callback, const QosChoice& qos = std::nullopt) {
    add_subscription(topic, topic_type<T>(), qos,
                     [cb = std::move(callback)](const void* m) { cb(*static_cast<const T*>(m)); });
  }

  /// As subscribe, with the sender: `callback` takes (const T&, SenderId).
  template <class T, class F>
  void subscribe_with_sender(const std::string& topic, F callback, const QosChoice& qos = std::nullopt) {
    add_subscription_with_sender(topic, topic_type<T>(), qos, [cb = std::move(callback)](const void* m, SenderId s) {
      cb(*static_cast<const T*>(m), s);
    });
  }

  /// A recording's tap: as subscribe_with_sender, with the message's wire bytes where the transport
  /// has them: `callback` takes (const T&, SenderId, WireBytes).
  template <class T, class F>
  void subscribe_tap(const std::string& topic, F callback, const QosChoice& qos = std::nullopt) {
    add_tap(topic, topic_type<T>(), qos, [cb = std::move(callback)](const void* m, SenderId s, WireBytes wire) {
      cb(*static_cast<const T*>(m), s, wire);
    });
  }

 protected:
  /// Returns the function that sends one message (passed as a pointer to the T of `type`).
  virtual std::function<void(const void*)> make_sink(const std::string& topic, const TopicType& type,
                                                     const QosChoice& qos) = 0;
  virtual void add_subscription(const std::string& topic, const TopicType& type, const QosChoice& qos,
                                std::function<void(const void*)> deliver) = 0;
  /// A transport that can tell senders apart overrides this; by default every sender is 0.
  virtual void add_subscription_with_sender(const std::string& topic, const TopicType& type, const QosChoice& qos,
                                            std::function<void(const void*, SenderId)> deliver) {
    add_subscription(topic, type, qos, [d = std::move(deliver)](const void* m) { d(m, 0); });
  }
  /// A transport that keeps the wire bytes overrides this; by default they are empty.
  virtual void add_tap(const std::string& topic, const TopicType& type, const QosChoice& qos,
                       std::function<void(const void*, SenderId, WireBytes)> deliver) {
    add_subscription_with_sender(topic, type, qos,
                                 [d = std::move(deliver)](const void* m, SenderId s) { d(m, s, WireBytes{}); });
  }
};

}  // namespace quadcosim::sim
