// The Foxglove protocol's messages and frames (protocol.hpp) and the Origin policy (origin_allowed),
// against bytes and texts written out by hand from the protocol's specification.
#include "foxglove/protocol.hpp"

#include <gtest/gtest.h>

#include "foxglove/server.hpp"

namespace quadcosim::foxglove {
namespace {

TEST(FoxgloveProtocol, TimeFrameIsOpcodeThenLittleEndianNanoseconds) {
  // 0x0102030405060708 ns
  const auto f = protocol::time_frame(0x0102030405060708LL);
  const std::array<std::uint8_t, 9> want{0x02, 0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01};
  EXPECT_EQ(f, want);
}

TEST(FoxgloveProtocol, MessageFrameHasSubscriptionTimeAndPayload) {
  const auto f = protocol::message_frame(0x0A0B0C0D, 1'000'000'000, {0xAA, 0xBB});
  // 1e9 ns = 0x3B9ACA00
  const std::vector<std::uint8_t> want{0x01, 0x0D, 0x0C, 0x0B, 0x0A, 0x00, 0xCA, 0x9A,
                                       0x3B, 0x00, 0x00, 0x00, 0x00, 0xAA, 0xBB};
  EXPECT_EQ(f, want);
  // A negative time is sent as 0.
  const auto g = protocol::message_frame(1, -5, {});
  EXPECT_EQ(g, (std::vector<std::uint8_t>{0x01, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
}

TEST(FoxgloveProtocol, TextMessages) {
  EXPECT_EQ(protocol::status_error("bad"), R"({"level":2,"message":"bad","op":"status"})");
  EXPECT_EQ(protocol::server_info("q", "7"),
            R"({"capabilities":["time"],"metadata":{},"name":"q","op":"serverInfo","sessionId":"7",)"
            R"("supportedEncodings":["cdr"]})");
  const protocol::ChannelInfo a{"/drone/Pose", "geometry_msgs/msg/PoseStamped", "text"};
  EXPECT_EQ(protocol::advertise({&a}),
            R"({"channels":[{"encoding":"cdr","id":0,"schema":"text","schemaEncoding":"ros2msg",)"
            R"("schemaName":"geometry_msgs/msg/PoseStamped","topic":"/drone/Pose"}],"op":"advertise"})");
}

TEST(FoxgloveProtocol, ParsesSubscribeEntriesKeepingBadOnes) {
  const auto r = protocol::parse_request(
      R"({"op":"subscribe","subscriptions":[{"id":3,"channelId":1},{"id":-1,"channelId":2},{"channelId":4},)"
      R"({"id":4294967295,"channelId":4294967296}]})");
  ASSERT_EQ(r.op, protocol::Request::Op::kSubscribe);
  ASSERT_EQ(r.subscriptions.size(), 4u);
  EXPECT_EQ(r.subscriptions[0].id, 3u);
  EXPECT_EQ(r.subscriptions[0].channel, 1u);
  EXPECT_FALSE(r.subscriptions[1].id.has_value());
  EXPECT_EQ(r.subscriptions[1].channel, 2u);
  EXPECT_FALSE(r.subscriptions[2].id.has_value());
  EXPECT_EQ(r.subscriptions[3].id, 4294967295u);
  EXPECT_FALSE(r.subscriptions[3].channel.has_value());
}

TEST(FoxgloveProtocol, ParsesUnsubscribeWithTheIdsText) {
  const auto r = protocol::parse_request(R"({"op":"unsubscribe","subscriptionIds":[5,"x"]})");
  ASSERT_EQ(r.op, protocol::Request::Op::kUnsubscribe);
  ASSERT_EQ(r.subscription_ids.size(), 2u);
  EXPECT_EQ(r.subscription_ids[0].id, 5u);
  EXPECT_FALSE(r.subscription_ids[1].id.has_value());
  EXPECT_EQ(r.subscription_ids[1].text, R"("x")");
}

TEST(FoxgloveProtocol, RefusesWhatIsNotARequest) {
  const auto error_of = [](const char* text) {
    const auto r = protocol::parse_request(text);
    EXPECT_EQ(r.op, protocol::Request::Op::kInvalid) << text;
    return r.error;
  };
  EXPECT_EQ(error_of("{"), "malformed JSON");
  EXPECT_EQ(error_of("[1]"), "a JSON message must be an object with a string field \"op\"");
  EXPECT_EQ(error_of(R"({"op":1})"), "a JSON message must be an object with a string field \"op\"");
  EXPECT_EQ(error_of(R"({"op":"subscribe"})"), "subscribe: \"subscriptions\" must be an array");
  EXPECT_EQ(error_of(R"({"op":"unsubscribe","subscriptionIds":3})"),
            "unsubscribe: \"subscriptionIds\" must be an array");
  EXPECT_EQ(error_of(R"({"op":"advertise"})"), "op \"advertise\" is not supported (capabilities: time)");
}

TEST(FoxgloveOrigin, LocalPagesAndNativeClientsOnly) {
  EXPECT_TRUE(origin_allowed("", {}));
  EXPECT_TRUE(origin_allowed("http://localhost:8080", {}));
  EXPECT_TRUE(origin_allowed("HTTPS://127.0.0.1/", {}));
  EXPECT_TRUE(origin_allowed("http://[::1]", {}));
  EXPECT_FALSE(origin_allowed("http://localhost.evil.com", {}));
  EXPECT_FALSE(origin_allowed("http://localhost:80/path", {}));
  EXPECT_FALSE(origin_allowed("null", {}));
  EXPECT_FALSE(origin_allowed("https://app.foxglove.dev", {}));
  EXPECT_TRUE(origin_allowed("https://app.foxglove.dev", {"https://APP.foxglove.dev/"}));
  EXPECT_TRUE(origin_allowed("https://anything.example", {"*"}));
}

}  // namespace
}  // namespace quadcosim::foxglove
