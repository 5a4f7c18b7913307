#include "inproc/swarm.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>

namespace quadcosim::inproc {

Swarm::Swarm(const SimulationConfig& simulation, const model::VehicleParams& vehicle, const model::State& initial,
             const control::ControllerConfig& controller, const std::vector<sim::ScheduledParameter>& schedule,
             const SwarmLayout& layout)
    : layout_(layout), duration_ticks_(simulation.duration_ticks) {
  const auto n = static_cast<std::size_t>(layout.vehicles);
  setups_.reserve(n);
  namespaces_.reserve(n);
  vehicles_.reserve(n);
  for (int i = 0; i < layout.vehicles; ++i) {
    setups_.push_back(sim::swarm_vehicle(simulation, initial, controller, schedule, layout, i));
    const SwarmVehicle& s = setups_.back();
    namespaces_.push_back(s.simulation.ns);
    vehicles_.push_back(std::make_unique<Simulation>(s.simulation, vehicle, s.initial, s.controller, s.schedule));
  }
}

void Swarm::run(int threads, sim::Tick block_ticks, const std::vector<bool>& recorded, const Recorder& recorder) {
  run_ticks(0, duration_ticks_, threads, block_ticks, recorded, recorder);
}

void Swarm::run_ticks(sim::Tick first_tick, sim::Tick last_tick, int threads, sim::Tick block_ticks,
                      const std::vector<bool>& recorded, const Recorder& recorder) {
  last_tick = std::min(last_tick, duration_ticks_);
  threads = std::clamp(threads, 1, std::max(1, size()));
  block_ticks = std::max<sim::Tick>(block_ticks, 1);
  std::exception_ptr failure;
  std::mutex failure_mutex;
  // Each thread owns a contiguous range of vehicles and runs it through every block; the vehicles do
  // not interact, so threads need no synchronisation beyond the final join.
  auto work = [&](int first, int last) {
    try {
      for (sim::Tick start = first_tick; start <= last_tick; start += block_ticks) {
        const sim::Tick end = std::min(start + block_ticks - 1, last_tick);
        for (int i = first; i < last; ++i) {
          Simulation& s = *vehicles_[static_cast<std::size_t>(i)];
          const bool rec = recorder && !recorded.empty() && recorded[static_cast<std::size_t>(i)];
          if (rec) {
            s.run_ticks(end, [&](const TickRecord& r) { recorder(i, r); });
          } else {
            s.run_ticks(end);
          }
        }
        std::lock_guard lock(failure_mutex);
        if (failure) return;
      }
    } catch (...) {
      std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  const int n = size();
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, n * t / threads, n * (t + 1) / threads);
  work(0, n / threads);
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace quadcosim::inproc
