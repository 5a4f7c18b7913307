// ROS 2 parameter services over DDS: server and client in one process on a private domain with
// localhost-only discovery, against a small stand-in parameter table.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <thread>

#include "dds/dds_test_support.hpp"
#include "dds/dds_transport.hpp"
#include "dds/parameter_client.hpp"
#include "dds/parameter_service.hpp"
#include "rcl_interfaces.h"

namespace quadcosim::dds {
namespace {

constexpr std::int64_t kSecond = 1'000'000'000;

// Two doubles with ranges and a choice, refusing like control::set_parameter does.
class FakeTable {
 public:
  ParameterCallbacks callbacks() {
    ParameterCallbacks cb;
    cb.names = [] { return std::vector<std::string>{"z_des", "gain.kp", "gain.inner.ki", "mode"}; };
    cb.get = [this](const std::string& n) -> std::optional<ParamValue> {
      std::lock_guard lock(mutex_);
      if (n == "mode") return ParamValue::of_string(mode_);
      const auto it = numbers_.find(n);
      if (it == numbers_.end()) return std::nullopt;
      return ParamValue::of_double(it->second);
    };
    cb.set = [this](const std::string& n, const ParamValue& v) -> std::string {
      std::lock_guard lock(mutex_);
      if (n == "mode") {
        if (v.type != ParamType::kString || (v.string_value != "attitude" && v.string_value != "position")) {
          return "mode must be one of 'attitude' 'position', got '" + v.string_value + "'";
        }
        mode_ = v.string_value;
        return {};
      }
      const auto it = numbers_.find(n);
      if (it == numbers_.end()) return "unknown parameter '" + n + "'";
      if (v.type != ParamType::kDouble) return n + " must be a number, got '" + v.string_value + "'";
      if (!(v.double_value >= -1000 && v.double_value <= 1e5)) return n + " must be in [-1000, 100000] m";
      it->second = v.double_value;
      return {};
    };
    cb.describe = [this](const std::string& n) -> std::optional<ParamDescriptor> {
      if (n != "mode" && !numbers_.count(n)) return std::nullopt;
      ParamDescriptor d;
      d.name = n;
      d.type = n == "mode" ? ParamType::kString : ParamType::kDouble;
      d.description = "test parameter " + n;
      if (n != "mode") d.floating_point_range = FloatRange{-1000, 1e5, 0};
      return d;
    };
    return cb;
  }
  double number(const std::string& n) {
    std::lock_guard lock(mutex_);
    return numbers_.at(n);
  }
  std::string mode() {
    std::lock_guard lock(mutex_);
    return mode_;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, double> numbers_{{"z_des", 1.0}, {"gain.kp", 2.0}, {"gain.inner.ki", 0.5}};
  std::string mode_ = "attitude";
};

// A node with the parameter services, spun on its own thread like a controller's loop.
class ServedNode {
 public:
  explicit ServedNode(FakeTable& table, const std::string& name = "test_controller")
      : transport_(test::private_env()), server_(transport_, parse_node_name(name), table.callbacks()) {
    thread_ = std::thread([this] {
      while (!stop_) transport_.spin_once(20'000'000);
    });
  }
  ~ServedNode() {
    stop_ = true;
    thread_.join();
  }
  const ParameterServer& server() const { return server_; }
  std::array<std::uint8_t, 16> participant_guid() {
    dds_guid_t g;
    dds_get_guid(transport_.participant().handle(), &g);
    std::array<std::uint8_t, 16> out{};
    std::copy(std::begin(g.v), std::end(g.v), out.begin());
    return out;
  }

