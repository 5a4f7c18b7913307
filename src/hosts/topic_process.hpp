// The topic tools (`quadcosim topic list|echo|hz`): a look at the ROS 2 graph without ROS 2 installed
// (topic_process.cpp).
#pragma once

#include <string>

namespace quadcosim::hosts {

/// What to look at. Negative wait_s: the verb's default.
struct TopicToolOptions {
  std::string verb;         ///< "list", "echo" or "hz" (set by the subcommand parsed)
  bool show_types = false;  ///< list -t
  bool include_hidden = false;
  double wait_s = -1.0;  ///< list: discovery time (1 s); echo/hz: how long to look for the topic (5 s)
  std::string topic;
  int count = 0;              ///< echo: stop after this many messages (0: until Ctrl-C)
  std::string qos;            ///< "default" (reliable) or "sensor" (best effort); "": the verb's default
  int window = 10000;         ///< hz: intervals the statistics cover
  double duration_s = 0.0;    ///< hz: stop after this long (0: until Ctrl-C)
  std::string enclave = "/";  ///< DDS Security enclave (rcl --enclave)
};

/// Runs the verb of `o` until done, its count, its duration or Ctrl-C; returns the exit code of `topic`
/// (0, 1 when hz saw no message, 2 for a bad verb). Throws std::invalid_argument for a topic not found
/// in time or of a type quadcosim cannot decode (bad input, exit 2).
int run_topic_tool(TopicToolOptions o);

}  // namespace quadcosim::hosts
