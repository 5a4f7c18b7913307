#include "foxglove/server.hpp"

#include "foxglove/protocol.hpp"

// websocketpp on standalone asio (Debian's libwebsocketpp-dev and libasio-dev), without TLS.
#define ASIO_STANDALONE
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include <fmt/format.h>
#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace quadcosim::foxglove {

namespace {

using WsServer = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;

// Per client: the first error is logged, the rest only counted; this many close the connection.
constexpr std::uint64_t kErrorsBeforeDisconnect = 100;

}  // namespace

struct Server::Impl {
  struct Channel {
    protocol::ChannelInfo info;
    std::atomic<int> subscribers{0};
    // Server thread only: the newest message, sent at once to a client that subscribes later.
    std::vector<std::uint8_t> last;
    std::int64_t last_t_ns = -1;
  };
  struct Client {
    std::uint64_t id = 0;
    std::string remote;
    std::map<std::uint32_t, std::uint32_t> subscriptions;  // subscription id -> channel
    std::vector<std::int64_t> subscription_of;             // channel -> subscription id, -1 for none
    std::uint64_t dropped = 0, errors = 0;
    bool dropping = false;  // its queue is full (logged once per episode)
    bool closing = false;   // disconnected for its errors: nothing more it sends is read
  };
  struct Handed {
    std::uint32_t channel;
    std::int64_t t_ns;
    std::vector<std::uint8_t> cdr;
  };

  explicit Impl(ServerOptions o) : options(std::move(o)) {}

  ServerOptions options;
  std::vector<std::unique_ptr<Channel>> channels;
  asio::io_context io;
  WsServer ws;
  std::thread thread;
  bool started = false, stopped = false;
  std::string session_id;
  std::string advertised;  // the advertise message (the channels are fixed once started)

  // Hand-over from the publishing threads.
  std::mutex handoff_mutex;
  std::vector<Handed> handoff, batch;
  bool drain_posted = false;

  // Server thread only.
  std::map<Hdl, Client, std::owner_less<Hdl>> clients;
  // Handshakes accepted whose connection has not opened (or failed) yet: they count against
  // max_clients, so a burst of simultaneous connects cannot pass the check before any of them opens.
  std::set<Hdl, std::owner_less<Hdl>> admitted;
  std::uint64_t next_client_id = 1;
  std::int64_t time_ns = -1;             // the newest time sent
  std::uint64_t n_refused_in_a_row = 0;  // refusals for the client limit since a connection last opened

  std::atomic<std::size_t> open{0};
  // Wakes Server::stop, which waits for the connections to close: notified (under the mutex, so the
  // waiter cannot miss it) after the server thread closed one.
  std::mutex open_mutex;
  std::condition_variable closed;
  // Wakes Server::wait_subscriptions_change: notified (under the mutex, so no waiter misses it) after
  // the server thread changed a channel's subscriber count.
  mutable std::mutex subscriptions_mutex;
  mutable std::condition_variable subscriptions_changed;
  void notify_subscriptions_changed() {
    { const std::lock_guard<std::mutex> lock(subscriptions_mutex); }
    subscriptions_changed.notify_all();
  }
  std::atomic<std::uint64_t> n_clients{0}, n_refused{0}, n_sent{0}, n_dropped{0}, n_handoff_dropped{0}, n_time{0},
      n_bad{0}, n_disconnected{0};

  void log(const std::string& line) const { std::cerr << fmt::format("{}: {}\n", options.name, line); }

  WsServer::connection_ptr connection(const Hdl& h) {
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr c = ws.get_con_from_hdl(h, ec);
    return ec ? nullptr : c;
  }

