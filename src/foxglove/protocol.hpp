// The Foxglove WebSocket protocol's messages (foxglove.websocket.v1) as the server speaks them: the
// JSON texts it sends (serverInfo, advertise, status), its binary frames (message data, time) and the
// client's JSON requests parsed (subscribe, unsubscribe). No connection state: the server (server.cpp)
// decides what a request does to a client.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::foxglove::protocol {

/// A channel as advertised: messages are CDR, `schema` is ros2msg text.
struct ChannelInfo {
  std::string topic, schema_name, schema;
};

/// The serverInfo message: capability time, encoding cdr.
std::string server_info(const std::string& name, const std::string& session_id);
/// The advertise message of `channels`, channel id = index.
std::string advertise(const std::vector<const ChannelInfo*>& channels);
/// A status message of level error.
std::string status_error(const std::string& message);

/// The binary time frame (opcode 0x02, the time in ns, little-endian).
std::array<std::uint8_t, 9> time_frame(std::int64_t t_ns);
/// The binary message data frame (opcode 0x01, subscription id, time in ns (negative as 0), the CDR).
std::vector<std::uint8_t> message_frame(std::uint32_t subscription, std::int64_t t_ns,
                                        const std::vector<std::uint8_t>& cdr);

/// A client's text message parsed.
struct Request {
  enum class Op { kSubscribe, kUnsubscribe, kInvalid };
  Op op = Op::kInvalid;
  std::string error;  ///< kInvalid: what is wrong with it (the status text sent back)
  /// kSubscribe: the entries in order; an id or channelId missing or not a u32 is nullopt.
  struct Subscription {
    std::optional<std::uint32_t> id, channel;
  };
  std::vector<Subscription> subscriptions;
  /// kUnsubscribe: the ids in order (nullopt when not a u32), each with its JSON text for errors.
  struct SubscriptionId {
    std::optional<std::uint32_t> id;
    std::string text;
  };
  std::vector<SubscriptionId> subscription_ids;
};

/// Parses a client's text message: an object with a string "op", subscribe with an array
/// "subscriptions" or unsubscribe with an array "subscriptionIds"; anything else is kInvalid with the
/// reason.
Request parse_request(std::string_view text);

}  // namespace quadcosim::foxglove::protocol
