#include "hosts/foxglove_serving.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <iostream>
#include <thread>

#include "foxglove/topic_tap.hpp"
#include "hosts/signals.hpp"
#include "io/scenario.hpp"
#include "sim/topics.hpp"

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

FoxgloveRecording::FoxgloveRecording(const FoxgloveOptions& o, const std::string& who, const io::RecordingOptions& ro,
                                     sim::Transport& bus)
    : o_(o), who_(who) {
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
  server_ = std::make_unique<foxglove::Server>(so);
  foxglove::serve_vehicle_topics(*server_, bus, sim::Topics::for_namespace(ro.ns));
  if (ro.sensors) foxglove::serve_sensor_topics(*server_, bus, ro.ns, *ro.sensors);
  // As run.mcap records it (io::McapRecording): the vehicle drawn where its plant publishes its /tf.
  if (ro.vehicle) foxglove::serve_vehicle_description(*server_, *ro.vehicle, ro.ns, ro.start_ns);
  server_->start();
  const bool v6 = so.address.find(':') != std::string::npos;
  std::cerr << fmt::format("{}: foxglove: serving ws://{}{}{}:{}\n", who, v6 ? "[" : "", so.address, v6 ? "]" : "",
                           server_->port())
            << std::flush;
  wait_for_client();
  paced_from_ = std::chrono::steady_clock::now();
}

void FoxgloveRecording::tick(const sim::RecordedTick& t) {
  // --foxglove-pace: the run at this many times real time, so a viewer sees it as it would fly.
  if (o_.pace > 0.0) {
    std::this_thread::sleep_until(paced_from_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                    std::chrono::duration<double>(t.t_s / o_.pace)));
  }
}

void FoxgloveRecording::wait_for_client() {
  const FoxgloveOptions& o = o_;
  const std::string& who = who_;
  foxglove::Server& server = *server_;
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

void FoxgloveRecording::finish(bool) {
  if (finished_) return;
  finished_ = true;
  const FoxgloveOptions& o = o_;
  const std::string& who = who_;
  foxglove::Server& server = *server_;
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