  // --- handshake, open, close -------------------------------------------------------------------
  bool validate(Hdl h) {
    WsServer::connection_ptr c = connection(h);
    if (!c) return false;
    const auto& offered = c->get_requested_subprotocols();
    if (std::find(offered.begin(), offered.end(), kSubprotocol) == offered.end()) {
      ++n_refused;
      log(fmt::format("refused {}: it does not offer the subprotocol {}", c->get_remote_endpoint(), kSubprotocol));
      c->set_status(websocketpp::http::status_code::bad_request);
      return false;
    }
    if (const std::string& origin = c->get_request_header("Origin"); !origin_allowed(origin, options.allowed_origins)) {
      ++n_refused;
      log(fmt::format("refused {}: Origin {} is not local nor allowed (--foxglove-allow-origin)",
                      c->get_remote_endpoint(), origin));
      c->set_status(websocketpp::http::status_code::forbidden);
      return false;
    }
    if (clients.size() + admitted.size() >= options.max_clients) {
      // Logged once per episode of refusals (a burst would otherwise log a line per connect).
      if (++n_refused_in_a_row == 1)
        log(fmt::format("refused {}: {} clients already connected (the limit); further refusals are counted",
                        c->get_remote_endpoint(), clients.size() + admitted.size()));
      ++n_refused;
      c->set_status(websocketpp::http::status_code::service_unavailable);
      return false;
    }
    websocketpp::lib::error_code ec;
    c->select_subprotocol(kSubprotocol, ec);
    if (ec) return false;
    admitted.insert(h);
    return true;
  }

  void on_open(Hdl h) {
    admitted.erase(h);
    n_refused_in_a_row = 0;
    WsServer::connection_ptr c = connection(h);
    if (!c) return;
    Client& cl = clients[h];
    cl.id = next_client_id++;
    cl.remote = c->get_remote_endpoint();
    cl.subscription_of.assign(channels.size(), -1);
    c->set_close_handshake_timeout(1000);  // a client that does not answer a close is cut off after 1 s
    ++n_clients;
    ++open;
    send_text(h, protocol::server_info(options.name, session_id));
    send_text(h, advertised);
    if (time_ns >= 0) send_time(h, cl);
  }

  void on_close(Hdl h) {
    admitted.erase(h);  // a handshake accepted whose connection failed before it opened
    const auto it = clients.find(h);
    if (it == clients.end()) return;
    Client& cl = it->second;
    if (WsServer::connection_ptr c = connection(h);
        c && c->get_local_close_code() == websocketpp::close::status::message_too_big) {
      ++n_bad;
      ++n_disconnected;
      log(fmt::format("client {} ({}): frame longer than {} bytes: disconnected", cl.id, cl.remote,
                      options.max_client_frame_bytes));
    }
    for (const auto& [sub, channel] : cl.subscriptions) --channels[channel]->subscribers;
    if (!cl.subscriptions.empty()) notify_subscriptions_changed();
    if (cl.dropped > 0)
      log(fmt::format("client {} ({}) left; {} messages dropped for it", cl.id, cl.remote, cl.dropped));
    clients.erase(it);
    --open;
    { const std::lock_guard<std::mutex> lock(open_mutex); }
    closed.notify_all();
  }

  // --- client requests ---------------------------------------------------------------------------
  // A bad request: an error status back, counted. The client's first error is logged (one line);
  // its 100th closes the connection (one more line), after which nothing it sent is read.
  void error(Hdl h, Client& cl, const std::string& what) {
    if (cl.closing) return;
    ++n_bad;
    ++cl.errors;
    if (cl.errors == 1)
      log(fmt::format("client {} ({}): {} (further errors of this client are only counted; the {}th disconnects it)",
                      cl.id, cl.remote, what, kErrorsBeforeDisconnect));
    send_text(h, protocol::status_error(what));
    if (cl.errors >= kErrorsBeforeDisconnect) {
      cl.closing = true;
      ++n_disconnected;
      log(fmt::format("client {} ({}): {} errors: disconnected", cl.id, cl.remote, cl.errors));
      websocketpp::lib::error_code ec;
      ws.close(h, websocketpp::close::status::policy_violation, "too many errors", ec);
    }
  }

