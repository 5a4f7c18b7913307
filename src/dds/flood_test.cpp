// A flood on a subscribed topic cannot make one spin_once call do unbounded work: the reader's
// KEEP_LAST history (ROS default depth 10) keeps only the newest samples, and spin_once delivers what
// the readers hold, then returns.
#include <gtest/gtest.h>

#include <unistd.h>

#include "dds/dds_transport.hpp"
#include "sim/messages.hpp"

namespace quadcosim::dds {
namespace {

TEST(DdsFloodTest, OneSpinDeliversAtMostTheHistoryDepthAndTheNewestLast) {
  RosEnvironment env;
  env.domain_id = 195 + static_cast<std::uint32_t>(getpid() % 5);  // 195-199, apart from tests/faults
  env.range = DiscoveryRange::kLocalhost;
  DdsTransport sender(env), receiver(env);
  std::vector<double> got;
  receiver.subscribe<msg::Float64MultiArray>("/flood/motor_commands",
                                             [&](const msg::Float64MultiArray& m) { got.push_back(m.data[0]); });
  auto pub = sender.advertise<msg::Float64MultiArray>("/flood/motor_commands");
  ASSERT_TRUE(sender.spin_until([&] { return sender.matched_readers("/flood/motor_commands") == 1; }, 5'000'000'000));
  msg::Float64MultiArray m;
  m.data = {0, 0, 0, 0};
  m.dim = {{"", 4, 4}};
  constexpr int kSent = 5000;
  for (int i = 0; i < kSent; ++i) {
    m.data[0] = i;
    pub.publish(m);
  }
  // The last sample may still be on its way: wait for it, one spin at a time.
  int spins = 0;
  while ((got.empty() || got.back() != kSent - 1) && spins < 1000) {
    const std::size_t before = got.size();
    receiver.spin_once(100'000'000);
    ++spins;
    ASSERT_LE(got.size() - before, static_cast<std::size_t>(QosProfile::ros_default().depth)) << "spin " << spins;
  }
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), kSent - 1);
  EXPECT_LT(got.size(), static_cast<std::size_t>(kSent));  // older samples were replaced, not queued
  for (std::size_t i = 1; i < got.size(); ++i) EXPECT_LT(got[i - 1], got[i]);
}

}  // namespace
}  // namespace quadcosim::dds
