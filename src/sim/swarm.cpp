#include "sim/swarm.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

namespace quadcosim::sim {

std::string vehicle_namespace(const std::string& prefix, int index, int vehicles) {
  int width = 1;
  for (int n = std::max(vehicles - 1, 1); n >= 10; n /= 10) ++width;
  width = std::max(width, 4);
  std::string digits = std::to_string(index);
  if (static_cast<int>(digits.size()) < width) digits.insert(0, static_cast<std::size_t>(width) - digits.size(), '0');
  return prefix + digits;
}

Eigen::Vector3d vehicle_offset_W(const SwarmLayout& layout, int index) {
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(layout.vehicles))));
  const int column = index % columns, row = index / columns;
  return {column * layout.spacing_m, row * layout.spacing_m, (index % layout.altitude_layers) * layout.layer_spacing_m};
}

SwarmVehicle swarm_vehicle(const SimulationConfig& simulation, const model::State& initial,
                           const control::ControllerConfig& controller, const std::vector<ScheduledParameter>& schedule,
                           const SwarmLayout& layout, int index) {
  const Eigen::Vector3d o = vehicle_offset_W(layout, index);
  SwarmVehicle v{simulation, initial, controller, schedule};
  v.simulation.ns = vehicle_namespace(layout.ns_prefix, index, layout.vehicles);
  v.initial.p_W.x() += o.x();
  v.initial.p_W.y() += o.y();
  v.controller.node.setpoint.p_des_W += o;
  v.controller.trajectory_offset_W += o;
  for (ScheduledParameter& p : v.schedule) {
    const int axis = p.name == "x_des" ? 0 : p.name == "y_des" ? 1 : p.name == "z_des" ? 2 : -1;
    if (axis >= 0 && std::holds_alternative<double>(p.value)) p.value = std::get<double>(p.value) + o[axis];
  }
  return v;
}

Swarm::Swarm(const SimulationConfig& simulation, const model::VehicleParams& vehicle, const model::State& initial,
             const control::ControllerConfig& controller, const std::vector<ScheduledParameter>& schedule,
             const SwarmLayout& layout)
    : layout_(layout), duration_ticks_(simulation.duration_ticks) {
  const auto n = static_cast<std::size_t>(layout.vehicles);
  setups_.reserve(n);
  namespaces_.reserve(n);
  vehicles_.reserve(n);
  for (int i = 0; i < layout.vehicles; ++i) {
    setups_.push_back(swarm_vehicle(simulation, initial, controller, schedule, layout, i));
    const SwarmVehicle& s = setups_.back();
    namespaces_.push_back(s.simulation.ns);
    vehicles_.push_back(std::make_unique<Simulation>(s.simulation, vehicle, s.initial, s.controller, s.schedule));
  }
}

bool Swarm::run(int threads, Tick block_ticks, const std::vector<bool>& recorded, const Recorder& recorder,
                const StopCheck& stop) {
  return run_ticks(0, duration_ticks_, threads, block_ticks, recorded, recorder, stop);
}

bool Swarm::run_ticks(Tick first_tick, Tick last_tick, int threads, Tick block_ticks, const std::vector<bool>& recorded,
                      const Recorder& recorder, const StopCheck& stop) {
  last_tick = std::min(last_tick, duration_ticks_);
  threads = std::clamp(threads, 1, std::max(1, size()));
  block_ticks = std::max<Tick>(block_ticks, 1);
  std::exception_ptr failure;
  std::mutex failure_mutex;
  std::atomic<bool> stopped{false};
  const std::thread::id caller = std::this_thread::get_id();
  // Each thread owns a contiguous range of vehicles and runs it through every block; the vehicles do
  // not interact, so threads need no synchronisation beyond the final join.
  auto work = [&](int first, int last) {
    try {
      for (Tick start = first_tick; start <= last_tick; start += block_ticks) {
        const Tick end = std::min(start + block_ticks - 1, last_tick);
        for (int i = first; i < last; ++i) {
          Simulation& s = *vehicles_[static_cast<std::size_t>(i)];
          const bool rec = recorder && !recorded.empty() && recorded[static_cast<std::size_t>(i)];
          for (Tick k = start; k <= end; ++k) {
            if (rec) {
              s.tick(k, [&recorder, i](const TickRecord& r) { recorder(i, r); });
            } else {
              s.tick(k);
            }
          }
        }
        if (stop && std::this_thread::get_id() == caller && stop(end)) stopped = true;
        if (stopped) return;
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
  return !stopped;
}

}  // namespace quadcosim::sim
