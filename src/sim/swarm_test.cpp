// Tests of the swarm: names, grid, and that each vehicle flies exactly (bit for bit) what a
// single-vehicle Simulation set up by hand with the same offsets flies, for any thread count and
// block length.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "controllers/paper/paper_controller.hpp"
#include "controllers/registry.hpp"
#include "sim/swarm.hpp"

namespace quadcosim::sim {
namespace {

TEST(SwarmTest, NamespacesAreZeroPaddedToTheLargestIndex) {
  EXPECT_EQ(vehicle_namespace("/uav", 7, 16), "/uav0007");
  EXPECT_EQ(vehicle_namespace("/uav", 9999, 10000), "/uav9999");
  EXPECT_EQ(vehicle_namespace("/uav", 3, 50000), "/uav00003");
  EXPECT_EQ(vehicle_namespace("/uav", 49999, 50000), "/uav49999");
  EXPECT_EQ(vehicle_namespace("/fleet/q", 0, 1), "/fleet/q0000");
}

TEST(SwarmTest, GridOffsets) {
  SwarmLayout l;
  l.vehicles = 10;  // ceil(sqrt(10)) = 4 columns
  l.spacing_m = 3.0;
  l.altitude_layers = 3;
  l.layer_spacing_m = 0.5;
  EXPECT_EQ(vehicle_offset_W(l, 0), Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(vehicle_offset_W(l, 3), Eigen::Vector3d(9, 0, 0));
  EXPECT_EQ(vehicle_offset_W(l, 5), Eigen::Vector3d(3, 3, 1.0));  // column 1, row 1, layer 2
  EXPECT_EQ(vehicle_offset_W(l, 9), Eigen::Vector3d(3, 6, 0));
}

struct Trace {
  std::vector<double> values;
  void add(const TickRecord& r) {
    const auto& x = r.state;
    for (double v : {x.p_W.x(), x.p_W.y(), x.p_W.z(), x.v_W.x(), x.v_W.z(), x.q_WB.w(), x.q_WB.x(), x.w_B.y(),
                     r.latched_command[0], r.latched_command[3], r.status.u[0]}) {
      values.push_back(v);
    }
  }
};

SimulationConfig config() {
  SimulationConfig c;
  c.duration_ticks = 600;
  return c;
}

control::ControllerConfig position_mode() {
  controllers::PaperParams p;
  p.roll = {1.0, 0.02, 1.0};
  p.pitch = {1.0, 0.02, 1.0};
  p.position.kp = 0.8;
  p.position.kd = 1.4;
  control::ControllerConfig c = controllers::make_config("paper", model::VehicleParams{});
  c.controller = std::make_shared<controllers::PaperController>(c.vehicle, p);
  c.node.setpoint.mode = control::Mode::kPosition;
  return c;
}

std::vector<ScheduledParameter> schedule() { return {{0, "z_des", 3.0}, {150, "x_des", 0.5}, {301, "y_des", -0.5}}; }

TEST(SwarmTest, EachVehicleFliesWhatItsOwnSimulationFlies) {
  SwarmLayout l;
  l.vehicles = 5;  // 3 columns
  l.spacing_m = 2.0;
  l.altitude_layers = 2;
  l.layer_spacing_m = 1.5;
  Swarm swarm(config(), model::VehicleParams{}, model::State{}, position_mode(), schedule(), l);
  std::vector<Trace> got(5);
  swarm.run(2, 100, std::vector<bool>(5, true),
            [&](int i, const TickRecord& r) { got[static_cast<std::size_t>(i)].add(r); });

  // Vehicle 4: column 1, row 1, layer 0, set up by hand.
  for (int i : {0, 4}) {
    const double ox = (i % 3) * 2.0, oy = (i / 3) * 2.0, oz = (i % 2) * 1.5;
    model::State x0;
    x0.p_W = {ox, oy, 0.0};
    control::ControllerConfig c = position_mode();
    c.node.setpoint.p_des_W = {ox, oy, oz};
    SimulationConfig cfg = config();
    cfg.ns = i == 0 ? "/uav0000" : "/uav0004";
    Simulation alone(cfg, model::VehicleParams{}, x0, c,
                     {{0, "z_des", 3.0 + oz}, {150, "x_des", 0.5 + ox}, {301, "y_des", -0.5 + oy}});
    Trace want;
    alone.run([&](const TickRecord& r) { want.add(r); });
    EXPECT_EQ(swarm.vehicle_ns(i), cfg.ns);
    ASSERT_EQ(got[static_cast<std::size_t>(i)].values.size(), want.values.size());
    EXPECT_TRUE(got[static_cast<std::size_t>(i)].values == want.values) << "vehicle " << i << " differs";
  }
  // And it went where it was told: x_des = 0.5 + 2 for vehicle 4 (settling), z near 3.
  EXPECT_NEAR(swarm.vehicle(4).plant().state().p_W.z(), 3.0, 0.2);
}

TEST(SwarmTest, ThreadsAndBlocksDoNotChangeTheNumbers) {
  SwarmLayout l;
  l.vehicles = 7;
  auto finals = [&](int threads, Tick block) {
    Swarm s(config(), model::VehicleParams{}, model::State{}, position_mode(), schedule(), l);
    s.run(threads, block);
    std::vector<double> v;
    for (int i = 0; i < s.size(); ++i) {
      const auto& x = s.vehicle(i).plant().state();
      v.insert(v.end(), {x.p_W.x(), x.p_W.y(), x.p_W.z(), x.q_WB.x(), x.w_B.z()});
    }
    return v;
  };
  const auto ref = finals(1, 1);
  EXPECT_TRUE(finals(2, 100) == ref);
  EXPECT_TRUE(finals(3, 7) == ref);
  EXPECT_TRUE(finals(7, 1000) == ref);
}

TEST(SwarmTest, ARefusedScheduledChangeStopsTheRunWithItsReason) {
  SwarmLayout l;
  l.vehicles = 4;
  Swarm s(config(), model::VehicleParams{}, model::State{}, position_mode(), {{10, "z_des", 1e9}}, l);
  EXPECT_THROW(s.run(2, 100), std::invalid_argument);
}

TEST(SwarmTest, AStopCheckEndsEveryThreadAtABlockBoundary) {
  SwarmLayout l;
  l.vehicles = 4;  // 2 threads: the caller flies vehicles 0 and 1
  Swarm s(config(), model::VehicleParams{}, model::State{}, position_mode(), schedule(), l);
  std::vector<Tick> asked;
  std::vector<int> ticks(4, 0);
  const bool completed = s.run(
      2, 50, std::vector<bool>(4, true), [&](int i, const TickRecord&) { ++ticks[static_cast<std::size_t>(i)]; },
      [&](Tick last) {
        asked.push_back(last);
        return asked.size() == 3;
      });
  EXPECT_FALSE(completed);
  EXPECT_EQ(asked, (std::vector<Tick>{49, 99, 149}));  // on the calling thread, after each of its blocks
  EXPECT_EQ(ticks[0], 150);
  EXPECT_EQ(ticks[1], 150);
  for (int i : {2, 3}) {  // the other thread ends the block it is in (whole blocks), or had finished
    const int n = ticks[static_cast<std::size_t>(i)];
    EXPECT_TRUE(n == 601 || (n >= 50 && n % 50 == 0)) << "vehicle " << i << ": " << n << " ticks";
  }
  Swarm whole(config(), model::VehicleParams{}, model::State{}, position_mode(), schedule(), l);
  EXPECT_TRUE(whole.run(2, 50, {}, {}, [](Tick) { return false; }));
}

}  // namespace
}  // namespace quadcosim::sim
