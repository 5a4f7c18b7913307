// A live view of a node's topics for Foxglove: a WebSocket server speaking the Foxglove WebSocket
// protocol (subprotocol foxglove.websocket.v1) that advertises one channel per topic (CDR messages,
// ros2msg schemas) and streams the messages to the clients subscribed to them, with the simulated
// time as the server's time. It only ever reads what the node publishes: it runs on its own thread,
// the publishing thread only hands messages over (nothing is serialised while no client subscribed),
// and a slow, stuck or misbehaving client costs drops and errors counted here, never a wait of the
// simulation or a change of what it computes.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace quadcosim::foxglove {

/// The subprotocol a client must offer in its handshake.
inline constexpr const char* kSubprotocol = "foxglove.websocket.v1";

struct ServerOptions {
  std::string address = "127.0.0.1";  ///< where to listen (an IPv4 or IPv6 address)
  std::uint16_t port = 0;             ///< 0: a free port (Server::port() gives the one bound)
  std::string name = "quadcosim";     ///< serverInfo's name
  /// Bytes queued for one client (not yet taken by its socket) above which that client's messages are
  /// dropped, and counted, until it reads again.
  std::size_t client_queue_bytes = 1 << 20;
  /// Messages handed over by the publishing threads and not yet taken by the server thread, above which
  /// new ones are dropped (and counted): bounds the memory when the server thread itself falls behind.
  std::size_t handoff_messages = 1 << 16;
  /// Largest frame a client may send [bytes]; a longer one closes its connection (1009, message too big).
  std::size_t max_client_frame_bytes = 64 * 1024;
  /// Connections at most, counting those whose handshake was accepted and is still being answered;
  /// further handshakes are refused (HTTP 503), also in a burst of simultaneous connects.
  std::size_t max_clients = 16;
  /// Origins a browser page may connect from, besides the local ones (see origin_allowed()); "*"
  /// admits any. A handshake with another Origin header is refused (HTTP 403).
  std::vector<std::string> allowed_origins;
  /// Hand every message over even while nobody subscribes, so that the newest one of each channel can
  /// be sent to a client that subscribes later (e.g. after the run ended); costs the serialisation of
  /// every message. Off: nothing is serialised while no client subscribes.
  bool keep_last = false;
};

/// Whether a handshake with Origin header `origin` ("" when it has none) is admitted: no Origin (a
/// native client: Foxglove desktop, a script), an http(s) origin on localhost, 127.0.0.1 or [::1] (any
/// port), or one of `allowed` (compared without regard to case; "*" admits every origin). Anything
/// else, "null" included, is a page of another site and is refused.
bool origin_allowed(const std::string& origin, const std::vector<std::string>& allowed);

/// What the server has done, summed over its clients (read any time, from any thread).
struct ServerStats {
  std::uint64_t clients = 0;           ///< connections accepted
  std::uint64_t refused = 0;           ///< handshakes refused: no foxglove.websocket.v1, an Origin not
                                       ///< allowed, or too many clients
  std::uint64_t messages_sent = 0;     ///< message frames queued to clients
  std::uint64_t messages_dropped = 0;  ///< message frames not sent: the client's queue was full
  std::uint64_t handoff_dropped = 0;   ///< messages dropped before the server thread saw them
  std::uint64_t time_frames = 0;       ///< time frames queued to clients
  std::uint64_t bad_requests = 0;      ///< client messages answered with an error status
  std::uint64_t disconnected = 0;      ///< connections closed by the server for a client's fault
};

class Server {
 public:
  explicit Server(ServerOptions options);
  ~Server();  ///< stop()
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Declares a channel (before start()); returns its id. `schema_name` "pkg/msg/Type", `schema` its
  /// ros2msg text; messages are CDR.
  std::uint32_t add_channel(const std::string& topic, const std::string& schema_name, const std::string& schema);
  /// A channel whose one message, `cdr` at time `t_ns`, is given now (before start()) and sent to each
  /// client as it subscribes, as a transient-local ROS 2 topic gives its sample to a late reader
  /// (robot_description, /tf_static). It does not move the server's time.
  std::uint32_t add_latched_channel(const std::string& topic, const std::string& schema_name, const std::string& schema,
                                    std::int64_t t_ns, std::vector<std::uint8_t> cdr);

  /// Binds options.address:options.port and starts serving on a thread of its own. Throws
  /// std::runtime_error naming the address and port when it cannot listen there.
  void start();
  /// The bound port (after start()).
  std::uint16_t port() const { return port_; }

  /// True while some client subscribes to `channel`: publish() is worth its serialisation.
  bool wanted(std::uint32_t channel) const;
  /// Hands one message over (any thread, never blocks on a client): `t_ns` is its time (simulated,
  /// the header stamp), also the server's time once no earlier. Dropped when nobody wants it.
  void publish(std::uint32_t channel, std::int64_t t_ns, std::vector<std::uint8_t> cdr);

  /// Closes every connection (going away) and ends the thread; returns within about a second
  /// whatever the clients do. Idempotent.
  void stop();

  ServerStats stats() const;
  /// Connections open now.
  std::size_t connected() const;
  /// Subscriptions held now, over every client.
  std::size_t subscriptions() const;
  /// Waits until subscriptions() is not `seen` or `deadline` passed, whichever comes first, and
  /// returns subscriptions() then. Woken by the server thread as a client subscribes, unsubscribes
  /// or leaves (no polling).
  std::size_t wait_subscriptions_change(std::size_t seen, std::chrono::steady_clock::time_point deadline) const;
  /// One line for the node's summary: clients, messages sent and dropped, bad requests.
  std::string summary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::uint16_t port_ = 0;
};

}  // namespace quadcosim::foxglove
