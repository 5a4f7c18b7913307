// `quadcosim topic list|echo|hz`: its flags; the tools are hosts/topic_process.hpp.
#include <CLI/CLI.hpp>

#include <utility>

#include "app/commands.hpp"
#include "hosts/topic_process.hpp"

namespace quadcosim::app {

CLI::App* add_topic_subcommand(CLI::App& app, TopicOptions& o) {
  auto* topic = app.add_subcommand("topic", "list, echo and measure ROS 2 topics (no ROS 2 needed)");
  topic->require_subcommand(1);

  auto* list = topic->add_subcommand("list", "the topics on the domain, as `ros2 topic list`");
  list->add_flag("-t,--show-types", o.show_types, "also each topic's type");
  list->add_flag("-a,--include-hidden-topics", o.include_hidden, "also topics with a token starting with '_'");
  list->add_option("--wait", o.wait_s, "discovery time [s] (default 1)")->check(CLI::Range(0.0, 3600.0));
  add_enclave_option(list, o.enclave);
  list->callback([&o] { o.verb = "list"; });

  auto* echo = topic->add_subcommand("echo", "print a topic's messages as `ros2 topic echo`");
  echo->add_option("topic", o.topic, "ROS topic name, e.g. /drone/Pose")->required();
  echo->add_option("--count", o.count, "exit after this many messages (default: until Ctrl-C)")
      ->check(CLI::Range(1, 1 << 30));
  echo->add_option("--qos", o.qos,
                   "default: the topic's ROS 2 QoS (reliable; transient local for robot_description and "
                   "/tf_static); sensor: best effort (matches any writer); transient_local: reliable, transient local")
      ->check(CLI::IsMember({"default", "sensor", "transient_local"}));
  echo->add_option("--wait", o.wait_s, "how long to look for the topic [s] (default 5)")
      ->check(CLI::Range(0.0, 3600.0));
  add_enclave_option(echo, o.enclave);
  echo->callback([&o] { o.verb = "echo"; });

  auto* hz = topic->add_subcommand("hz", "a topic's rate as `ros2 topic hz`, every second");
  hz->add_option("topic", o.topic, "ROS topic name, e.g. /drone/Imu")->required();
  hz->add_option("--window", o.window, "intervals the statistics cover (default 10000)")->check(CLI::Range(1, 1 << 30));
  hz->add_option("--duration", o.duration_s, "stop after this many seconds (default: until Ctrl-C)")
      ->check(CLI::Range(0.0, 1e9));
  hz->add_option("--qos", o.qos, "sensor (default): best effort, matches any writer; default: reliable")
      ->check(CLI::IsMember({"default", "sensor"}));
  hz->add_option("--wait", o.wait_s, "how long to look for the topic [s] (default 5)")->check(CLI::Range(0.0, 3600.0));
  add_enclave_option(hz, o.enclave);
  hz->callback([&o] { o.verb = "hz"; });
  return topic;
}

int topic_command(TopicOptions o) { return hosts::run_topic_tool(std::move(o)); }

}  // namespace quadcosim::app
