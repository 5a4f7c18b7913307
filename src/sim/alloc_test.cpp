// No heap allocation per step: global operator new/delete are replaced by counting versions, and the
// in-process single-vehicle loop and the swarm loop must allocate nothing once warmed up (the first
// ticks may: the scheduled parameter change, the command label's first buffer).
#include <gtest/gtest.h>

#include "controllers/registry.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

#include "sim/simulation.hpp"
#include "sim/swarm.hpp"

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};

void* counted(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}

// Counts the allocations `f` makes.
template <class F>
long allocations_during(F f) {
  g_allocations = 0;
  g_counting = true;
  f();
  g_counting = false;
  return g_allocations.load();
}
}  // namespace

void* operator new(std::size_t n) { return counted(n); }
void* operator new[](std::size_t n) { return counted(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace quadcosim::sim {
namespace {

SimulationConfig config(Tick duration) {
  SimulationConfig c;
  c.duration_ticks = duration;
  return c;
}

std::vector<ScheduledParameter> altitude_step() { return {{0, "z_des", 10.0}}; }

TEST(AllocationTest, TheCounterSeesAllocations) {
  // The counter itself works: a vector's growth is counted.
  EXPECT_GE(allocations_during([] {
              std::vector<int> v;
              for (int i = 0; i < 100; ++i) v.push_back(i);
            }),
            1);
}

TEST(AllocationTest, SingleVehicleLoopAllocatesNothingPerStep) {
  Simulation s(config(3000), model::VehicleParams{}, model::State{},
               controllers::make_config("paper", model::VehicleParams{}), altitude_step());
  for (Tick k = 0; k < 100; ++k) s.tick(k);  // warm-up: the schedule, the first command label
  const long n = allocations_during([&] {
    for (Tick k = 100; k < 3000; ++k) s.tick(k);
  });
  EXPECT_EQ(n, 0);
  EXPECT_GT(s.plant().state().p_W.z(), 5.0);  // it flew: the loop did run
}

TEST(AllocationTest, RecordedRunAllocatesNothingPerStepBeyondTheRecorder) {
  // run() with an observer: the scheduler and TickRecord add nothing either.
  Simulation s(config(2000), model::VehicleParams{}, model::State{},
               controllers::make_config("paper", model::VehicleParams{}), altitude_step());
  double z_sum = 0.0;
  long during = -1;
  s.run([&](const TickRecord& r) {
    if (r.tick == 100) {
      g_allocations = 0;
      g_counting = true;
    }
    z_sum += r.state.p_W.z();
    if (r.tick == 1999) {
      g_counting = false;
      during = g_allocations.load();
    }
  });
  EXPECT_EQ(during, 0);
  EXPECT_GT(z_sum, 0.0);
}

TEST(AllocationTest, SwarmLoopAllocatesNothingPerStep) {
  SwarmLayout layout;
  layout.vehicles = 16;
  Swarm swarm(config(2000), model::VehicleParams{}, model::State{},
              controllers::make_config("paper", model::VehicleParams{}), altitude_step(), layout);
  swarm.run_ticks(0, 99, 1, 100);  // warm-up
  EXPECT_EQ(allocations_during([&] { swarm.run_ticks(100, 1999, 1, 100); }), 0);
  for (int i = 0; i < swarm.size(); ++i) EXPECT_GT(swarm.vehicle(i).plant().state().p_W.z(), 5.0) << i;
}

TEST(AllocationTest, SwarmOnTwoThreadsAllocatesOnlyToStartTheThread) {
  // Starting the second thread allocates its state; the count must not grow with ticks or vehicles.
  SwarmLayout layout;
  layout.vehicles = 16;
  Swarm swarm(config(3000), model::VehicleParams{}, model::State{},
              controllers::make_config("paper", model::VehicleParams{}), altitude_step(), layout);
  swarm.run_ticks(0, 99, 2, 100);
  const long short_run = allocations_during([&] { swarm.run_ticks(100, 109, 2, 100); });
  const long long_run = allocations_during([&] { swarm.run_ticks(110, 2999, 2, 100); });
  EXPECT_EQ(short_run, long_run);
  EXPECT_LE(long_run, 2);
}

}  // namespace
}  // namespace quadcosim::sim
