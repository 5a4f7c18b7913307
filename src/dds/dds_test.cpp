// DDS transport tests on a private domain with localhost-only discovery.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <typeindex>
#include <vector>

#include "dds/arrival_executor.hpp"
#include "dds/dds_test_support.hpp"
#include "dds/dds_transport.hpp"
#include "dds/idl_walk.hpp"
#include "dds/peer_pairing.hpp"
#include "sim/messages.hpp"

namespace quadcosim::dds {
namespace {

// Every field of a message, from its fields() list: FillFields gives each leaf a value of its own
// (so a field written to or read from its neighbour shows), Flatten lists them exactly (doubles in
// hex), so a round trip compares whole messages whatever fields they have.
struct FillFields {
  int next = 1;
  template <class T>
  void field(std::string_view, T& v, msg::FieldNote = {}) {
    put(v);
  }
  template <class F>
  void group(std::string_view, std::string_view, F&& visit) {
    visit(*this);
  }
  template <class T>
  void put(T& v) {
    const int k = next++;
    if constexpr (std::is_same_v<T, bool>) {
      v = k % 2 == 0;
    } else if constexpr (std::is_same_v<T, std::string>) {
      v = std::string(static_cast<std::size_t>(k % 7), 'a' + static_cast<char>(k % 26)) + std::to_string(k);
    } else if constexpr (std::is_floating_point_v<T>) {
      v = k + 1.0 / (k + 2);
    } else if constexpr (std::is_arithmetic_v<T>) {
      v = static_cast<T>(k * 1000003);
    } else if constexpr (requires {
                           v.size();
                           v.resize(2);
                         }) {
      v.resize(2);
      for (auto& e : v) put(e);
    } else if constexpr (requires { v.size(); }) {
      for (auto& e : v) put(e);
    } else {
      T::fields(v, *this);
    }
  }
};

struct Flatten {
  std::vector<std::string> out;
  template <class T>
  void field(std::string_view name, const T& v, msg::FieldNote = {}) {
    put(std::string(name), v);
  }
  template <class F>
  void group(std::string_view, std::string_view, F&& visit) {
    visit(*this);
  }
  template <class T>
  void put(const std::string& name, const T& v) {
    char buf[64];
    if constexpr (std::is_same_v<T, std::string>) {
      out.push_back(name + "='" + v + "'");
    } else if constexpr (std::is_floating_point_v<T>) {
      std::snprintf(buf, sizeof buf, "%a", v);
      out.push_back(name + "=" + buf);
    } else if constexpr (std::is_arithmetic_v<T>) {
      out.push_back(name + "=" + std::to_string(v));
    } else if constexpr (requires { v.size(); }) {
      out.push_back(name + ".size=" + std::to_string(v.size()));
      for (std::size_t i = 0; i < v.size(); ++i) put(name + "[" + std::to_string(i) + "]", v[i]);
    } else {
      Flatten sub;
      T::fields(v, sub);
      for (const std::string& f : sub.out) out.push_back(name + "." + f);
    }
  }
};

template <class T>
std::vector<std::string> flatten(const T& m) {
  Flatten f;
  T::fields(m, f);
  return f.out;
}

// Sends a message with every field its own value from one transport to another and compares what
// arrives, field by field.
template <class T>
void expect_round_trip(const std::string& topic) {
  DdsTransport a(test::private_env()), b(test::private_env());
  std::optional<T> got;
  b.subscribe<T>(topic, [&](const T& m) { got = m; });
  auto pub = a.advertise<T>(topic);
  ASSERT_TRUE(a.spin_until([&] { return a.matched_readers(topic) == 1; }, 5'000'000'000)) << T::kRosType;
  T m;
  FillFields fill;
  T::fields(m, fill);
  pub.publish(m);
  ASSERT_TRUE(b.spin_until([&] { return got.has_value(); }, 5'000'000'000)) << T::kRosType;
  EXPECT_EQ(flatten(*got), flatten(m)) << T::kRosType;
}

TEST(DdsTransportTest, RoundTripsEveryMessageTypeFieldForField) {
  expect_round_trip<msg::PoseStamped>("/t/Pose");
  expect_round_trip<msg::TwistStamped>("/t/Velocity");
  expect_round_trip<msg::Imu>("/t/Imu");
  expect_round_trip<msg::MagneticField>("/t/mag");
  expect_round_trip<msg::FluidPressure>("/t/baro");
  expect_round_trip<msg::NavSatFix>("/t/fix");
  expect_round_trip<msg::Float64MultiArray>("/t/cmd");
  expect_round_trip<msg::Clock>("/t/clock");
  expect_round_trip<msg::ControllerStatus>("/t/status");
  expect_round_trip<msg::PlantStatus>("/t/plant_status");
}

TEST(DdsTransportTest, RoundTripsExtremesAndEmpties) {
  msg::Float64MultiArray empty;  // no dimension, no data
  msg::Float64MultiArray cmd;
  cmd.data = {4830.5, -0.0, 1e-300, std::numeric_limits<double>::infinity()};
  cmd.dim = {{"rotors@5", 4, 4}, {"", 0, 0}};
  msg::Clock clock;
  clock.clock = {2147483647, 999999999};
  DdsTransport a(test::private_env()), b(test::private_env());
  std::vector<msg::Float64MultiArray> cmds;
  std::optional<msg::Clock> clock_in;
  b.subscribe<msg::Float64MultiArray>("/e/cmd", [&](const msg::Float64MultiArray& m) { cmds.push_back(m); });
  b.subscribe<msg::Clock>("/e/clock", [&](const msg::Clock& m) { clock_in = m; });
  auto cmd_pub = a.advertise<msg::Float64MultiArray>("/e/cmd");
  auto clock_pub = a.advertise<msg::Clock>("/e/clock");
  ASSERT_TRUE(a.spin_until([&] { return a.matched_readers("/e/cmd") == 1 && a.matched_readers("/e/clock") == 1; },
                           5'000'000'000));
  cmd_pub.publish(empty);
  cmd_pub.publish(cmd);
  clock_pub.publish(clock);
  ASSERT_TRUE(b.spin_until([&] { return cmds.size() == 2 && clock_in; }, 5'000'000'000));
  EXPECT_TRUE(cmds[0].data.empty());
  EXPECT_TRUE(cmds[0].dim.empty());
  EXPECT_EQ(flatten(cmds[1]), flatten(cmd));
  EXPECT_TRUE(std::signbit(cmds[1].data[1]));
  EXPECT_EQ(clock_in->clock.sec, 2147483647);
  EXPECT_EQ(clock_in->clock.nanosec, 999999999u);
}

// The conversions pair fields() with idlc's instructions and refuse any difference, naming it.
struct Pair {
  static constexpr std::string_view kRosType = "test_msgs/msg/Pair";
  double a = 0;
  std::uint32_t b = 0;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("a", m.a);
    v.field("b", m.b);
  }
};
struct PairOfPairs {
  static constexpr std::string_view kRosType = "test_msgs/msg/PairOfPairs";
  Pair first;
  std::vector<Pair> rest;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("first", m.first);
    v.group("more", "test_msgs/msg/More", [&](auto& g) { g.field("rest", m.rest); });
  }
};

constexpr std::uint32_t kAdr = DDS_OP_ADR;  // as an integer: ORing two enumerations is deprecated

std::string layout_error(const std::function<void()>& check) {
  try {
    check();
  } catch (const std::logic_error& e) {
    return e.what();
  }
  return "";
}

TEST(IdlWalkTest, RefusesAFieldTheIdlTypeDoesNotHaveOrTypesDifferently) {
  dds_topic_descriptor_t d{};
  const std::uint32_t same[] = {kAdr | DDS_OP_TYPE_8BY | DDS_OP_FLAG_FP, 0, kAdr | DDS_OP_TYPE_4BY, 8, DDS_OP_RTS};
  d.m_ops = same;
  EXPECT_EQ(layout_error([&] { idl_walk::check_fields<Pair>(d); }), "");
  const std::uint32_t signed_b[] = {kAdr | DDS_OP_TYPE_8BY | DDS_OP_FLAG_FP, 0,
                                    kAdr | DDS_OP_TYPE_4BY | DDS_OP_FLAG_SGN, 8, DDS_OP_RTS};
  d.m_ops = signed_b;
  EXPECT_NE(layout_error([&] { idl_walk::check_fields<Pair>(d); }).find("test_msgs/msg/Pair field 'b'"),
            std::string::npos);
  const std::uint32_t b_double[] = {kAdr | DDS_OP_TYPE_8BY | DDS_OP_FLAG_FP, 0, kAdr | DDS_OP_TYPE_8BY | DDS_OP_FLAG_FP,
                                    8, DDS_OP_RTS};
  d.m_ops = b_double;
  EXPECT_NE(layout_error([&] { idl_walk::check_fields<Pair>(d); }).find("field 'b'"), std::string::npos);
  const std::uint32_t one[] = {kAdr | DDS_OP_TYPE_8BY | DDS_OP_FLAG_FP, 0, DDS_OP_RTS};
  d.m_ops = one;
  const std::string extra = layout_error([&] { idl_walk::check_fields<Pair>(d); });
  EXPECT_NE(extra.find("field 'b'"), std::string::npos) << extra;
  EXPECT_NE(extra.find("fields() lists a field after the IDL type's last member"), std::string::npos) << extra;
  const std::uint32_t three[] = {
      kAdr | DDS_OP_TYPE_8BY | DDS_OP_FLAG_FP, 0, kAdr | DDS_OP_TYPE_4BY, 8, kAdr | DDS_OP_TYPE_BLN, 12, DDS_OP_RTS};
  d.m_ops = three;
  EXPECT_NE(layout_error([&] { idl_walk::check_fields<Pair>(d); }).find("a member after the last field"),
            std::string::npos);
  // A real pair that differs: Vector3's fields against PoseStamped's members (header first).
  EXPECT_NE(layout_error([&] {
              idl_walk::check_fields<msg::Vector3>(*type_ops(typeid(msg::PoseStamped))->descriptor);
            }).find("geometry_msgs/msg/Vector3 field 'x'"),
            std::string::npos);
}

TEST(IdlWalkTest, WalksNestedStructsAndSequencesOfStructsEvenWhenEmpty) {
  dds_topic_descriptor_t d{};
  // PairOfPairs_ { Pair_ first; More_ more; }; More_ { sequence<Pair_> rest; }; element type wrong (int32 b).
  const std::uint32_t ops[] = {kAdr | DDS_OP_TYPE_EXT,
                               0,
                               (3u << 16u) + 7u,  // 0: first -> Pair_ at 7
                               kAdr | DDS_OP_TYPE_EXT,
                               16,
                               (3u << 16u) + 9u,  // 3: more -> More_ at 12
                               DDS_OP_RTS,        // 6
                               kAdr | DDS_OP_TYPE_8BY | DDS_OP_FLAG_FP,
                               0,  // 7: Pair_
                               kAdr | DDS_OP_TYPE_4BY,
                               8,
                               DDS_OP_RTS,  // 9
                               kAdr | DDS_OP_TYPE_SEQ | DDS_OP_SUBTYPE_STU,
                               0,
                               16,
                               (4u << 16u) + 5u,  // 12: More_.rest -> 17
                               DDS_OP_RTS,        // 16
                               kAdr | DDS_OP_TYPE_8BY | DDS_OP_FLAG_FP,
                               0,  // 17: element Pair_
                               kAdr | DDS_OP_TYPE_4BY | DDS_OP_FLAG_SGN,
                               8,
                               DDS_OP_RTS};
  d.m_ops = ops;
  EXPECT_NE(layout_error([&] { idl_walk::check_fields<PairOfPairs>(d); }).find("field 'more.rest.b'"),
            std::string::npos);
}

// Every message type the transport carries is checked against its idlc type when the table is made.
TEST(IdlWalkTest, EveryMessageTypeMatchesItsIdlcType) {
  for (const std::type_index t : {std::type_index(typeid(msg::PoseStamped)), std::type_index(typeid(msg::TwistStamped)),
                                  std::type_index(typeid(msg::Imu)), std::type_index(typeid(msg::Float64MultiArray)),
                                  std::type_index(typeid(msg::Clock)), std::type_index(typeid(msg::ControllerStatus)),
                                  std::type_index(typeid(msg::PlantStatus))}) {
    EXPECT_NE(type_ops(t), nullptr) << t.name();
  }
}

// Waits (without spinning `t`) until `done()`, up to 5 s.
template <class F>
bool eventually(F done) {
  for (int i = 0; i < 5000 && !done(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return done();
}

msg::Clock clock_at(std::int64_t ns) {
  msg::Clock c;
  c.clock = msg::Time::from_ns(ns);
  return c;
}

// Two transports on one domain: `a` publishes /t/in, `b` subscribes (matched before returning).
struct ArrivalRig {
  DdsTransport a{test::private_env()}, b{test::private_env()};
  sim::Publisher<msg::Clock> in;
  std::vector<std::int64_t> got;
  std::vector<std::thread::id> threads;
  std::atomic<int> count{0};

  explicit ArrivalRig(std::function<void(const msg::Clock&)> extra = {}) {
    b.subscribe<msg::Clock>("/t/in", [this, extra](const msg::Clock& m) {
      got.push_back(m.clock.to_ns());
      threads.push_back(std::this_thread::get_id());
      if (extra) extra(m);
      ++count;
    });
    in = a.advertise<msg::Clock>("/t/in");
  }
  bool matched() {
    return b.spin_until([&] { return b.matched_writers("/t/in") == 1; }, 5'000'000'000) &&
           a.spin_until([&] { return a.matched_readers("/t/in") == 1; }, 5'000'000'000);
  }
};

TEST(DdsTransportTest, OnArrivalOnlyTheOwningThreadMayWaitAndTheTransportItselfNotSpin) {
  ArrivalRig rig;
  ArrivalExecutor arrival(rig.b);
  std::string error;
  std::thread other([&] {
    try {
      arrival.wait(0);
    } catch (const std::logic_error& e) {
      error = e.what();
    }
  });
  other.join();
  EXPECT_NE(error.find("ArrivalExecutor::wait"), std::string::npos) << error;
  EXPECT_EQ(arrival.wait(0), 0);                       // the owner may
  EXPECT_THROW(rig.b.spin_once(0), std::logic_error);  // not past the executor
  EXPECT_THROW(ArrivalExecutor second(rig.b), std::logic_error);
}

// In one process Cyclone delivers to a local reader on the publishing thread, so a publisher on a
// thread of its own stands for the receive thread of a remote one.
TEST(DdsTransportTest, OnArrivalDeliversInOrderOnlyWhileTheOwnerWaits) {
  ArrivalRig rig;
  ASSERT_TRUE(rig.matched());
  auto arrival = std::make_unique<ArrivalExecutor>(rig.b);
  std::thread first([&] {
    for (int i = 1; i <= 50; ++i) rig.in.publish(clock_at(i));
  });
  int counted = 0;  // what wait reports as delivered since its last call
  const auto t0 = std::chrono::steady_clock::now();
  while (rig.count < 50 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5)) {
    counted += arrival->wait(10'000'000);
  }
  first.join();
  counted += arrival->wait(0);
  EXPECT_EQ(counted, 50);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(rig.got[static_cast<std::size_t>(i)], i + 1);
  // Between waits the owner holds the deliveries: the other thread's sample waits (taken out of
  // the reader, so none of those that arrive meanwhile is lost to the reader's history depth).
  std::thread second([&] {
    for (int i = 51; i <= 90; ++i) rig.in.publish(clock_at(i));
  });
  second.join();
  EXPECT_EQ(rig.count, 50);
  ASSERT_TRUE(arrival->wait_until([&] { return rig.count == 90; }, 5'000'000'000)) << rig.count;
  for (int i = 50; i < 90; ++i) EXPECT_EQ(rig.got[static_cast<std::size_t>(i)], i + 1);

  arrival.reset();  // back to delivery by spin_once, on the caller's thread
  std::thread third([&] { rig.in.publish(clock_at(91)); });
  third.join();
  EXPECT_EQ(rig.count, 90);
  ASSERT_TRUE(rig.b.spin_until([&] { return rig.count == 91; }, 5'000'000'000));
  EXPECT_EQ(rig.threads.back(), std::this_thread::get_id());
  EXPECT_EQ(rig.got.back(), 91);
}

TEST(DdsTransportTest, OnArrivalADeliveryMayPublishToItsOwnTransport) {
  // b answers every /t/in on /t/echo, which b itself also reads: a delivery inside a delivery.
  std::atomic<int> echoes{0};
  sim::Publisher<msg::Clock> echo;
  ArrivalRig rig([&](const msg::Clock& m) { echo.publish(m); });
  echo = rig.b.advertise<msg::Clock>("/t/echo");
  rig.b.subscribe<msg::Clock>("/t/echo", [&](const msg::Clock&) { ++echoes; });
  ASSERT_TRUE(rig.matched());
  ASSERT_TRUE(rig.b.spin_until([&] { return rig.b.matched_readers("/t/echo") >= 1; }, 5'000'000'000));
  ArrivalExecutor arrival(rig.b);
  std::thread publisher([&] {
    for (int i = 1; i <= 20; ++i) rig.in.publish(clock_at(i));
  });
  EXPECT_TRUE(arrival.wait_until([&] { return echoes == 20; }, 5'000'000'000)) << echoes << " echoes";
  publisher.join();
}

// A reader that another participant and the owner itself both write (a recorder of a topic a
// stranger publishes too): the other writer's delivery comes while the owner works and holds the
// lock, then the owner writes to that reader. Cyclone runs one listener of a reader at a time, so a
// delivery that waited inside the listener for the owner's lock would hold the owner's own write for
// ever (the owner held it in turn). The delivery is noted instead and comes first, in order.
TEST(DdsTransportTest, OnArrivalAnotherWritersDeliveryNeverHoldsTheOwnersOwnWrite) {
  ArrivalRig rig;
  const auto own = rig.b.advertise<msg::Clock>("/t/in");
  ASSERT_TRUE(rig.b.spin_until([&] { return rig.b.matched_writers("/t/in") == 2; }, 5'000'000'000));
  ASSERT_TRUE(rig.a.spin_until([&] { return rig.a.matched_readers("/t/in") == 1; }, 5'000'000'000));
  std::atomic<bool> finished{false};
  std::thread watchdog([&] {  // a deadlock cannot be undone: end the test process with the reason
    for (int i = 0; i < 200 && !finished; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!finished) {
      std::fprintf(stderr, "deadlock: the owner's write waited 20 s for another writer's delivery\n");
      std::_Exit(1);
    }
  });
  {
    ArrivalExecutor arrival(rig.b);  // the owner (this thread) holds the lock from here
    std::atomic<bool> stranger_done{false};
    std::thread stranger([&] {
      rig.in.publish(clock_at(1));
      stranger_done = true;
    });
    // The stranger's delivery is not held: it returns without the lock, its sample left for later.
    for (int i = 0; i < 100 && !stranger_done; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_TRUE(stranger_done);
    EXPECT_EQ(rig.count, 0);
    own.publish(clock_at(2));  // the owner's own write to the same reader
    stranger.join();
    EXPECT_TRUE(arrival.wait_until([&] { return rig.count == 2; }, 5'000'000'000));
    EXPECT_EQ(rig.got, (std::vector<std::int64_t>{1, 2}));
    // Later ones from both writers, interleaved while the owner works and waits: none lost, each
    // writer's in its order.
    std::thread more([&] {
      for (int i = 10; i < 60; ++i) rig.in.publish(clock_at(i));
    });
    for (int i = 100; i < 150; ++i) {
      own.publish(clock_at(i));
      if (i % 10 == 0) arrival.wait(1'000'000);
    }
    more.join();
    EXPECT_TRUE(arrival.wait_until([&] { return rig.count == 102; }, 5'000'000'000)) << rig.count;
  }
  finished = true;
  watchdog.join();
  std::vector<std::int64_t> from_stranger, from_owner;
  for (const auto t : rig.got) (t == 2 || t >= 100 ? from_owner : from_stranger).push_back(t);
  ASSERT_EQ(from_stranger.size(), 51u);
  ASSERT_EQ(from_owner.size(), 51u);
  EXPECT_TRUE(std::is_sorted(from_stranger.begin(), from_stranger.end()));
  EXPECT_TRUE(std::is_sorted(from_owner.begin(), from_owner.end()));
}

TEST(DdsTransportTest, OnArrivalAFailedDeliveryWakesTheWaitAndIsRethrown) {
  ArrivalRig rig([](const msg::Clock& m) {
    if (m.clock.to_ns() == 3) throw std::invalid_argument("sample 3 refused");
  });
  ASSERT_TRUE(rig.matched());
  ArrivalExecutor arrival(rig.b);
  for (int i = 1; i <= 5; ++i) rig.in.publish(clock_at(i));
  const auto t0 = std::chrono::steady_clock::now();
  try {
    for (int i = 0; i < 100; ++i) arrival.wait(10'000'000'000);
    FAIL() << "not rethrown";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "sample 3 refused");
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));  // woken, not timed out
  EXPECT_EQ(rig.count, 2);                                                    // 1 and 2; nothing after the failure
}

// Samples already in the reader when the executor is made are delivered by its constructor; one
// that throws there comes out of the first wait(), and the transport is left as on any executor.
TEST(DdsTransportTest, OnArrivalAPendingDeliveryThatThrowsIsRethrownByTheFirstWait) {
  ArrivalRig rig([](const msg::Clock& m) {
    if (m.clock.to_ns() == 2) throw std::invalid_argument("pending sample 2 refused");
  });
  ASSERT_TRUE(rig.matched());
  for (int i = 1; i <= 3; ++i) rig.in.publish(clock_at(i));  // in b's reader, undelivered
  EXPECT_EQ(rig.count, 0);
  {
    std::unique_ptr<ArrivalExecutor> arrival;
    ASSERT_NO_THROW(arrival = std::make_unique<ArrivalExecutor>(rig.b));
    EXPECT_EQ(rig.count, 1);  // sample 1; 2 threw, 3 is dropped
    const auto t0 = std::chrono::steady_clock::now();
    try {
      arrival->wait(10'000'000'000);
      FAIL() << "not rethrown";
    } catch (const std::invalid_argument& e) {
      EXPECT_STREQ(e.what(), "pending sample 2 refused");
    }
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));  // woken, not timed out
    EXPECT_EQ(arrival->wait(0), 0);                                             // rethrown once
  }
  // The executor's end returned the transport to spin_once: a later sample reaches b there.
  std::thread later([&] { rig.in.publish(clock_at(4)); });
  later.join();
  ASSERT_TRUE(rig.b.spin_until([&] { return rig.count == 2; }, 5'000'000'000));
  EXPECT_EQ(rig.got, (std::vector<std::int64_t>{1, 2, 4}));  // 2 reached the callback, which threw; 3 did not
}

TEST(DdsTransportTest, OnArrivalTheHookRunsAfterEachDeliveryAndTrueEndsTheWait) {
  ArrivalRig rig;
  ASSERT_TRUE(rig.matched());
  ArrivalExecutor arrival(rig.b);
  int runs = 0;
  arrival.after_each([&] {
    ++runs;
    return !rig.got.empty() && rig.got.back() == 7;
  });
  std::thread publisher([&] {
    for (int i = 1; i <= 7; ++i) rig.in.publish(clock_at(i));
  });
  const auto t0 = std::chrono::steady_clock::now();
  // Long waits return once sample 7 is in (every earlier one delivered before it).
  while (rig.count < 7 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5)) {
    arrival.wait(30'000'000'000);
  }
  publisher.join();
  EXPECT_EQ(rig.count, 7);
  EXPECT_EQ(runs, 7);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  // wait_until runs the hook too, beside its own condition.
  std::thread more([&] { rig.in.publish(clock_at(8)); });
  EXPECT_TRUE(arrival.wait_until([&] { return rig.count == 8; }, 5'000'000'000));
  more.join();
  EXPECT_EQ(runs, 8);
}

TEST(PeerFilterTest, TakesOnlyThePairedWritersSamplesByTokenOrByParticipant) {
  DdsTransport peer(test::private_env()), stranger(test::private_env()), me(test::private_env());
  peer.set_user_data_keys(std::string(kPairTokenKey) + "=run-1;");  // before its endpoints exist
  stranger.set_user_data_keys(std::string(kPairTokenKey) + "=run-0;");
  PeerFilter filter(me);
  std::vector<std::int64_t> accepted, refused;
  std::vector<sim::SenderId> senders;
  me.subscribe_with_sender<msg::Clock>("/t/in", [&](const msg::Clock& m, sim::SenderId s) {
    (filter.accepts("/t/in", s) ? accepted : refused).push_back(m.clock.to_ns());
    senders.push_back(s);
  });
  auto from_peer = peer.advertise<msg::Clock>("/t/in");
  auto from_stranger = stranger.advertise<msg::Clock>("/t/in");
  ASSERT_TRUE(me.spin_until([&] { return me.matched_writers("/t/in") == 2; }, 5'000'000'000));
  ASSERT_TRUE(peer.spin_until([&] { return peer.matched_readers("/t/in") == 1; }, 5'000'000'000));
  ASSERT_TRUE(stranger.spin_until([&] { return stranger.matched_readers("/t/in") == 1; }, 5'000'000'000));
  auto send_both = [&](std::int64_t base) {
    accepted.clear();
    refused.clear();
    for (int i = 1; i <= 3; ++i) from_peer.publish(clock_at(base + i));
    for (int i = 1; i <= 2; ++i) from_stranger.publish(clock_at(base + 100 + i));
    ASSERT_TRUE(me.spin_until([&] { return accepted.size() + refused.size() == 5; }, 5'000'000'000));
    std::sort(accepted.begin(), accepted.end());
    std::sort(refused.begin(), refused.end());
  };

  send_both(0);  // unpaired: everyone's samples are taken
  EXPECT_FALSE(filter.paired());
  EXPECT_EQ(accepted, (std::vector<std::int64_t>{1, 2, 3, 101, 102}));

  filter.pair_by_token("run-1");
  send_both(1000);
  EXPECT_EQ(accepted, (std::vector<std::int64_t>{1001, 1002, 1003}));
  EXPECT_EQ(refused, (std::vector<std::int64_t>{1101, 1102}));

  // By participant: the stranger's, read from its samples' sender through discovery.
  const auto info = me.sender_info("/t/in", senders.back());
  ASSERT_TRUE(info.has_value());
  EXPECT_EQ(info->pair_token, "run-0");
  filter.pair_by_participant(info->participant);
  send_both(2000);
  EXPECT_EQ(accepted, (std::vector<std::int64_t>{2101, 2102}));
  EXPECT_EQ(refused, (std::vector<std::int64_t>{2001, 2002, 2003}));
}

TEST(PeerFilterTest, TokensAreFreshAndTheEnvironmentsIsChecked) {
  const std::string a = new_pair_token(), b = new_pair_token();
  EXPECT_EQ(a.size(), 16u);
  EXPECT_NE(a, b);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos) << a;
  ::setenv(kPairTokenEnv, "ok_token-1", 1);
  EXPECT_EQ(pair_token_from_environment(), "ok_token-1");
  for (const char* bad : {"has;semicolon", "a=b", "", "with space"}) {
    ::setenv(kPairTokenEnv, bad, 1);
    EXPECT_THROW(pair_token_from_environment(), std::invalid_argument) << "'" << bad << "'";
  }
  ::setenv(kPairTokenEnv, std::string(65, 'x').c_str(), 1);
  EXPECT_THROW(pair_token_from_environment(), std::invalid_argument);
  ::unsetenv(kPairTokenEnv);
  EXPECT_EQ(pair_token_from_environment(), "");
}

TEST(DdsTransportTest, TopicAndTypeNamesFollowRos2) {
  EXPECT_EQ(dds_topic_name("/drone/Pose"), "rt/drone/Pose");
  EXPECT_STREQ(type_ops(typeid(msg::PoseStamped))->descriptor->m_typename, "geometry_msgs::msg::dds_::PoseStamped_");
  EXPECT_STREQ(type_ops(typeid(msg::Imu))->descriptor->m_typename, "sensor_msgs::msg::dds_::Imu_");
  EXPECT_STREQ(type_ops(typeid(msg::MagneticField))->descriptor->m_typename, "sensor_msgs::msg::dds_::MagneticField_");
  EXPECT_STREQ(type_ops(typeid(msg::FluidPressure))->descriptor->m_typename, "sensor_msgs::msg::dds_::FluidPressure_");
  EXPECT_STREQ(type_ops(typeid(msg::NavSatFix))->descriptor->m_typename, "sensor_msgs::msg::dds_::NavSatFix_");
  EXPECT_STREQ(type_ops(typeid(msg::Float64MultiArray))->descriptor->m_typename,
               "std_msgs::msg::dds_::Float64MultiArray_");
  EXPECT_STREQ(type_ops(typeid(msg::Clock))->descriptor->m_typename, "rosgraph_msgs::msg::dds_::Clock_");
}

TEST(RosEnvironmentTest, ReadsDomainAndRange) {
  setenv("ROS_DOMAIN_ID", "0x10", 1);
  setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST", 1);
  unsetenv("ROS_LOCALHOST_ONLY");
  setenv("ROS_STATIC_PEERS", "10.0.0.2;host.example", 1);
  const RosEnvironment e = read_ros_environment();
  EXPECT_EQ(e.domain_id, 16u);
  EXPECT_EQ(e.range, DiscoveryRange::kLocalhost);
  const std::string xml = cyclone_config(e);
  EXPECT_NE(xml.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos);
  EXPECT_NE(xml.find("<Peer address=\"localhost\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<Peer address=\"10.0.0.2\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<Peer address=\"host.example\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"), std::string::npos);

  setenv("ROS_DOMAIN_ID", "500", 1);
  EXPECT_THROW(read_ros_environment(), DdsError);
  setenv("ROS_DOMAIN_ID", "12abc", 1);
  EXPECT_THROW(read_ros_environment(), DdsError);
  setenv("ROS_DOMAIN_ID", "", 1);
  setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "NEARBY", 1);
  EXPECT_THROW(read_ros_environment(), DdsError);
  unsetenv("ROS_AUTOMATIC_DISCOVERY_RANGE");
  setenv("ROS_LOCALHOST_ONLY", "1", 1);
  EXPECT_EQ(read_ros_environment().range, DiscoveryRange::kLocalhost);
  EXPECT_EQ(read_ros_environment().domain_id, 0u);
  unsetenv("ROS_LOCALHOST_ONLY");
  unsetenv("ROS_STATIC_PEERS");
  unsetenv("ROS_DOMAIN_ID");
}

}  // namespace
}  // namespace quadcosim::dds

#include "dds/node_announcer.hpp"
#include "rmw_dds_common.h"

namespace quadcosim::dds {
namespace {

TEST(NodeAnnouncerTest, PublishesTheNodeWithItsEndpointGids) {
  DdsTransport node(test::private_env());
  auto pub = node.advertise<msg::PoseStamped>("/n/Pose");
  node.subscribe<msg::Clock>("/clock_n", [](const msg::Clock&) {});
  NodeAnnouncer announcer(node.participant().handle(), "quadrotor_plant");
  announcer.announce();
  EXPECT_EQ(announcer.writers(), 1u);
  EXPECT_EQ(announcer.readers(), 1u);

  // A late-joining reader of ros_discovery_info (transient local) still gets it.
  Participant other(test::private_env());
  const dds_entity_t topic = dds_create_topic(other.handle(), &rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc,
                                              "ros_discovery_info", nullptr, nullptr);
  ASSERT_GT(topic, 0);
  dds_qos_t* qos = ros_qos(100, true);
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  const dds_entity_t reader = dds_create_reader(other.handle(), topic, qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(reader, 0);
  dds_guid_t participant_guid;
  ASSERT_EQ(dds_get_guid(node.participant().handle(), &participant_guid), DDS_RETCODE_OK);

  bool found = false;
  for (int attempt = 0; attempt < 100 && !found; ++attempt) {
    const dds_entity_t ws = dds_create_waitset(other.handle());
    const dds_entity_t rc = dds_create_readcondition(reader, DDS_ANY_STATE);
    dds_waitset_attach(ws, rc, 0);
    dds_waitset_wait(ws, nullptr, 0, DDS_MSECS(100));
    void* samples[8] = {nullptr};
    dds_sample_info_t infos[8];
    const dds_return_t n = dds_take(reader, samples, infos, 8, 8);
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto* info = static_cast<const rmw_dds_common_msg_dds__ParticipantEntitiesInfo_*>(samples[i]);
      if (std::memcmp(info->gid.data, participant_guid.v, 16) != 0) continue;
      ASSERT_EQ(info->node_entities_info_seq._length, 1u);
      const auto& n0 = info->node_entities_info_seq._buffer[0];
      EXPECT_STREQ(n0.node_name, "quadrotor_plant");
      EXPECT_STREQ(n0.node_namespace, "/");
      EXPECT_EQ(n0.reader_gid_seq._length, 1u);
      EXPECT_EQ(n0.writer_gid_seq._length, 1u);
      found = true;
    }
    if (n > 0) dds_return_loan(reader, samples, n);
    dds_delete(ws);
  }
  EXPECT_TRUE(found);
}

TEST(ParticipantTest, UserDataSaysEnclave) {
  Participant p(test::private_env());
  dds_qos_t* qos = dds_create_qos();
  ASSERT_EQ(dds_get_qos(p.handle(), qos), DDS_RETCODE_OK);
  void* data = nullptr;
  size_t size = 0;
  ASSERT_TRUE(dds_qget_userdata(qos, &data, &size));
  EXPECT_EQ(std::string(static_cast<char*>(data), size), "enclave=/;");
  dds_free(data);
  dds_delete_qos(qos);
}

}  // namespace
}  // namespace quadcosim::dds

#include "dds/graph.hpp"
#include "dds/topic_tools.hpp"

namespace quadcosim::dds {
namespace {

TEST(GraphTest, DemanglesRosTypesAsRmwCyclonedds) {
  EXPECT_EQ(demangle_ros_type("geometry_msgs::msg::dds_::PoseStamped_"), "geometry_msgs/msg/PoseStamped");
  EXPECT_EQ(demangle_ros_type("sensor_msgs::msg::dds_::Imu_"), "sensor_msgs/msg/Imu");
  EXPECT_EQ(demangle_ros_type("rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"),
            "rmw_dds_common/msg/ParticipantEntitiesInfo");
  EXPECT_EQ(demangle_ros_type("rcl_interfaces::srv::dds_::SetParameters_Request_"),
            "rcl_interfaces/srv/SetParameters_Request");
  // Not mangled ROS types: unchanged.
  EXPECT_EQ(demangle_ros_type("HelloWorldData::Msg"), "HelloWorldData::Msg");
  EXPECT_EQ(demangle_ros_type("pkg::msg::dds_::Name"), "pkg::msg::dds_::Name");
  EXPECT_EQ(demangle_ros_type(""), "");
  // Every type quadcosim writes demangles to its ROS name.
  EXPECT_EQ(demangle_ros_type(type_ops(typeid(msg::ControllerStatus))->descriptor->m_typename),
            msg::ControllerStatus::kRosType);
  EXPECT_EQ(demangle_ros_type(type_ops(typeid(msg::Float64MultiArray))->descriptor->m_typename),
            msg::Float64MultiArray::kRosType);
}

TEST(GraphTest, OnlyRtTopicsAreRosTopics) {
  EXPECT_EQ(ros_topic_name("rt/drone/Pose"), "/drone/Pose");
  EXPECT_EQ(ros_topic_name("rt/clock"), "/clock");
  EXPECT_EQ(ros_topic_name("ros_discovery_info"), std::nullopt);
  EXPECT_EQ(ros_topic_name("rq/attitude_controller/set_parametersRequest"), std::nullopt);
  EXPECT_EQ(ros_topic_name("rt/"), std::nullopt);
  EXPECT_EQ(ros_topic_name("rtx/a"), std::nullopt);
  EXPECT_TRUE(is_hidden_topic("/_secret"));
  EXPECT_TRUE(is_hidden_topic("/drone/_debug/x"));
  EXPECT_FALSE(is_hidden_topic("/drone/motor_commands"));
}

TEST(GraphTest, ListsTopicsSortedUniqueWithTypes) {
  const std::vector<Endpoint> endpoints = {
      {"rt/drone/Pose", "geometry_msgs::msg::dds_::PoseStamped_", true, true, ""},
      {"rt/clock", "rosgraph_msgs::msg::dds_::Clock_", true, false, ""},
      {"ros_discovery_info", "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_", true, true, ""},
      {"rt/drone/Pose", "geometry_msgs::msg::dds_::PoseStamped_", false, true, ""},
      {"rt/drone/Imu", "sensor_msgs::msg::dds_::Imu_", true, true, ""},
      {"rt/drone/_internal", "std_msgs::msg::dds_::Float64MultiArray_", true, true, ""},
      {"rt/mixed", "b::msg::dds_::B_", true, true, ""},
      {"rt/mixed", "a::msg::dds_::A_", false, true, ""},
      {"rq/x/get_parametersRequest", "rcl_interfaces::srv::dds_::GetParameters_Request_", true, true, ""},
  };
  const auto topics = ros_topics(endpoints);
  ASSERT_EQ(topics.size(), 5u);
  EXPECT_EQ(topics[0].name, "/clock");
  EXPECT_EQ(topics[0].best_effort_publishers, 1);
  EXPECT_EQ(topics[2].name, "/drone/Pose");
  EXPECT_EQ(topics[2].publishers, 1);
  EXPECT_EQ(topics[2].subscribers, 1);
  EXPECT_EQ(format_topic_list(topics, false), "/clock\n/drone/Imu\n/drone/Pose\n/mixed\n");
  EXPECT_EQ(format_topic_list(topics, true),
            "/clock [rosgraph_msgs/msg/Clock]\n"
            "/drone/Imu [sensor_msgs/msg/Imu]\n"
            "/drone/Pose [geometry_msgs/msg/PoseStamped]\n"
            "/mixed [a/msg/A, b/msg/B]\n");
  EXPECT_EQ(format_topic_list(topics, false, true), "/clock\n/drone/Imu\n/drone/Pose\n/drone/_internal\n/mixed\n");
  EXPECT_EQ(format_topic_list({}, true), "");
}

TEST(GraphTest, FindsTheNodeBehindAPublisherByItsParticipantsParameterServices) {
  auto ep = [](std::string topic, bool writer, std::uint8_t participant) {
    Endpoint e{std::move(topic), "t", writer, true, ""};
    e.participant.fill(participant);
    return e;
  };
  std::vector<Endpoint> es = {
      ep("rt/drone/motor_commands", true, 1),
      ep("rq/attitude_controller/get_parametersRequest", false, 1),
      ep("rq/attitude_controller/set_parametersRequest", false, 1),
      ep("rr/attitude_controller/get_parametersReply", true, 1),
      // Another process's node, and a client (a writer of requests) in the publisher's process.
      ep("rq/quadrotor_plant/get_parametersRequest", false, 2),
      ep("rq/other/get_parametersRequest", true, 1),
      ep("rt/drone/motor_commands", false, 2),
  };
  EXPECT_EQ(parameter_nodes_writing(es, "/drone/motor_commands"), std::vector<std::string>{"/attitude_controller"});
  EXPECT_TRUE(parameter_nodes_writing(es, "/uav1/motor_commands").empty());
  // A process with two nodes (a namespaced one too): both, sorted.
  es.push_back(ep("rq/uav1/helper/get_parametersRequest", false, 1));
  EXPECT_EQ(parameter_nodes_writing(es, "/drone/motor_commands"),
            (std::vector<std::string>{"/attitude_controller", "/uav1/helper"}));
  // A malformed service topic is not a node.
  EXPECT_TRUE(parameter_nodes_writing({ep("rt/x", true, 3), ep("rq//get_parametersRequest", false, 3)}, "/x").empty());
}

TEST(GraphTest, DiscoversAnotherParticipantsEndpoints) {
  DdsTransport node(test::private_env());
  auto pub = node.advertise<msg::PoseStamped>("/g/Pose");
  node.set_qos("/g/Imu", QosProfile::sensor_data());
  node.subscribe<msg::Imu>("/g/Imu", [](const msg::Imu&) {});
  Participant tool(test::private_env());
  auto has_both = [](const std::vector<Endpoint>& es) {
    int n = 0;
    for (const auto& e : es) n += (e.dds_topic == "rt/g/Pose" && e.writer) + (e.dds_topic == "rt/g/Imu" && !e.writer);
    return n == 2;
  };
  const auto es = discover_endpoints(tool.handle(), DDS_SECS(10), has_both);
  ASSERT_TRUE(has_both(es));
  for (const auto& e : es) {
    if (e.dds_topic == "rt/g/Pose") {
      EXPECT_EQ(e.dds_type, "geometry_msgs::msg::dds_::PoseStamped_");
      EXPECT_TRUE(e.reliable);
    }
    if (e.dds_topic == "rt/g/Imu") {
      EXPECT_FALSE(e.reliable);
    }
  }
  // The participant's own endpoints are not listed.
  for (const auto& e : discover_endpoints(node.participant().handle(), DDS_MSECS(200))) {
    EXPECT_NE(e.dds_topic, "rt/g/Pose");
  }
  // Without `done`, it waits out the whole time.
  const auto t0 = dds_time();
  discover_endpoints(tool.handle(), DDS_MSECS(300));
  EXPECT_GE(dds_time() - t0, DDS_MSECS(290));
}

TEST(TopicToolsTest, FloatsAsPythonReprThroughPyYaml) {
  EXPECT_EQ(yaml_float(0.0), "0.0");
  EXPECT_EQ(yaml_float(-0.0), "-0.0");
  EXPECT_EQ(yaml_float(1.0), "1.0");
  EXPECT_EQ(yaml_float(0.1), "0.1");
  EXPECT_EQ(yaml_float(-9.81), "-9.81");
  EXPECT_EQ(yaml_float(0.0001), "0.0001");
  EXPECT_EQ(yaml_float(0.00001), "1.0e-05");
  EXPECT_EQ(yaml_float(1.5e-7), "1.5e-07");
  EXPECT_EQ(yaml_float(1e-300), "1.0e-300");
  EXPECT_EQ(yaml_float(1e15), "1000000000000000.0");
  EXPECT_EQ(yaml_float(1e16), "1.0e+16");
  EXPECT_EQ(yaml_float(123456.789), "123456.789");
  EXPECT_EQ(yaml_float(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(yaml_float(std::nan("")), ".nan");
  EXPECT_EQ(yaml_float(INFINITY), ".inf");
  EXPECT_EQ(yaml_float(-INFINITY), "-.inf");
}

TEST(TopicToolsTest, StringsQuotedOnlyWhenNeeded) {
  EXPECT_EQ(yaml_string("world"), "world");
  EXPECT_EQ(yaml_string("rotors@100000000"), "rotors@100000000");
  EXPECT_EQ(yaml_string("it's"), "it's");
  EXPECT_EQ(yaml_string(""), "''");
  EXPECT_EQ(yaml_string("123"), "'123'");
  EXPECT_EQ(yaml_string("1.5"), "'1.5'");
  EXPECT_EQ(yaml_string("true"), "'true'");
  EXPECT_EQ(yaml_string("null"), "'null'");
  EXPECT_EQ(yaml_string("a: b"), "'a: b'");
  EXPECT_EQ(yaml_string("'q'"), "'''q'''");
  EXPECT_EQ(yaml_string("@x"), "'@x'");
  EXPECT_EQ(yaml_string("a\nb"), "\"a\\nb\"");
}

TEST(TopicToolsTest, MessagesAsRos2TopicEcho) {
  msg::PoseStamped p;
  p.header.stamp = {12, 345};
  p.header.frame_id = "world";
  p.position = {1.5, 0.0, -2.0};
  EXPECT_EQ(to_yaml(p),
            "header:\n"
            "  stamp:\n"
            "    sec: 12\n"
            "    nanosec: 345\n"
            "  frame_id: world\n"
            "pose:\n"
            "  position:\n"
            "    x: 1.5\n"
            "    y: 0.0\n"
            "    z: -2.0\n"
            "  orientation:\n"
            "    x: 0.0\n"
            "    y: 0.0\n"
            "    z: 0.0\n"
            "    w: 1.0\n");

  msg::Float64MultiArray c;
  c.data = {400.0, 400.5};
  c.dim = {{"rotors@10000000", 4, 4}};
  EXPECT_EQ(to_yaml(c),
            "layout:\n"
            "  dim:\n"
            "  - label: rotors@10000000\n"
            "    size: 4\n"
            "    stride: 4\n"
            "  data_offset: 0\n"
            "data:\n"
            "- 400.0\n"
            "- 400.5\n");
  EXPECT_EQ(to_yaml(msg::Float64MultiArray{}), "layout:\n  dim: []\n  data_offset: 0\ndata: []\n");

  msg::Clock k;
  k.clock = {3, 10000000};
  EXPECT_EQ(to_yaml(k), "clock:\n  sec: 3\n  nanosec: 10000000\n");

  msg::Imu imu;
  imu.header.frame_id = "base_link";
  const std::string y = to_yaml(imu);
  EXPECT_NE(y.find("  frame_id: base_link\norientation:\n  x: 0.0\n"), std::string::npos);
  EXPECT_NE(y.find("orientation_covariance:\n- 0.0\n- 0.0\n"), std::string::npos);
  EXPECT_NE(y.find("\nlinear_acceleration_covariance:\n- 0.0\n"), std::string::npos);

  msg::ControllerStatus s;
  s.mode = "attitude";
  s.rotor_saturated[1] = true;
  const std::string sy = to_yaml(s);
  EXPECT_NE(sy.find("mode: attitude\nsetpoint:\n- 0.0\n"), std::string::npos);
  EXPECT_NE(sy.find("rotor_saturated:\n- false\n- true\n- false\n- false\n- false\n- false\n- false\n- false\n"
                    "tilt_saturated: false\nsafety: false\n"),
            std::string::npos);
  EXPECT_NE(to_yaml(msg::TwistStamped{}).find("twist:\n  linear:\n    x: 0.0\n"), std::string::npos);
}

// Every message type with a distinct value in every field, against the text `ros2 topic echo` prints for
// it, written out by hand from the .msg definitions (field order, nesting, PyYAML's block style).
TEST(TopicToolsTest, EveryMessageTypeAsRos2TopicEcho) {
  msg::PoseStamped p;
  p.header.stamp = {1700000000, 999999999};
  p.header.frame_id = "map";
  p.position = {1.25, -0.5, 1e-05};
  p.orientation = {0.1, -0.2, 0.3, 0.9};
  EXPECT_EQ(to_yaml(p),
            "header:\n"
            "  stamp:\n"
            "    sec: 1700000000\n"
            "    nanosec: 999999999\n"
            "  frame_id: map\n"
            "pose:\n"
            "  position:\n"
            "    x: 1.25\n"
            "    y: -0.5\n"
            "    z: 1.0e-05\n"
            "  orientation:\n"
            "    x: 0.1\n"
            "    y: -0.2\n"
            "    z: 0.3\n"
            "    w: 0.9\n");

  msg::TwistStamped t;
  t.header.stamp = {-1, 5};
  t.linear = {2.0, 3.5, -4.25};
  t.angular = {1e16, -0.0, 123456.789};
  EXPECT_EQ(to_yaml(t),
            "header:\n"
            "  stamp:\n"
            "    sec: -1\n"
            "    nanosec: 5\n"
            "  frame_id: ''\n"
            "twist:\n"
            "  linear:\n"
            "    x: 2.0\n"
            "    y: 3.5\n"
            "    z: -4.25\n"
            "  angular:\n"
            "    x: 1.0e+16\n"
            "    y: -0.0\n"
            "    z: 123456.789\n");

  msg::Imu imu;
  imu.header.stamp = {7, 8};
  imu.header.frame_id = "imu_link";
  imu.orientation = {0.0, 0.0, 0.6, 0.8};
  imu.orientation_covariance = {-1, 0, 0, 0, 0, 0, 0, 0, 0};
  imu.angular_velocity = {0.01, -0.02, 0.03};
  imu.angular_velocity_covariance = {1e-4, 0, 0, 0, 2e-4, 0, 0, 0, 3e-4};
  imu.linear_acceleration = {0.125, -0.25, 9.81};
  imu.linear_acceleration_covariance = {0.5, std::nan(""), INFINITY, -INFINITY, 1.5, 0, 0, 0, 2.5};
  EXPECT_EQ(to_yaml(imu),
            "header:\n"
            "  stamp:\n"
            "    sec: 7\n"
            "    nanosec: 8\n"
            "  frame_id: imu_link\n"
            "orientation:\n"
            "  x: 0.0\n"
            "  y: 0.0\n"
            "  z: 0.6\n"
            "  w: 0.8\n"
            "orientation_covariance:\n"
            "- -1.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n"
            "angular_velocity:\n"
            "  x: 0.01\n"
            "  y: -0.02\n"
            "  z: 0.03\n"
            "angular_velocity_covariance:\n"
            "- 0.0001\n- 0.0\n- 0.0\n- 0.0\n- 0.0002\n- 0.0\n- 0.0\n- 0.0\n- 0.0003\n"
            "linear_acceleration:\n"
            "  x: 0.125\n"
            "  y: -0.25\n"
            "  z: 9.81\n"
            "linear_acceleration_covariance:\n"
            "- 0.5\n- .nan\n- .inf\n- -.inf\n- 1.5\n- 0.0\n- 0.0\n- 0.0\n- 2.5\n");

  msg::Float64MultiArray a;
  a.dim = {{"rotors@10000000", 4, 4}, {"true", 2, 1}};
  a.data_offset = 3;
  a.data = {400.0, -0.001, 1.5e-07};
  EXPECT_EQ(to_yaml(a),
            "layout:\n"
            "  dim:\n"
            "  - label: rotors@10000000\n"
            "    size: 4\n"
            "    stride: 4\n"
            "  - label: 'true'\n"
            "    size: 2\n"
            "    stride: 1\n"
            "  data_offset: 3\n"
            "data:\n"
            "- 400.0\n"
            "- -0.001\n"
            "- 1.5e-07\n");

  msg::Clock k;
  k.clock = {2147483647, 4294967295u};
  EXPECT_EQ(to_yaml(k), "clock:\n  sec: 2147483647\n  nanosec: 4294967295\n");

  msg::ControllerStatus s;
  s.header.stamp = {3, 250000000};
  s.header.frame_id = "world";
  s.controller = "paper";
  s.mode = "position";
  s.setpoint = {1.0, 2.0, -3.0, 0.1, 0.2, 3.5};
  s.u = {9.81, 0.01, -0.02, 0.0};
  s.position_error = {0.75, -1.5, -0.5};
  s.yaw_error = 1e-06;
  s.attitude_error = 0.0078125;
  s.output_names = {"error.z", "error.roll", "error.pitch", "error.yaw"};
  s.outputs = {-0.5, 0.25, -0.125, 1e-06};
  s.rotor_saturated = {true, false, false, true};
  s.tilt_saturated = true;
  s.safety = false;
  s.rejected_non_finite = 1;
  s.rejected_bad_quaternion = 22;
  s.rejected_bad_stamp = 333;
  s.rejected_stamp_backwards = 18446744073709551615u;  // uint64 max: a Python int, not -1
  EXPECT_EQ(to_yaml(s),
            "header:\n"
            "  stamp:\n"
            "    sec: 3\n"
            "    nanosec: 250000000\n"
            "  frame_id: world\n"
            "controller: paper\n"
            "mode: position\n"
            "setpoint:\n"
            "- 1.0\n- 2.0\n- -3.0\n- 0.1\n- 0.2\n- 3.5\n"
            "u:\n"
            "- 9.81\n- 0.01\n- -0.02\n- 0.0\n"
            "position_error:\n"
            "- 0.75\n- -1.5\n- -0.5\n"
            "yaw_error: 1.0e-06\n"
            "attitude_error: 0.0078125\n"
            "rotor_saturated:\n"
            "- true\n- false\n- false\n- true\n- false\n- false\n- false\n- false\n"
            "tilt_saturated: true\n"
            "safety: false\n"
            "rejected_non_finite: 1\n"
            "rejected_bad_quaternion: 22\n"
            "rejected_bad_stamp: 333\n"
            "rejected_stamp_backwards: 18446744073709551615\n"
            "rejected_stamp_ahead: 0\n"
            "output_names:\n"
            "- error.z\n- error.roll\n- error.pitch\n- error.yaw\n"
            "outputs:\n"
            "- -0.5\n- 0.25\n- -0.125\n- 1.0e-06\n");

  msg::PlantStatus ps;
  ps.header.stamp = {9, 1};
  ps.header.frame_id = "base_link";
  ps.commands_accepted = 10;
  ps.commands_clamped = 2;
  ps.commands_rejected_length = 1;
  ps.commands_rejected_non_finite = 4;
  ps.last_problem = "rotor 2: speed above omega_max";
  ps.watchdog_active = true;
  ps.watchdog_trips = 3;
  ps.watchdog_ticks = 250;
  ps.commands_stale = 7;
  ps.commands_foreign = 1;
  ps.commands_rejected_second_topic = 2;
  ps.commands_rejected_bad_quaternion = 3;
  EXPECT_EQ(to_yaml(ps),
            "header:\n"
            "  stamp:\n"
            "    sec: 9\n"
            "    nanosec: 1\n"
            "  frame_id: base_link\n"
            "commands_accepted: 10\n"
            "commands_clamped: 2\n"
            "commands_rejected_length: 1\n"
            "commands_rejected_non_finite: 4\n"
            "last_problem: 'rotor 2: speed above omega_max'\n"
            "watchdog_active: true\n"
            "watchdog_trips: 3\n"
            "watchdog_ticks: 250\n"
            "commands_stale: 7\n"
            "commands_foreign: 1\n"
            "commands_rejected_second_topic: 2\n"
            "commands_rejected_bad_quaternion: 3\n");
}

// The sensor types, written out by hand as `ros2 topic echo` prints them (int8 and uint16 as plain
// integers, the NavSatStatus a nested mapping).
TEST(TopicToolsTest, SensorTypesAsRos2TopicEcho) {
  msg::FluidPressure b;
  b.header = {{7, 5}, "baro"};
  b.fluid_pressure = 101325.0;
  b.variance = 0.25;
  EXPECT_EQ(to_yaml(b),
            "header:\n  stamp:\n    sec: 7\n    nanosec: 5\n  frame_id: baro\n"
            "fluid_pressure: 101325.0\nvariance: 0.25\n");

  msg::MagneticField m;
  m.magnetic_field = {2.1e-05, -1.5e-06, 4.4e-05};
  m.magnetic_field_covariance[4] = 1e-14;
  EXPECT_EQ(to_yaml(m),
            "header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: ''\n"
            "magnetic_field:\n  x: 2.1e-05\n  y: -1.5e-06\n  z: 4.4e-05\n"
            "magnetic_field_covariance:\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 1.0e-14\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n");

  msg::NavSatFix f;
  f.header = {{1700000000, 250000000}, "gnss"};
  f.status.status = msg::NavSatStatus::kStatusNoFix;
  f.status.service = msg::NavSatStatus::kServiceGps | msg::NavSatStatus::kServiceCompass;
  f.latitude = 47.5;
  f.longitude = -8.25;
  f.altitude = 488.0;
  f.position_covariance_type = msg::NavSatFix::kCovarianceTypeApproximated;
  EXPECT_EQ(to_yaml(f),
            "header:\n  stamp:\n    sec: 1700000000\n    nanosec: 250000000\n  frame_id: gnss\n"
            "status:\n  status: -1\n  service: 5\n"
            "latitude: 47.5\nlongitude: -8.25\naltitude: 488.0\n"
            "position_covariance:\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n"
            "position_covariance_type: 1\n");
  EXPECT_EQ(to_yaml(msg::NavSatStatus{}), "status: -2\nservice: 0\n");  // the .msg defaults
}

TEST(TopicToolsTest, RateWindowAsRos2TopicHz) {
  RateWindow w(3);
  EXPECT_FALSE(w.stats());
  w.add(0);
  EXPECT_FALSE(w.stats());
  w.add(10'000'000);
  w.add(20'000'000);
  w.add(32'000'000);
  w.add(40'000'000);  // the window keeps the last 3 intervals: 10, 12, 8 ms
  const auto s = w.stats();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->window, 3u);
  EXPECT_NEAR(s->rate_hz, 100.0, 1e-9);
  EXPECT_NEAR(s->min_s, 0.008, 1e-12);
  EXPECT_NEAR(s->max_s, 0.012, 1e-12);
  EXPECT_NEAR(s->std_dev_s, std::sqrt(8.0 / 3.0) * 1e-3, 1e-12);
  EXPECT_EQ(w.messages(), 5u);
  EXPECT_EQ(format_rate(*s), "average rate: 100.000\n\tmin: 0.008s max: 0.012s std dev: 0.00163s window: 3\n");
  w.add(1'000);  // the clock went back: start over
  EXPECT_FALSE(w.stats());
}

}  // namespace
}  // namespace quadcosim::dds
