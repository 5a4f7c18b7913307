// `quadcosim topic list|echo|hz`: a look at the ROS 2 graph without ROS 2 installed. Topics and their
// types come from DDS discovery (dds/graph.hpp); echo and hz subscribe through DdsTransport, so they
// decode the message types quadcosim itself speaks.
#include "hosts/topic_process.hpp"

#include <fmt/format.h>

#include <chrono>
#include <functional>
#include <iostream>
#include <map>

#include "dds/dds_transport.hpp"
#include "dds/graph.hpp"
#include "dds/steady_clock.hpp"
#include "dds/topic_tools.hpp"
#include "hosts/exit_code.hpp"
#include "hosts/signals.hpp"
#include "sim/messages.hpp"

namespace quadcosim::hosts {

namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kSecond = 1'000'000'000;

using dds::steady_ns;

std::int64_t to_ns(double seconds) { return static_cast<std::int64_t>(seconds * 1e9); }

/// Subscribes `topic` with its C++ type and hands each message to `sink`, converted to YAML.
using Subscriber = std::function<void(dds::DdsTransport&, const std::string& topic,
                                      std::function<void(const std::string& yaml)> sink)>;

template <class T>
std::pair<const std::string, Subscriber> entry() {
  return {std::string(T::kRosType),
          [](dds::DdsTransport& t, const std::string& topic, std::function<void(const std::string&)> sink) {
            t.subscribe<T>(topic, [sink = std::move(sink)](const T& m) { sink(dds::to_yaml(m)); });
          }};
}

const std::map<std::string, Subscriber>& known_types() {
  static const std::map<std::string, Subscriber> table = {
      entry<msg::PoseStamped>(),       entry<msg::TwistStamped>(),  entry<msg::Imu>(),
      entry<msg::Float64MultiArray>(), entry<msg::Clock>(),         entry<msg::ControllerStatus>(),
      entry<msg::PlantStatus>(),       entry<msg::TFMessage>(),     entry<msg::String>(),
      entry<msg::MagneticField>(),     entry<msg::FluidPressure>(), entry<msg::NavSatFix>(),
      entry<msg::RotorSpeeds>(),       entry<msg::RotorThrusts>(),  entry<msg::ThrustRates>(),
      entry<msg::ThrustAttitude>(),    entry<msg::ThrustTorque>(),  entry<msg::VelocityYaw>(),
      entry<msg::AccelerationYaw>()};
  return table;
}

std::string known_type_list() {
  std::string s;
  for (const auto& [name, sub] : known_types()) s += (s.empty() ? "" : ", ") + name;
  return s;
}

/// Thrown for a topic that cannot be subscribed (not found, unknown type): bad input, exit 2.
struct TopicError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Waits (up to wait_s, less once it appears) for `topic` in discovery and checks that quadcosim
/// can decode its type. Returns the topic as discovered.
dds::RosTopic find_topic(dds::DdsTransport& transport, const std::string& topic, double wait_s) {
  auto find = [&](const std::vector<dds::Endpoint>& endpoints) -> std::optional<dds::RosTopic> {
    for (auto& t : dds::ros_topics(endpoints)) {
      if (t.name == topic) return t;
    }
    return std::nullopt;
  };
  const auto endpoints = dds::discover_endpoints(transport.participant().handle(), to_ns(wait_s),
                                                 [&](const auto& e) { return find(e).has_value(); });
  const auto found = find(endpoints);
  if (!found) {
    throw TopicError(
        fmt::format("topic {} not found on ROS_DOMAIN_ID {} within {} s (no publisher or "
                    "subscription seen); `quadcosim topic list` shows what is there",
                    topic, transport.participant().domain_id(), wait_s));
  }
  if (found->types.size() != 1) {
    throw TopicError(fmt::format("topic {} has more than one type: {}", topic, fmt::join(found->types, ", ")));
  }
  if (!known_types().count(found->types[0])) {
    throw TopicError(fmt::format("topic {} has type {}, which quadcosim cannot decode (it knows {})", topic,
                                 found->types[0], known_type_list()));
  }
  return *found;
}

/// "default": what ROS 2 uses for `topic` (dds::QosProfile::for_topic: the ROS default, tf2's for /tf
/// and /tf_static, transient local for robot_description); "sensor": best effort; "transient_local":
/// reliable, transient local, depth 1 (gets the last sample a latching writer holds).
dds::QosProfile qos_named(const std::string& name, const std::string& topic) {
  if (name == "sensor") return dds::QosProfile::sensor_data();
  if (name == "transient_local") return {1, true, true};
  return dds::QosProfile::for_topic(topic);
}

std::string normalized(std::string topic) {
  if (!topic.empty() && topic.front() != '/') topic.insert(topic.begin(), '/');  // as ros2: relative to "/"
  return topic;
}

int topic_list(const TopicToolOptions& o) {
  const dds::RosEnvironment env = dds::read_ros_environment(o.enclave);
  dds::Participant participant(env);
  const auto topics = dds::ros_topics(dds::discover_endpoints(participant.handle(), to_ns(o.wait_s)));
  std::cout << dds::format_topic_list(topics, o.show_types, o.include_hidden) << std::flush;
  return exit_code::kOk;
}

int topic_echo(const TopicToolOptions& o) {
  const std::string topic = normalized(o.topic);
  dds::DdsTransport transport(dds::read_ros_environment(o.enclave));
  const dds::RosTopic found = find_topic(transport, topic, o.wait_s);
  const dds::QosProfile qos = qos_named(o.qos, topic);
  if (qos.reliable && found.publishers > 0 && found.best_effort_publishers == found.publishers) {
    std::cerr << fmt::format(
        "note: every publisher of {} is best effort, which a reliable reader does not "
        "match; use --qos sensor\n",
        topic);
  }
  transport.set_qos(topic, qos);
  int printed = 0;
  known_types().at(found.types[0])(transport, topic, [&](const std::string& yaml) {
    if (o.count > 0 && printed >= o.count) return;  // the rest of a batch after the last one wanted
    std::cout << yaml << "---\n" << std::flush;
    ++printed;
  });
  while (!stop_requested() && (o.count <= 0 || printed < o.count)) transport.spin_once(100 * kMs);
  return exit_code::kOk;
}

int topic_hz(const TopicToolOptions& o) {
  const std::string topic = normalized(o.topic);
  dds::DdsTransport transport(dds::read_ros_environment(o.enclave));
  const dds::RosTopic found = find_topic(transport, topic, o.wait_s);
  if (found.publishers == 0) {
    std::cerr << fmt::format("WARNING: topic [{}] does not appear to be published yet\n", topic);
  }
  transport.set_qos(topic, qos_named(o.qos, topic));
  dds::RateWindow window(static_cast<std::size_t>(o.window));
  // Arrival times on the steady clock; decoding to YAML is wasted work here but keeps one path.
  known_types().at(found.types[0])(transport, topic, [&](const std::string&) { window.add(steady_ns()); });

  const std::int64_t start = steady_ns();
  const std::int64_t end = o.duration_s > 0 ? start + to_ns(o.duration_s) : INT64_MAX;
  std::int64_t next_report = -1;  // one second after the first message, then every second
  std::uint64_t reported = 0;     // messages counted at the last report
  auto report = [&] {
    if (window.messages() == reported) {
      std::cout << "no new messages\n" << std::flush;
    } else if (const auto s = window.stats()) {
      std::cout << dds::format_rate(*s) << std::flush;
      reported = window.messages();
    }
  };
  while (!stop_requested()) {
    const std::int64_t now = steady_ns();
    if (now >= end) break;
    if (next_report < 0 && window.messages() > 0) next_report = now + kSecond;
    if (next_report >= 0 && now >= next_report) {
      report();
      next_report += kSecond;
      continue;
    }
    std::int64_t wait = std::min<std::int64_t>(end - now, 100 * kMs);  // 100 ms: notice Ctrl-C promptly
    if (next_report >= 0) wait = std::min(wait, next_report - now);
    transport.spin_once(wait);
  }
  if (window.messages() > reported && window.stats()) report();  // what came in since the last report
  if (window.messages() == 0) {
    std::cerr << fmt::format("no message on {} (QoS {})\n", topic, o.qos);
    return exit_code::kFailed;
  }
  return exit_code::kOk;
}

}  // namespace

int run_topic_tool(TopicToolOptions o) {
  install_stop_handlers();
  if (o.verb == "list") {
    if (o.wait_s < 0) o.wait_s = 1.0;
    return topic_list(o);
  }
  if (o.wait_s < 0) o.wait_s = 5.0;
  if (o.verb == "echo") {
    if (o.qos.empty()) o.qos = "default";
    return topic_echo(o);
  }
  if (o.verb == "hz") {
    if (o.qos.empty()) o.qos = "sensor";
    return topic_hz(o);
  }
  std::cerr << "error: topic: expected list, echo or hz\n";
  return exit_code::kBadInput;
}

}  // namespace quadcosim::hosts