  void on_message(Hdl h, WsServer::message_ptr m) {
    const auto it = clients.find(h);
    if (it == clients.end() || it->second.closing) return;
    Client& cl = it->second;
    if (m->get_opcode() != websocketpp::frame::opcode::text) {
      error(h, cl, "binary client messages need the clientPublish capability, which this server does not offer");
      return;
    }
    const protocol::Request request = protocol::parse_request(m->get_payload());
    switch (request.op) {
      case protocol::Request::Op::kSubscribe: subscribe(h, cl, request.subscriptions); break;
      case protocol::Request::Op::kUnsubscribe: unsubscribe(h, cl, request.subscription_ids); break;
      case protocol::Request::Op::kInvalid: error(h, cl, request.error); break;
    }
  }

  void subscribe(Hdl h, Client& cl, const std::vector<protocol::Request::Subscription>& subscriptions) {
    for (const protocol::Request::Subscription& s : subscriptions) {
      if (cl.closing) return;
      const std::optional<std::uint32_t> id = s.id, channel = s.channel;
      if (!id || !channel) {
        error(h, cl, "subscribe: each subscription needs an \"id\" and a \"channelId\" (u32)");
        continue;
      }
      if (*channel >= channels.size()) {
        error(h, cl, fmt::format("subscribe: unknown channel id {}", *channel));
        continue;
      }
      if (cl.subscriptions.count(*id) != 0) {
        error(h, cl, fmt::format("subscribe: subscription id {} is in use", *id));
        continue;
      }
      if (cl.subscription_of[*channel] >= 0) {
        error(h, cl,
              fmt::format("subscribe: channel {} is already subscribed (subscription {})", *channel,
                          cl.subscription_of[*channel]));
        continue;
      }
      cl.subscriptions[*id] = *channel;
      cl.subscription_of[*channel] = *id;
      Channel& ch = *channels[*channel];
      ++ch.subscribers;
      notify_subscriptions_changed();
      if (ch.last_t_ns >= 0) send_message(h, cl, *id, ch.last_t_ns, ch.last);
    }
  }

  void unsubscribe(Hdl h, Client& cl, const std::vector<protocol::Request::SubscriptionId>& ids) {
    for (const protocol::Request::SubscriptionId& v : ids) {
      if (cl.closing) return;
      const std::optional<std::uint32_t> id = v.id;
      const auto it = id ? cl.subscriptions.find(*id) : cl.subscriptions.end();
      if (it == cl.subscriptions.end()) {
        error(h, cl, fmt::format("unsubscribe: unknown subscription id {}", v.text));
        continue;
      }
      --channels[it->second]->subscribers;
      cl.subscription_of[it->second] = -1;
      cl.subscriptions.erase(it);
      notify_subscriptions_changed();
    }
  }

  // --- sending -------------------------------------------------------------------------------------
  void send_text(Hdl h, const std::string& text) {
    websocketpp::lib::error_code ec;
    ws.send(h, text, websocketpp::frame::opcode::text, ec);
  }

  // False when the client's queue is full (nothing sent).
  bool room(Hdl h, Client& cl, WsServer::connection_ptr& c) {
    c = connection(h);
    if (!c) return false;
    if (c->get_buffered_amount() <= options.client_queue_bytes) {
      if (cl.dropping) {
        cl.dropping = false;
        log(fmt::format("client {} ({}) reads again; {} messages dropped for it so far", cl.id, cl.remote, cl.dropped));
      }
      return true;
    }
    if (!cl.dropping) {
      cl.dropping = true;
      log(fmt::format("client {} ({}) does not keep up: {} bytes queued; dropping its messages", cl.id, cl.remote,
                      c->get_buffered_amount()));
    }
    return false;
  }

  void send_time(Hdl h, Client& cl) {
    WsServer::connection_ptr c;
    if (!room(h, cl, c)) return;
    const std::array<std::uint8_t, 9> frame = protocol::time_frame(time_ns);
    c->send(frame.data(), frame.size(), websocketpp::frame::opcode::binary);
    ++n_time;
  }

