#include "hosts/foxglove_serving.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <iostream>

#include "foxglove/topic_tap.hpp"
#include "hosts/signals.hpp"
#include "io/scenario.hpp"

namespace quadcosim::hosts {

std::string parse_listen(const std::string& text, std::string& address, std::uint16_t& port) {
  std::string port_text = text;
  address = "127.0.0.1";
  if (!text.empty() && text.front() == '[') {  // [IPv6]:PORT
    const auto close = text.find("]:");
    if (close == std::string::npos) return fmt::format("\"{}\": expected [ADDRESS]:PORT", text);
    address = text.substr(1, close - 1);
    port_text = text.substr(close + 2);
  } else if (const auto colon = text.rfind(':'); colon != std::string::npos) {
    address = text.substr(0, colon);
    port_text = text.substr(colon + 1);
    if (address.find(':') != std::string::npos)
      return fmt::format("\"{}\": write an IPv6 address as [ADDRESS]:PORT", text);
  }
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), value);
  if (port_text.empty() || ec != std::errc() || end != port_text.data() + port_text.size() || value > 65535) {
    return fmt::format("\"{}\": the port must be a number 0..65535", text);
  }
  if (address.empty()) return fmt::format("\"{}\": empty address", text);
  port = static_cast<std::uint16_t>(value);
  return "";
}

std::unique_ptr<foxglove::Server> start_foxglove(const FoxgloveOptions& o, const std::string& who,
                                                 sim::Transport& transport, const sim::Topics& topics,
                                                 const io::Scenario& sc) {
  if (o.listen.empty()) return nullptr;
  foxglove::ServerOptions so;
  if (std::string err = parse_listen(o.listen, so.address, so.port); !err.empty()) {
    throw io::ConfigError("--foxglove " + err);
  }
  so.name = fmt::format("{}: foxglove", who);
  so.client_queue_bytes = o.queue_kib * 1024;
  so.keep_last = o.linger_s > 0.0;
  for (const std::string& origin : o.allow_origins) {
    if (origin != "*" && origin.find("://") == std::string::npos)
      throw io::ConfigError(fmt::format(
          "--foxglove-allow-origin \"{}\": expected an origin as SCHEME://HOST[:PORT] (e.g. https://app.foxglove.dev) "
          "or *",
          origin));
  }
  so.allowed_origins = o.allow_origins;
  auto server = std::make_unique<foxglove::Server>(so);
  foxglove::serve_vehicle_topics(*server, transport, topics);
  foxglove::serve_sensor_topics(*server, transport, sc.simulation.ns, sc.simulation.plant.realism.extra_sensors);
  // As the recorders of run.mcap do (app/inprocess_run.cpp, the plant's --mcap): the vehicle drawn
  // where its plant publishes its /tf.
  if (sc.simulation.plant.publish_tf)
    foxglove::serve_vehicle_description(*server, sc.vehicle, sc.simulation.ns, sc.simulation.plant.clock.ns(0));
  server->start();
  const bool v6 = so.address.find(':') != std::string::npos;
  std::cerr << fmt::format("{}: foxglove: serving ws://{}{}{}:{}\n", who, v6 ? "[" : "", so.address, v6 ? "]" : "",
                           server->port())
            << std::flush;
  return server;
}

void wait_for_foxglove_client(const FoxgloveOptions& o, const std::string& who, foxglove::Server& server) {
  if (o.wait_s <= 0.0) return;
  std::cerr << fmt::format("{}: foxglove: waiting up to {:g} s for a client to subscribe\n", who, o.wait_s)
            << std::flush;
  using Clock = std::chrono::steady_clock;
  // The server wakes these waits as subscriptions change; a stop (a signal's flag, which cannot wake
  // the server's condition variable) is looked at every kStopCheck.
  constexpr auto kStopCheck = std::chrono::milliseconds(50);
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.wait_s));
  std::size_t seen = server.subscriptions();
  while (seen == 0 && !stop_requested() && Clock::now() < deadline) {
    seen = server.wait_subscriptions_change(seen, std::min(deadline, Clock::now() + kStopCheck));
  }
  if (seen == 0) {
    std::cerr << fmt::format("{}: foxglove: no client subscribed; running\n", who);
    return;
  }
  // A client subscribes to each topic with a request of its own (Foxglove's panels, one by one): the
  // run starts once its subscriptions have stopped coming (200 ms without a new one, at most 2 s), so
  // none of them misses the first messages.
  const auto quiet = std::chrono::milliseconds(200);
  const auto last = Clock::now() + std::chrono::seconds(2);
  auto changed = Clock::now();
  while (!stop_requested()) {
    const auto quiet_until = std::min(changed + quiet, last);
    const std::size_t n = server.wait_subscriptions_change(seen, std::min(quiet_until, Clock::now() + kStopCheck));
    const auto now = Clock::now();
    if (n != seen) {
      seen = n;
      changed = now;
    }
    if (now - changed >= quiet || now >= last) break;
  }
}

void finish_foxglove(const FoxgloveOptions& o, const std::string& who, foxglove::Server& server) {
  if (o.linger_s > 0.0 && !stop_requested()) {
    std::cerr << fmt::format("{}: foxglove: run ended; serving its last state for {:g} s (Ctrl-C ends)\n", who,
                             o.linger_s)
              << std::flush;
    wait_for_stop(std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                         std::chrono::duration<double>(o.linger_s)));
  }
  server.stop();
  std::cerr << fmt::format("{}: foxglove: {}\n", who, server.summary());
}

}  // namespace quadcosim::hosts
