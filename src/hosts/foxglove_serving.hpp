// `--foxglove [ADDR:]PORT` on run, plant and controller: the node's topics served live to Foxglove
// (foxglove/server.hpp) as one of the run's recorders (sim/recorder.hpp), with what happens around the
// run (waiting for a client, pacing, lingering after the end). hosts/recording.hpp builds it.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "foxglove/server.hpp"
#include "hosts/node_options.hpp"
#include "io/recording.hpp"
#include "sim/recorder.hpp"
#include "sim/transport.hpp"

namespace quadcosim::hosts {

/// "PORT" or "ADDR:PORT" ("[V6ADDR]:PORT" for IPv6) into `address` and `port`; "" or what is wrong.
std::string parse_listen(const std::string& text, std::string& address, std::uint16_t& port);

/// The live view as a recorder: built, it serves the vehicle's topics (those run.mcap records) as
/// channels tapped through the bus, and, when `ro.vehicle` is set (the plant publishes /tf), the
/// vehicle's robot_description, /tf_static and scene as latched channels; then it listens, prints
/// "WHO: foxglove: serving ws://ADDR:PORT" on stderr and, with --foxglove-wait, waits for a client.
/// tick() holds each tick back until its time on the wall clock under --foxglove-pace; finish()
/// serves on for --foxglove-linger (Ctrl-C ends it), prints the server's summary and stops it.
class FoxgloveRecording final : public sim::Recorder {
 public:
  /// Throws io::ConfigError for a bad --foxglove, std::runtime_error when it cannot listen.
  FoxgloveRecording(const FoxgloveOptions& o, const std::string& who, const io::RecordingOptions& ro,
                    sim::Transport& bus);
  void tick(const sim::RecordedTick& t) override;
  void finish(bool completed) override;
  foxglove::Server& server() { return *server_; }

 private:
  /// --foxglove-wait: waits up to o_.wait_s for a client to subscribe (or Ctrl-C).
  void wait_for_client();

  FoxgloveOptions o_;
  std::string who_;
  std::unique_ptr<foxglove::Server> server_;
  std::chrono::steady_clock::time_point paced_from_;
  bool finished_ = false;
};

}  // namespace quadcosim::hosts