  void send_message(Hdl h, Client& cl, std::uint32_t subscription, std::int64_t t_ns,
                    const std::vector<std::uint8_t>& cdr) {
    WsServer::connection_ptr c;
    if (!room(h, cl, c)) {
      ++cl.dropped;
      ++n_dropped;
      return;
    }
    const std::vector<std::uint8_t> frame = protocol::message_frame(subscription, t_ns, cdr);
    c->send(frame.data(), frame.size(), websocketpp::frame::opcode::binary);
    ++n_sent;
  }

  // Runs on the server thread: everything handed over so far, in the order it came.
  void drain() {
    {
      std::lock_guard<std::mutex> lock(handoff_mutex);
      batch.swap(handoff);
      drain_posted = false;
    }
    for (Handed& m : batch) {
      if (m.t_ns > time_ns) {
        time_ns = m.t_ns;
        for (auto& [h, cl] : clients) send_time(h, cl);
      }
      for (auto& [h, cl] : clients) {
        const std::int64_t sub = cl.subscription_of[m.channel];
        if (sub >= 0) send_message(h, cl, static_cast<std::uint32_t>(sub), m.t_ns, m.cdr);
      }
      Channel& ch = *channels[m.channel];
      ch.last = std::move(m.cdr);
      ch.last_t_ns = m.t_ns;
    }
    batch.clear();  // keeps its capacity for the next swap
  }

  void run() {
    // Ctrl-C and SIGTERM go to the node's threads, which poll for them.
    sigset_t block;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &block, nullptr);
    for (;;) {
      try {
        io.run();
        return;
      } catch (const std::exception& e) {  // a handler's failure ends that handler, not the server
        log(fmt::format("error: {}", e.what()));
      }
    }
  }
};

Server::Server(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}

Server::~Server() { stop(); }

std::uint32_t Server::add_channel(const std::string& topic, const std::string& schema_name, const std::string& schema) {
  if (impl_->started) throw std::logic_error("foxglove::Server::add_channel after start()");
  auto ch = std::make_unique<Impl::Channel>();
  ch->info = {topic, schema_name, schema};
  impl_->channels.push_back(std::move(ch));
  return static_cast<std::uint32_t>(impl_->channels.size() - 1);
}

std::uint32_t Server::add_latched_channel(const std::string& topic, const std::string& schema_name,
                                          const std::string& schema, std::int64_t t_ns, std::vector<std::uint8_t> cdr) {
  const std::uint32_t id = add_channel(topic, schema_name, schema);
  // The newest message of a channel is what a subscribing client gets at once (Impl::subscribe).
  Impl::Channel& ch = *impl_->channels[id];
  ch.last = std::move(cdr);
  ch.last_t_ns = std::max<std::int64_t>(t_ns, 0);
  return id;
}

void Server::start() {
  Impl& s = *impl_;
  const std::string where = fmt::format("{}:{}", s.options.address, s.options.port);
  asio::error_code aec;
  const asio::ip::address address = asio::ip::make_address(s.options.address, aec);
  if (aec) throw std::runtime_error(fmt::format("foxglove: {}: not an IP address", s.options.address));
  s.ws.clear_access_channels(websocketpp::log::alevel::all);  // the server logs what matters itself
  s.ws.clear_error_channels(websocketpp::log::elevel::all);
  websocketpp::lib::error_code ec;
  s.ws.init_asio(&s.io, ec);
  if (ec) throw std::runtime_error(fmt::format("foxglove: {}: {}", where, ec.message()));
  s.ws.set_reuse_addr(true);
  s.ws.set_max_message_size(s.options.max_client_frame_bytes);
  s.ws.set_validate_handler([&s](Hdl h) { return s.validate(h); });
  s.ws.set_open_handler([&s](Hdl h) { s.on_open(h); });
  s.ws.set_close_handler([&s](Hdl h) { s.on_close(h); });
  s.ws.set_fail_handler([&s](Hdl h) { s.on_close(h); });
  s.ws.set_message_handler([&s](Hdl h, WsServer::message_ptr m) { s.on_message(h, std::move(m)); });
  s.ws.listen(asio::ip::tcp::endpoint(address, s.options.port), ec);
  if (ec) throw std::runtime_error(fmt::format("foxglove: cannot listen on {}: {}", where, ec.message()));
  const asio::ip::tcp::endpoint bound = s.ws.get_local_endpoint(ec);
  if (ec) throw std::runtime_error(fmt::format("foxglove: {}: {}", where, ec.message()));
  port_ = bound.port();
  s.ws.start_accept(ec);
  if (ec) throw std::runtime_error(fmt::format("foxglove: {}: {}", where, ec.message()));
  s.session_id = std::to_string(std::chrono::system_clock::now().time_since_epoch().count());
  std::vector<const protocol::ChannelInfo*> infos;
  for (const auto& ch : s.channels) infos.push_back(&ch->info);
  s.advertised = protocol::advertise(infos);
  s.handoff.reserve(1024);
  s.batch.reserve(1024);
  s.started = true;
  s.thread = std::thread([&s] { s.run(); });
}