 private:
  DdsTransport transport_;
  ParameterServer server_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

Param param(const std::string& n, ParamValue v) { return {n, std::move(v)}; }

TEST(ParameterTypesTest, NamesAndTopicsFollowRmwCyclonedds) {
  const NodeName n = parse_node_name("attitude_controller");
  EXPECT_EQ(n.ns, "/");
  EXPECT_EQ(n.fully_qualified(), "/attitude_controller");
  EXPECT_EQ(parse_node_name("/attitude_controller").fully_qualified(), "/attitude_controller");
  const NodeName u = parse_node_name("/uav1/attitude_controller");
  EXPECT_EQ(u.ns, "/uav1");
  EXPECT_EQ(u.name, "attitude_controller");
  EXPECT_EQ(request_topic(n, ParamService::kSet), "rq/attitude_controller/set_parametersRequest");
  EXPECT_EQ(reply_topic(n, ParamService::kSet), "rr/attitude_controller/set_parametersReply");
  EXPECT_EQ(request_topic(u, ParamService::kGetTypes), "rq/uav1/attitude_controller/get_parameter_typesRequest");
  EXPECT_EQ(reply_topic(n, ParamService::kSetAtomically), "rr/attitude_controller/set_parameters_atomicallyReply");
  EXPECT_EQ(reply_topic(n, ParamService::kDescribe), "rr/attitude_controller/describe_parametersReply");
  EXPECT_EQ(reply_topic(n, ParamService::kList), "rr/attitude_controller/list_parametersReply");
  EXPECT_EQ(reply_topic(n, ParamService::kGet), "rr/attitude_controller/get_parametersReply");
  EXPECT_THROW(parse_node_name(""), std::invalid_argument);
  EXPECT_THROW(parse_node_name("/a//b"), std::invalid_argument);
  EXPECT_THROW(parse_node_name("9lives"), std::invalid_argument);
  EXPECT_THROW(parse_node_name("bad-name"), std::invalid_argument);

  EXPECT_STREQ(rcl_interfaces_srv_dds__SetParameters_Request__desc.m_typename,
               "rcl_interfaces::srv::dds_::SetParameters_Request_");
  EXPECT_STREQ(rcl_interfaces_srv_dds__ListParameters_Response__desc.m_typename,
               "rcl_interfaces::srv::dds_::ListParameters_Response_");
  EXPECT_STREQ(rcl_interfaces_msg_dds__ParameterEvent__desc.m_typename, "rcl_interfaces::msg::dds_::ParameterEvent_");
}

TEST(ParameterTypesTest, ListFollowsRclcppDepthAndPrefixRules) {
  const std::vector<std::string> names = {"z_des", "gain.kp", "gain.inner.ki", "mode"};
  ListResult all = list_parameters(names, {}, kDepthRecursive);
  EXPECT_EQ(all.names, names);
  EXPECT_EQ(all.prefixes, (std::vector<std::string>{"gain", "gain.inner"}));
  EXPECT_EQ(list_parameters(names, {}, 1).names, (std::vector<std::string>{"z_des", "mode"}));
  EXPECT_EQ(list_parameters(names, {}, 2).names, (std::vector<std::string>{"z_des", "gain.kp", "mode"}));
  EXPECT_EQ(list_parameters(names, {"gain"}, kDepthRecursive).names,
            (std::vector<std::string>{"gain.kp", "gain.inner.ki"}));
  EXPECT_EQ(list_parameters(names, {"gain"}, 1).names, (std::vector<std::string>{"gain.kp"}));
  EXPECT_EQ(list_parameters(names, {"mode"}, 1).names, (std::vector<std::string>{"mode"}));
  EXPECT_TRUE(list_parameters(names, {"gai"}, kDepthRecursive).names.empty());
}

TEST(ParameterTypesTest, PrintsAndParsesValuesLikeRos2Param) {
  EXPECT_EQ(python_float(10.0), "10.0");
  EXPECT_EQ(python_float(3.0), "3.0");
  EXPECT_EQ(python_float(0.1), "0.1");
  EXPECT_EQ(python_float(-2.5), "-2.5");
  EXPECT_EQ(python_float(1e-4), "0.0001");
  EXPECT_EQ(python_float(1e-5), "1e-05");
  EXPECT_EQ(python_float(1.5e-7), "1.5e-07");
  EXPECT_EQ(python_float(1e9), "1000000000.0");
  EXPECT_EQ(python_float(1e16), "1e+16");
  EXPECT_EQ(python_float(1.25e100), "1.25e+100");
  EXPECT_EQ(python_float(123456.789), "123456.789");
  EXPECT_EQ(python_float(-0.0), "-0.0");
  EXPECT_EQ(python_float(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(python_float(HUGE_VAL), "inf");
  EXPECT_EQ(python_float(std::nan("")), "nan");

  EXPECT_EQ(ros2_get_line(ParamValue::of_double(10.0)), "Double value is: 10.0");
  EXPECT_EQ(ros2_get_line(ParamValue::of_string("attitude")), "String value is: attitude");
  EXPECT_EQ(ros2_get_line(ParamValue::of_integer(-3)), "Integer value is: -3");
  EXPECT_EQ(ros2_get_line(ParamValue::of_bool(true)), "Boolean value is: True");
  EXPECT_EQ(ros2_get_line(ParamValue{}), "Parameter not set.");
  ParamValue arr;
  arr.type = ParamType::kDoubleArray;
  arr.double_array_value = {1.0, 2.5};
  EXPECT_EQ(ros2_get_line(arr), "Double values are: [1.0, 2.5]");
  arr.type = ParamType::kStringArray;
  arr.string_array_value = {"a", "it's"};
  EXPECT_EQ(ros2_get_line(arr), "String values are: ['a', \"it's\"]");
  arr.type = ParamType::kByteArray;
  arr.byte_array_value = {1, 'a'};
  EXPECT_EQ(ros2_get_line(arr), "Byte values are: [b'\\x01', b'a']");

  EXPECT_EQ(parse_param_value("10"), ParamValue::of_integer(10));
  EXPECT_EQ(parse_param_value("-7"), ParamValue::of_integer(-7));
  EXPECT_EQ(parse_param_value("+7"), ParamValue::of_integer(7));
  EXPECT_EQ(parse_param_value("10.0"), ParamValue::of_double(10.0));
  EXPECT_EQ(parse_param_value("-.5"), ParamValue::of_double(-0.5));
  EXPECT_EQ(parse_param_value("1e3"), ParamValue::of_double(1000.0));
  EXPECT_EQ(parse_param_value(".inf"), ParamValue::of_double(HUGE_VAL));
  EXPECT_TRUE(std::isnan(parse_param_value(".nan").double_value));
  EXPECT_EQ(parse_param_value("true"), ParamValue::of_bool(true));
  EXPECT_EQ(parse_param_value("Off"), ParamValue::of_bool(false));
  EXPECT_EQ(parse_param_value("position"), ParamValue::of_string("position"));
  EXPECT_EQ(parse_param_value("inf"), ParamValue::of_string("inf"));
  EXPECT_EQ(parse_param_value("1.2.3"), ParamValue::of_string("1.2.3"));
  EXPECT_EQ(parse_param_value(""), ParamValue::of_string(""));
}

TEST(ParameterServiceTest, GetSetListDescribeTypesRoundTrip) {
  FakeTable table;
  ServedNode node(table);
  ParameterClient client(test::private_env(), parse_node_name("/test_controller"));
  const std::int64_t t = 10 * kSecond;

  // get
  auto values = client.get({"z_des", "mode"}, t);
  ASSERT_EQ(values.size(), 2u);
  EXPECT_EQ(values[0], ParamValue::of_double(1.0));
  EXPECT_EQ(values[1], ParamValue::of_string("attitude"));
  EXPECT_TRUE(client.get({"z_des", "z_dse"}, t).empty());  // rclcpp: nothing when one is undeclared

  // set: a double, an INTEGER for a double (what `ros2 param set NODE z_des 10` sends), a choice
  auto results = client.set({param("z_des", ParamValue::of_double(3.5))}, t);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_TRUE(results[0].successful) << results[0].reason;
  EXPECT_EQ(table.number("z_des"), 3.5);
  results = client.set({param("z_des", ParamValue::of_integer(10))}, t);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_TRUE(results[0].successful) << results[0].reason;
  EXPECT_EQ(client.get({"z_des"}, t).at(0), ParamValue::of_double(10.0));
  results = client.set({param("mode", ParamValue::of_string("position"))}, t);
  EXPECT_TRUE(results.at(0).successful);
  EXPECT_EQ(table.mode(), "position");

  // refusals carry the table's reason and change nothing; each parameter stands on its own
  results = client.set({param("z_des", ParamValue::of_string("high")), param("z_dse", ParamValue::of_double(1)),
                        param("z_des", ParamValue::of_double(1e9)), param("gain.kp", ParamValue::of_double(4))},
                       t);
  ASSERT_EQ(results.size(), 4u);
  EXPECT_FALSE(results[0].successful);
  EXPECT_EQ(results[0].reason, "z_des must be a number, got 'high'");
  EXPECT_FALSE(results[1].successful);
  EXPECT_EQ(results[1].reason, "unknown parameter 'z_dse'");
  EXPECT_FALSE(results[2].successful);
  EXPECT_EQ(results[2].reason, "z_des must be in [-1000, 100000] m");
  EXPECT_TRUE(results[3].successful);
  EXPECT_EQ(table.number("z_des"), 10.0);
  EXPECT_EQ(table.number("gain.kp"), 4.0);
  EXPECT_FALSE(client.set({param("z_des", ParamValue{})}, t).at(0).successful);  // NOT_SET: no undeclaring

  // atomically: all or none
  SetResult r = client.set_atomically(
      {param("z_des", ParamValue::of_double(5)), param("mode", ParamValue::of_string("upside_down"))}, t);
  EXPECT_FALSE(r.successful);
  EXPECT_EQ(r.reason, "mode must be one of 'attitude' 'position', got 'upside_down'");
  EXPECT_EQ(table.number("z_des"), 10.0);  // rolled back
  r = client.set_atomically(
      {param("z_des", ParamValue::of_integer(6)), param("mode", ParamValue::of_string("attitude"))}, t);
  EXPECT_TRUE(r.successful) << r.reason;
  EXPECT_EQ(table.number("z_des"), 6.0);
  EXPECT_EQ(table.mode(), "attitude");

  // list
  ListResult l = client.list({}, kDepthRecursive, t);
  EXPECT_EQ(l.names, (std::vector<std::string>{"z_des", "gain.kp", "gain.inner.ki", "mode"}));
  EXPECT_EQ(l.prefixes, (std::vector<std::string>{"gain", "gain.inner"}));
  EXPECT_EQ(client.list({"gain"}, 1, t).names, (std::vector<std::string>{"gain.kp"}));

  // types
  EXPECT_EQ(client.get_types({"z_des", "mode"}, t), (std::vector<ParamType>{ParamType::kDouble, ParamType::kString}));
  EXPECT_TRUE(client.get_types({"nope"}, t).empty());

  // describe
  auto d = client.describe({"z_des", "mode"}, t);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].name, "z_des");
  EXPECT_EQ(d[0].type, ParamType::kDouble);
  EXPECT_EQ(d[0].description, "test parameter z_des");
  ASSERT_TRUE(d[0].floating_point_range.has_value());
  EXPECT_EQ(d[0].floating_point_range->from_value, -1000);
  EXPECT_EQ(d[0].floating_point_range->to_value, 1e5);
  EXPECT_FALSE(d[0].integer_range.has_value());
  EXPECT_EQ(d[1].type, ParamType::kString);
  EXPECT_FALSE(d[1].floating_point_range.has_value());
  EXPECT_TRUE(client.describe({"z_des", "nope"}, t).empty());

  EXPECT_EQ(node.server().stats().replies_dropped, 0u);
}

TEST(ParameterServiceTest, RepliesEchoGuidAndSequenceAndEventsAnnounceChanges) {
  FakeTable table;
  ServedNode node(table);
  const NodeName name = parse_node_name("test_controller");

  // A bare DDS requester, without the "clientid" USER_DATA, with its own header values.
  Participant raw(test::private_env());
  const dds_entity_t rq_topic = dds_create_topic(raw.handle(), &rcl_interfaces_srv_dds__GetParameters_Request__desc,
                                                 request_topic(name, ParamService::kGet).c_str(), nullptr, nullptr);
  const dds_entity_t rr_topic = dds_create_topic(raw.handle(), &rcl_interfaces_srv_dds__GetParameters_Response__desc,
                                                 reply_topic(name, ParamService::kGet).c_str(), nullptr, nullptr);
  const dds_entity_t ev_topic = dds_create_topic(raw.handle(), &rcl_interfaces_msg_dds__ParameterEvent__desc,
                                                 "rt/parameter_events", nullptr, nullptr);
  ASSERT_GT(rq_topic, 0);
  ASSERT_GT(rr_topic, 0);
  ASSERT_GT(ev_topic, 0);
  dds_qos_t* qos = ros_qos(10, true);
  const dds_entity_t writer = dds_create_writer(raw.handle(), rq_topic, qos, nullptr);
  const dds_entity_t reader = dds_create_reader(raw.handle(), rr_topic, qos, nullptr);
  const dds_entity_t events = dds_create_reader(raw.handle(), ev_topic, qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(writer, 0);
  ASSERT_GT(reader, 0);
  ASSERT_GT(events, 0);
  const dds_entity_t ws = dds_create_waitset(raw.handle());
  const dds_entity_t rc = dds_create_readcondition(reader, DDS_ANY_STATE);
  const dds_entity_t ec = dds_create_readcondition(events, DDS_ANY_STATE);
  dds_waitset_attach(ws, rc, 0);
  dds_waitset_attach(ws, ec, 1);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (;;) {
    dds_publication_matched_status_t p;
    dds_subscription_matched_status_t s;
    dds_get_publication_matched_status(writer, &p);
    dds_get_subscription_matched_status(reader, &s);
    if (p.current_count > 0 && s.current_count > 0) break;
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "server not matched";
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }

  rcl_interfaces_srv_dds__GetParameters_Request_ rq{};
  char z_des[] = "z_des";
  char* names[] = {z_des};
  rq.guid = 0x0123456789abcdefULL;
  rq.seq = 42;
  rq.names = {1, 1, names, false};
  ASSERT_GE(dds_write(writer, &rq), 0);
  dds_write_flush(writer);
  bool got = false;
  while (!got && std::chrono::steady_clock::now() < deadline) {
    dds_waitset_wait(ws, nullptr, 0, kSecond);
    void* samples[4] = {nullptr};
    dds_sample_info_t infos[4];
    const dds_return_t n = dds_take(reader, samples, infos, 4, 4);
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto& rp = *static_cast<const rcl_interfaces_srv_dds__GetParameters_Response_*>(samples[i]);
      EXPECT_EQ(rp.guid, 0x0123456789abcdefULL);
      EXPECT_EQ(rp.seq, 42);
      ASSERT_EQ(rp.values._length, 1u);
      EXPECT_EQ(rp.values._buffer[0].type, 3);  // PARAMETER_DOUBLE
      EXPECT_EQ(rp.values._buffer[0].double_value, 1.0);
      got = true;
    }
    if (n > 0) dds_return_loan(reader, samples, n);
  }
  EXPECT_TRUE(got) << "no reply to a request without clientid";

  // Our client: guid is its request writer's instance handle, seq counts up; a set is announced.
  ParameterClient client(test::private_env(), name);
  client.get({"z_des"}, 10 * kSecond);
  const auto first = client.last_request();
  EXPECT_NE(first.guid, 0u);
  ASSERT_TRUE(client.set({param("z_des", ParamValue::of_integer(7))}, 10 * kSecond).at(0).successful);
  // The set uses another service, hence another request writer and guid; seq keeps counting.
  EXPECT_NE(client.last_request().guid, first.guid);
  EXPECT_EQ(client.last_request().seq, first.seq + 1);
  client.get({"z_des"}, 10 * kSecond);
  EXPECT_EQ(client.last_request().guid, first.guid);
  EXPECT_EQ(client.last_request().seq, first.seq + 2);

  bool event = false;
  deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!event && std::chrono::steady_clock::now() < deadline) {
    void* samples[4] = {nullptr};
    dds_sample_info_t infos[4];
    const dds_return_t n = dds_take(events, samples, infos, 4, 4);
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto& ev = *static_cast<const rcl_interfaces_msg_dds__ParameterEvent_*>(samples[i]);
      EXPECT_STREQ(ev.node, "/test_controller");
      ASSERT_EQ(ev.changed_parameters._length, 1u);
      EXPECT_STREQ(ev.changed_parameters._buffer[0].name, "z_des");
      EXPECT_EQ(ev.changed_parameters._buffer[0].value.type, 3);
      EXPECT_EQ(ev.changed_parameters._buffer[0].value.double_value, 7.0);
      EXPECT_EQ(ev.new_parameters._length, 0u);
      EXPECT_GT(ev.stamp.sec, 0);
      event = true;
    }
    if (n > 0) dds_return_loan(events, samples, n);
    if (!event) dds_waitset_wait(ws, nullptr, 0, 100'000'000);
  }
  EXPECT_TRUE(event) << "no ParameterEvent";
}

TEST(ParameterServiceTest, AnAsynchronousGetIsAnsweredThroughATransportInOrder) {
  // send_get returns at once; the replies come through DdsTransport::subscribe_raw, in the order of
  // the requests, each matched to its own request by is_reply_to.
  FakeTable table;
  ServedNode node(table);
  DdsTransport transport(test::private_env());
  ParameterClient client(transport.participant().handle(), parse_node_name("/test_controller"));
  ParameterClient nobody(transport.participant().handle(), parse_node_name("/nobody_here"));
  EXPECT_THROW(nobody.send_get({}), ParameterCallError) << "no service matched: refused, not lost";
  ASSERT_TRUE(client.wait_for_service(ParamService::kGet, 10 * kSecond));
  std::vector<ParameterClient::Header> requests;
  std::vector<std::int64_t> answered;  // the seq of each request a reply answered, in arrival order
  std::vector<double> values;
  transport.subscribe_raw(client.get_reply_reader(), "get_parameters reply", [&](const void* reply) {
    for (const auto& rq : requests) {
      if (!ParameterClient::is_reply_to(reply, rq)) continue;
      answered.push_back(rq.seq);
      const auto& r = *static_cast<const rcl_interfaces_srv_dds__GetParameters_Response_*>(reply);
      values.push_back(r.values._length == 1 ? r.values._buffer[0].double_value : -1.0);
    }
  });
  for (int i = 0; i < 5; ++i) requests.push_back(client.send_get({i % 2 == 0 ? "z_des" : "gain.kp"}));
  for (int i = 1; i < 5; ++i) EXPECT_EQ(requests[i].seq, requests[i - 1].seq + 1);
  ASSERT_TRUE(transport.spin_until([&] { return answered.size() == 5; }, 10 * kSecond)) << answered.size();
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(answered[i], requests[i].seq);
    EXPECT_EQ(values[i], i % 2 == 0 ? 1.0 : 2.0);
  }
  // A reply answers its own request only.
  rcl_interfaces_srv_dds__GetParameters_Response_ other{};
  other.guid = requests[0].guid;
  other.seq = requests[0].seq;
  EXPECT_TRUE(ParameterClient::is_reply_to(&other, requests[0]));
  EXPECT_FALSE(ParameterClient::is_reply_to(&other, requests[1]));
  other.guid += 1;
  EXPECT_FALSE(ParameterClient::is_reply_to(&other, requests[0]));
}

TEST(ParameterServiceTest, OnlyFromTakesThePeersRepliesNotANamesakes) {
  FakeTable peer_table, namesake_table;
  ServedNode namesake(namesake_table);  // the same node name on another participant: a leftover
  ServedNode peer(peer_table);
  ParameterClient client(test::private_env(), parse_node_name("/test_controller"));
  const std::int64_t t = 10 * kSecond;
  client.only_from(peer.participant_guid());
  // Told apart by their answers: the peer's z_des is 7, the namesake's stays 1.
  ASSERT_TRUE(client.set({param("z_des", ParamValue::of_double(7.0))}, t)[0].successful);
  ASSERT_EQ(peer_table.number("z_des"), 7.0);                           // applied before the peer's reply came
  std::this_thread::sleep_for(std::chrono::milliseconds(200));          // the namesake took the request too
  namesake_table.callbacks().set("z_des", ParamValue::of_double(1.0));  // and now answers 1
  for (int i = 0; i < 20; ++i) {
    const auto v = client.get({"z_des"}, t);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0], ParamValue::of_double(7.0)) << "call " << i << " took the namesake's reply";
  }
  // A client told to listen to a participant that has no such node waits for it, and says so.
  ParameterClient lost(test::private_env(), parse_node_name("/test_controller"));
  std::array<std::uint8_t, 16> nobody{};
  nobody.fill(0xab);
  lost.only_from(nobody);
  EXPECT_THROW(lost.get({"z_des"}, kSecond / 2), ParameterCallError);
}

TEST(ParameterServiceTest, MissingNodeIsAClearTimeout) {
  ParameterClient client(test::private_env(), parse_node_name("nobody_here"));
  try {
    client.get({"z_des"}, 300'000'000);
    FAIL() << "expected a timeout";
  } catch (const ParameterCallError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("node /nobody_here not found"), std::string::npos) << what;
    EXPECT_NE(what.find("rq/nobody_here/get_parametersRequest matched by 0 reader(s)"), std::string::npos) << what;
    EXPECT_NE(what.find("ROS_DOMAIN_ID"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace quadcosim::dds
