// `--foxglove [ADDR:]PORT` on run, plant and controller: the node's topics served live to Foxglove
// (foxglove/server.hpp) while it runs, and what happens around the run (waiting for a client, pacing,
// lingering after the end).
#pragma once

#include <memory>
#include <string>

#include "foxglove/server.hpp"
#include "hosts/node_options.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"

namespace quadcosim::io {
struct Scenario;
}

namespace quadcosim::hosts {

/// "PORT" or "ADDR:PORT" ("[V6ADDR]:PORT" for IPv6) into `address` and `port`; "" or what is wrong.
std::string parse_listen(const std::string& text, std::string& address, std::uint16_t& port);

/// The server of `o` for the node `who` (nullptr when --foxglove was not given): the vehicle's topics
/// as channels, subscribed through `transport`, and, when the plant of `sc` publishes /tf, the
/// vehicle's robot_description, /tf_static and scene as latched channels (what run.mcap records); then
/// listening; prints "WHO: foxglove: serving ws://ADDR:PORT" on stderr. Throws io::ConfigError for a
/// bad --foxglove, std::runtime_error when it cannot listen.
std::unique_ptr<foxglove::Server> start_foxglove(const FoxgloveOptions& o, const std::string& who,
                                                 sim::Transport& transport, const sim::Topics& topics,
                                                 const io::Scenario& sc);

/// --foxglove-wait: waits up to o.wait_s for a client to subscribe (or Ctrl-C).
void wait_for_foxglove_client(const FoxgloveOptions& o, const std::string& who, foxglove::Server& server);

/// The end of a served run: --foxglove-linger (serve on for o.linger_s, Ctrl-C ends it), then the
/// server's summary on stderr, then the server stopped.
void finish_foxglove(const FoxgloveOptions& o, const std::string& who, foxglove::Server& server);

}  // namespace quadcosim::hosts