bool Server::wanted(std::uint32_t channel) const {
  return impl_->options.keep_last || impl_->channels[channel]->subscribers.load(std::memory_order_relaxed) > 0;
}

void Server::publish(std::uint32_t channel, std::int64_t t_ns, std::vector<std::uint8_t> cdr) {
  Impl& s = *impl_;
  {
    std::lock_guard<std::mutex> lock(s.handoff_mutex);
    if (s.stopped) return;
    if (s.handoff.size() >= s.options.handoff_messages) {
      ++s.n_handoff_dropped;
      return;
    }
    s.handoff.push_back({channel, t_ns, std::move(cdr)});
    if (s.drain_posted) return;
    s.drain_posted = true;
  }
  asio::post(s.io, [&s] { s.drain(); });
}

void Server::stop() {
  Impl& s = *impl_;
  {
    std::lock_guard<std::mutex> lock(s.handoff_mutex);
    if (s.stopped) return;
    s.stopped = true;
  }
  if (!s.started) return;
  asio::post(s.io, [&s] {
    websocketpp::lib::error_code ec;
    s.ws.stop_listening(ec);
    for (auto& [h, cl] : s.clients) s.ws.close(h, websocketpp::close::status::going_away, "server shutting down", ec);
  });
  // Clients that answer the close are gone within milliseconds; one that does not is cut off.
  {
    std::unique_lock<std::mutex> lock(s.open_mutex);
    s.closed.wait_for(lock, std::chrono::milliseconds(1000), [&s] { return s.open.load() == 0; });
  }
  s.io.stop();
  s.thread.join();
}

ServerStats Server::stats() const {
  const Impl& s = *impl_;
  return {s.n_clients.load(),         s.n_refused.load(), s.n_sent.load(), s.n_dropped.load(),
          s.n_handoff_dropped.load(), s.n_time.load(),    s.n_bad.load(),  s.n_disconnected.load()};
}

std::size_t Server::connected() const { return impl_->open.load(); }

std::size_t Server::subscriptions() const {
  std::size_t n = 0;
  for (const auto& ch : impl_->channels) n += static_cast<std::size_t>(ch->subscribers.load());
  return n;
}

std::size_t Server::wait_subscriptions_change(std::size_t seen, std::chrono::steady_clock::time_point deadline) const {
  std::unique_lock<std::mutex> lock(impl_->subscriptions_mutex);
  impl_->subscriptions_changed.wait_until(lock, deadline, [&] { return subscriptions() != seen; });
  return subscriptions();
}

std::string Server::summary() const {
  const ServerStats st = stats();
  return fmt::format(
      "{} clients ({} refused), {} messages sent, {} dropped for slow clients, {} dropped before the "
      "server thread, {} bad requests, {} clients disconnected",
      st.clients, st.refused, st.messages_sent, st.messages_dropped, st.handoff_dropped, st.bad_requests,
      st.disconnected);
}

}  // namespace quadcosim::foxglove
