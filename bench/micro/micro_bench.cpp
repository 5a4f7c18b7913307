// Micro-benchmarks (Google Benchmark): the plant step per RK4 sub-step count, one controller step, the
// CARE solve, the allocation, one tick of the full in-process co-simulation, and the BASELINE minimal
// loop (bench/baseline/baseline_loop.hpp). Built with the project, never run by CTest:
//   build/bench/quadcosim_bench [--benchmark_filter=REGEX]
#include <benchmark/benchmark.h>

#include <memory>

#include "baseline/baseline_setup.hpp"
#include "control/allocation.hpp"
#include "control/care.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "hosts/scenario_resolvers.hpp"
#include "io/scenario.hpp"
#include "model/quadrotor.hpp"
#include "sim/simulation.hpp"

#ifndef QUADCOSIM_SOURCE_DIR
#error "QUADCOSIM_SOURCE_DIR must be defined"
#endif

namespace qc = quadcosim;

namespace {

// A hovering vehicle slightly off level, so every term of the derivative is exercised.
qc::model::State hover_state(const qc::model::Quadrotor& m) {
  qc::model::State x = m.initial_state({0.0, 0.0, 5.0}, 0.1, true);
  x.w_B = {0.01, -0.02, 0.005};
  return x;
}

void BM_PlantStep(benchmark::State& st) {
  const qc::model::Quadrotor m{qc::model::VehicleParams{}};
  qc::model::State x = hover_state(m);
  const qc::model::Vector4 cmd = qc::model::Vector4::Constant(m.params().hover_omega_rad_s());
  const int substeps = static_cast<int>(st.range(0));
  for (auto _ : st) {
    m.step(x, 0.0, cmd, 0.01, substeps);
    benchmark::DoNotOptimize(x);
  }
}
BENCHMARK(BM_PlantStep)->Arg(1)->Arg(2)->Arg(4)->Arg(8);

void BM_ControllerStep(benchmark::State& st) {
  qc::controllers::PaperController c{qc::model::VehicleParams{}};
  qc::control::Observation e;
  e.p_W = {0.1, -0.2, 4.9};
  e.v_W = {0.01, 0.02, -0.1};
  e.roll_rad = 0.01;
  e.pitch_rad = -0.02;
  e.yaw_rad = 0.1;
  e.w_B = {0.01, -0.02, 0.005};
  e.age_s = 0.0;
  qc::control::Reference ref;
  ref.p_W = {0.0, 0.0, 5.0};
  qc::control::ControllerOutput out;
  out.outputs.resize(c.output_names().size());
  for (auto _ : st) {
    c.step(e, ref, 0.02, out);
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_ControllerStep);

void BM_CareSolve(benchmark::State& st) {
  // One attitude axis of the paper's vehicle (2 states, 1 input).
  const double I = 0.0149;
  Eigen::MatrixXd A(2, 2), B(2, 1), Q(2, 2), R(1, 1);
  A << 0, 1, 0, 0;
  B << 0, -1.0 / I;
  Q << 1.3, 0, 0, 2.4;
  R << 100.0;
  for (auto _ : st) benchmark::DoNotOptimize(qc::control::solve_care(A, B, Q, R));
}
BENCHMARK(BM_CareSolve);

void BM_Allocation(benchmark::State& st) {
  const Eigen::Matrix4d Mi = qc::model::mixer_matrix(qc::model::VehicleParams{}).inverse();
  Eigen::Vector4d U(19.3, 0.01, -0.02, 0.001);
  for (auto _ : st) {
    benchmark::DoNotOptimize(U);
    benchmark::DoNotOptimize(qc::control::allocate(Mi, U, 0.0, 12000.0));
  }
}
BENCHMARK(BM_Allocation);

// One 100 Hz tick (plant step + half a controller step) of the BASELINE minimal loop.
void BM_BaselineTick(benchmark::State& st) {
  qc::baseline::BaselineLoop loop =
      qc::baseline::make_baseline(qc::model::VehicleParams{}, qc::controllers::PaperParams{}, 10.0);
  long k = 0;
  for (auto _ : st) {
    loop.tick(k++, 0.01);
    benchmark::DoNotOptimize(loop.state());
  }
}
BENCHMARK(BM_BaselineTick);

// One 100 Hz tick of the framework's in-process co-simulation (paper altitude scenario, recording
// off): /clock, Pose, Velocity, Imu published, the 50 Hz controller on even ticks, the command
// latched, RK4.
void BM_SimulationTick(benchmark::State& st) {
  const qc::io::Scenario sc = qc::io::load_scenario(QUADCOSIM_SOURCE_DIR "/scenarios/paper/altitude_step.yaml",
                                                    qc::hosts::scenario_resolvers());
  constexpr qc::sim::Tick kTicks = 100'000;
  auto cfg = sc.simulation;
  cfg.duration_ticks = kTicks;
  auto make = [&] {
    return std::make_unique<qc::sim::Simulation>(cfg, sc.vehicle, qc::io::initial_state(sc), sc.controller,
                                                 sc.schedule);
  };
  auto sim = make();
  qc::sim::Tick k = 0;
  for (auto _ : st) {
    if (k > kTicks) {
      st.PauseTiming();
      sim = make();
      k = 0;
      st.ResumeTiming();
    }
    sim->tick(k++);
  }
}
BENCHMARK(BM_SimulationTick);

}  // namespace

BENCHMARK_MAIN();
