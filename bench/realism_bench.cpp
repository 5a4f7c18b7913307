// What realism costs per plant tick: the plant node (publish outputs, latch, integrate) on the
// in-process bus with realism off (the paper's plant), with drag only, and with every source on;
// and the model's RK4 step without and with an Environment. Prints figures; asserts nothing.
//   build/bench/realism_bench [--benchmark_min_time=0.2]
#include <benchmark/benchmark.h>

#include "model/quadrotor.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"

namespace {

using namespace quadcosim;

sim::RealismConfig everything() {
  sim::RealismConfig r;
  r.seed = 1;
  r.imu.gyro_noise_density = 3e-4;
  r.imu.gyro_bias_random_walk = 4e-5;
  r.imu.accel_noise_density = 4e-3;
  r.imu.accel_bias_random_walk = 6e-4;
  r.imu.orientation_sigma_rad = 2e-3;
  r.imu.timing.latency_ticks = 1;
  r.pose.position_sigma_m = 0.01;
  r.pose.orientation_sigma_rad = 2e-3;
  r.velocity.linear_sigma_m_s = 0.02;
  r.velocity.angular_sigma_rad_s = 1e-3;
  r.wind.mean_W_m_s = {3, 0, 0};
  r.wind.gusts.enabled = true;
  return r;
}

void plant_ticks(benchmark::State& st, const sim::RealismConfig& r, bool drag) {
  sim::InProcessTransport bus;
  model::VehicleParams v;
  if (drag) v.aero.linear_drag_N_s_m.setConstant(0.25);
  sim::PlantOptions o;
  o.realism = r;
  const model::State x0 = model::Quadrotor(v).initial_state({0, 0, 5}, 0.0, true);
  sim::PlantNode plant(bus, sim::Topics::for_namespace("/drone"), v, o, x0);
  sim::Tick k = 0;
  for (auto _ : st) {
    plant.publish_outputs(k);
    plant.latch_command(k);
    plant.integrate(k);
    ++k;
  }
  st.SetItemsProcessed(st.iterations());
}

void BM_PlantTick_RealismOff(benchmark::State& st) { plant_ticks(st, {}, false); }
void BM_PlantTick_DragOnly(benchmark::State& st) { plant_ticks(st, {}, true); }
void BM_PlantTick_Everything(benchmark::State& st) { plant_ticks(st, everything(), true); }

void BM_Rk4Step(benchmark::State& st, bool with_env) {
  model::VehicleParams v;
  const model::Quadrotor q(v);
  model::State x = q.initial_state({0, 0, 5}, 0.0, true);
  const model::Vector4 cmd = x.omega_rad_s;
  const model::Environment env;
  for (auto _ : st) {
    q.step(x, 0.0, cmd, 0.01, 1, with_env ? &env : nullptr);
    benchmark::DoNotOptimize(x);
  }
}
void BM_Rk4Step_NoEnvironment(benchmark::State& st) { BM_Rk4Step(st, false); }
void BM_Rk4Step_IdleEnvironment(benchmark::State& st) { BM_Rk4Step(st, true); }

BENCHMARK(BM_PlantTick_RealismOff);
BENCHMARK(BM_PlantTick_DragOnly);
BENCHMARK(BM_PlantTick_Everything);
BENCHMARK(BM_Rk4Step_NoEnvironment);
BENCHMARK(BM_Rk4Step_IdleEnvironment);

}  // namespace

BENCHMARK_MAIN();
