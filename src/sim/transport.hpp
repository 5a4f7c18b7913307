// The seam between nodes and whatever carries their messages. Nodes publish and subscribe by topic
// name and message type only; they never learn which transport is underneath.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <typeindex>

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

  template <class T>
  Publisher<T> advertise(const std::string& topic) {
    return Publisher<T>(make_sink(topic, topic_type<T>()));
  }

  /// `callback` runs for every message on `topic`, in publication order. When it runs is up to the
  /// transport: in-process, during publish(); over a network, when the node polls.
  /// `callback` is any callable taking const T& (stored as it is: one indirect call per delivery).
  template <class T, class F>
  void subscribe(const std::string& topic, F callback) {
    add_subscription(topic, topic_type<T>(),
                     [cb = std::move(callback)](const void* m) { cb(*static_cast<const T*>(m)); });
  }

  /// As subscribe, with the sender: `callback` takes (const T&, SenderId).
  template <class T, class F>
  void subscribe_with_sender(const std::string& topic, F callback) {
    add_subscription_with_sender(topic, topic_type<T>(), [cb = std::move(callback)](const void* m, SenderId s) {
      cb(*static_cast<const T*>(m), s);
    });
  }

 protected:
  /// Returns the function that sends one message (passed as a pointer to the T of `type`).
  virtual std::function<void(const void*)> make_sink(const std::string& topic, const TopicType& type) = 0;
  virtual void add_subscription(const std::string& topic, const TopicType& type,
                                std::function<void(const void*)> deliver) = 0;
  /// A transport that can tell senders apart overrides this; by default every sender is 0.
  virtual void add_subscription_with_sender(const std::string& topic, const TopicType& type,
                                            std::function<void(const void*, SenderId)> deliver) {
    add_subscription(topic, type, [d = std::move(deliver)](const void* m) { d(m, 0); });
  }
};

}  // namespace quadcosim::sim
