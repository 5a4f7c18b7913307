#include "foxglove/protocol.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

namespace quadcosim::foxglove::protocol {

namespace {

using nlohmann::json;

// Binary opcodes (server to client) and status levels of the protocol.
constexpr std::uint8_t kMessageData = 0x01, kTime = 0x02;
constexpr int kStatusError = 2;

void put_le(std::uint8_t* p, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// A JSON number that is a whole number fitting a u32 (ids), else nullopt.
std::optional<std::uint32_t> as_u32(const json& v) {
  if (v.is_number_unsigned() && v.get<std::uint64_t>() <= UINT32_MAX)
    return static_cast<std::uint32_t>(v.get<std::uint64_t>());
  if (v.is_number_integer() && v.get<std::int64_t>() >= 0 && v.get<std::int64_t>() <= UINT32_MAX)
    return static_cast<std::uint32_t>(v.get<std::int64_t>());
  return std::nullopt;
}

Request invalid(std::string what) {
  Request r;
  r.error = std::move(what);
  return r;
}

}  // namespace

std::string server_info(const std::string& name, const std::string& session_id) {
  return json{{"op", "serverInfo"},
              {"name", name},
              {"capabilities", json::array({"time"})},
              {"supportedEncodings", json::array({"cdr"})},
              {"metadata", json::object()},
              {"sessionId", session_id}}
      .dump();
}

std::string advertise(const std::vector<const ChannelInfo*>& channels) {
  json list = json::array();
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const ChannelInfo& ch = *channels[i];
    list.push_back({{"id", i},
                    {"topic", ch.topic},
                    {"encoding", "cdr"},
                    {"schemaName", ch.schema_name},
                    {"schema", ch.schema},
                    {"schemaEncoding", "ros2msg"}});
  }
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string status_error(const std::string& message) {
  return json{{"op", "status"}, {"level", kStatusError}, {"message", message}}.dump();
}

std::array<std::uint8_t, 9> time_frame(std::int64_t t_ns) {
  std::array<std::uint8_t, 9> frame{};
  frame[0] = kTime;
  put_le(frame.data() + 1, static_cast<std::uint64_t>(t_ns), 8);
  return frame;
}

std::vector<std::uint8_t> message_frame(std::uint32_t subscription, std::int64_t t_ns,
                                        const std::vector<std::uint8_t>& cdr) {
  std::vector<std::uint8_t> frame(13 + cdr.size());
  frame[0] = kMessageData;
  put_le(frame.data() + 1, subscription, 4);
  put_le(frame.data() + 5, static_cast<std::uint64_t>(std::max<std::int64_t>(t_ns, 0)), 8);
  std::copy(cdr.begin(), cdr.end(), frame.begin() + 13);
  return frame;
}

Request parse_request(std::string_view text) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return invalid("malformed JSON");
  if (!j.is_object() || !j.contains("op") || !j["op"].is_string())
    return invalid("a JSON message must be an object with a string field \"op\"");
  const std::string op = j["op"].get<std::string>();
  Request r;
  if (op == "subscribe") {
    if (!j.contains("subscriptions") || !j["subscriptions"].is_array())
      return invalid("subscribe: \"subscriptions\" must be an array");
    r.op = Request::Op::kSubscribe;
    for (const json& s : j["subscriptions"]) {
      Request::Subscription sub;
      if (s.is_object() && s.contains("id")) sub.id = as_u32(s["id"]);
      if (s.is_object() && s.contains("channelId")) sub.channel = as_u32(s["channelId"]);
      r.subscriptions.push_back(sub);
    }
  } else if (op == "unsubscribe") {
    if (!j.contains("subscriptionIds") || !j["subscriptionIds"].is_array())
      return invalid("unsubscribe: \"subscriptionIds\" must be an array");
    r.op = Request::Op::kUnsubscribe;
    for (const json& v : j["subscriptionIds"]) r.subscription_ids.push_back({as_u32(v), v.dump()});
  } else {
    return invalid(fmt::format("op \"{}\" is not supported (capabilities: time)", op));
  }
  return r;
}

}  // namespace quadcosim::foxglove::protocol
