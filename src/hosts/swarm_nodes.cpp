// The swarm processes (`quadcosim plant --vehicles N`, `quadcosim controller --vehicles N`): N
// vehicles' nodes in one process over DDS, each vehicle under its own namespace (<prefix>0000, ...),
// lockstep only. The vehicles are split over `threads` threads; each thread has its own DDS
// participant and runs its vehicles' PlantNodes (or ControllerNodes) exactly as the single-vehicle
// processes do, so every vehicle's numbers equal those of the in-process swarm.
#include "hosts/swarm_nodes.hpp"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <thread>

#include "control/care.hpp"
#include "dds/node_announcer.hpp"
#include "drivers/controller_drivers.hpp"
#include "drivers/lockstep_plant_driver.hpp"
#include "hosts/exit_code.hpp"
#include "hosts/node_common.hpp"
#include "hosts/recording.hpp"
#include "hosts/signals.hpp"
#include "hosts/swarm_inprocess.hpp"
#include "sim/controller_node.hpp"
#include "sim/plant_node.hpp"

namespace quadcosim::hosts {

namespace fs = std::filesystem;

namespace {

io::SwarmSpec node_spec(const io::Scenario& sc, int vehicles, const std::string& ns_prefix) {
  io::SwarmSpec spec = swarm_spec(sc, vehicles, 0);
  if (!ns_prefix.empty()) {
    if (std::string err = sim::validate_namespace(ns_prefix + "0"); !err.empty()) {
      throw io::ConfigError("--ns-prefix: got '" + ns_prefix + "': " + err);
    }
    spec.layout.ns_prefix = ns_prefix;
  }
  return spec;
}

/// Runs `body(t)` on `threads` threads (t = 0 on the caller's); returns the largest exit code.
template <class F>
int run_threads(int threads, F body) {
  std::atomic<int> worst{exit_code::kOk};
  auto one = [&](int t) {
    int rc;
    try {
      rc = body(t);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << '\n';
      rc = exit_code::kOutput;
    }
    int cur = worst.load();
    while (rc > cur && !worst.compare_exchange_weak(cur, rc)) {
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(one, t);
  one(0);
  for (auto& th : pool) th.join();
  return worst.load();
}

// One thread's share of the plants: its participant, its vehicles, their lockstep driver.
class PlantShard {
 public:
  PlantShard(const io::Scenario& sc, const io::SwarmSpec& spec, int first, int last, const std::vector<bool>& recorded,
             const fs::path& out, bool sensor_qos, const std::string& enclave)
      : sc_(sc), clock_(sc.simulation.plant.clock), transport_(dds::read_ros_environment(enclave)), first_(first) {
    const model::State initial = io::initial_state(sc);
    for (int i = first; i < last; ++i) {
      const sim::SwarmVehicle v =
          sim::swarm_vehicle(sc.simulation, initial, sc.controller, sc.schedule, spec.layout, i);
      auto node = std::make_unique<Vehicle>();
      node->topics = sim::Topics::for_namespace(v.simulation.ns);
      if (sensor_qos) use_sensor_qos(transport_, node->topics);
      sim::PlantOptions po = v.simulation.plant;
      po.drop_stale_commands = true;
      po.publish_clock = i == 0;        // one /clock for the whole swarm
      po.typed_command_topics = false;  // the swarm's controllers are its own, on motor_commands
      node->plant = std::make_unique<sim::PlantNode>(transport_, node->topics, sc.vehicle, po, v.initial);
      if (recorded[static_cast<std::size_t>(i)]) {
        const fs::path dir = out / v.simulation.ns.substr(1);
        std::error_code ec;  // a failure shows as the writer's "cannot open" naming the file
        fs::create_directories(dir, ec);
        RecordingOptions ro;
        ro.csv = (dir / "trajectory.csv").string();
        node->recording = make_recording(ro, nullptr);
        node->recorded = true;
        Vehicle* raw = node.get();
        transport_.subscribe<msg::ControllerStatus>(node->topics.controller_status,
                                                    [raw](const msg::ControllerStatus& m) { raw->status = m; });
        node->status.header.stamp = msg::Time::from_ns(-1);
      }
      vehicles_.push_back(std::move(node));
    }
    announcer_ = std::make_unique<dds::NodeAnnouncer>(transport_.participant().handle(),
                                                      fmt::format("quadrotor_plants_{}", first));
    announcer_->announce();
  }

  /// Waits for every vehicle's controller, then runs all ticks (drivers::LockstepPlantDriver over
  /// this thread's vehicles). Returns an exit code.
  int run(double timeout_s, const std::string& on_timeout, int divider, sim::Tick duration_ticks) {
    const auto timeout_ns = static_cast<std::int64_t>(timeout_s * 1e9);
    std::size_t ready = 0;
    const bool found = transport_.spin_until(
        [&] {
          // As the single-vehicle plant: a command writer and all three sensor readers matched, so
          // tick 0 is not published before the controller can hear it (that would cost a 50 ms retry).
          while (ready < vehicles_.size()) {
            const sim::Topics& t = vehicles_[ready]->topics;
            if (transport_.matched_writers(t.motor_commands) == 0 || transport_.matched_readers(t.pose) == 0 ||
                transport_.matched_readers(t.velocity) == 0 || transport_.matched_readers(t.imu) == 0) {
              break;
            }
            ++ready;
          }
          return stop_requested() || ready == vehicles_.size();
        },
        timeout_ns);
    if (!found) {
      std::cerr << fmt::format("plant: no controller for {} within {} s ({} of {} vehicles of this thread matched)\n",
                               vehicles_[ready]->topics.motor_commands, timeout_s, ready, vehicles_.size());
      return exit_code::kNoPeer;
    }
    drivers::LockstepOptions lo;
    lo.clock = clock_;
    lo.duration_ticks = duration_ticks;
    lo.controller_divider = divider;
    lo.timeout_ns = timeout_ns;
    lo.on_timeout = on_timeout == "hold" ? drivers::TimeoutPolicy::kHold : drivers::TimeoutPolicy::kAbort;
    // Commands and statuses are taken in on Cyclone's receive thread as they arrive, and this thread
    // runs the ticks, woken once every vehicle's answer is in: the shards' participants share one
    // receive thread, which must not run every shard's ticks.
    lo.ticks_on_delivery = false;
    std::vector<drivers::DrivenPlant> plants;
    for (auto& v : vehicles_) {
      drivers::DrivenPlant p{v->plant.get(), {}, {}};
      if (v->recorded) {  // a recorded vehicle's status is awaited, as the single-vehicle plant's
        Vehicle* raw = v.get();
        p.status_awaited = [this, raw] { return transport_.matched_writers(raw->topics.controller_status) > 0; };
        p.status_stamp_ns = [raw] { return raw->status.header.stamp.to_ns(); };
      }
      plants.push_back(std::move(p));
    }
    drivers::LockstepHooks h;
    h.after_latch = [this](std::size_t i, sim::Tick k) {
      Vehicle& v = *vehicles_[i];
      if (!v.recorded) return;  // a swarm's rows show no watchdog
      v.recording.tick({k, clock_.seconds(k), clock_.ns(k), v.plant->state(), v.plant->latched_command(),
                        v.status.header.stamp.to_ns() >= 0 ? &v.status : nullptr, false});
    };
    h.on_timeout = [&](std::size_t i, sim::Tick k) {
      std::cerr << lockstep_timeout_message(transport_, vehicles_[i]->topics, clock_, k, timeout_s, on_timeout);
    };
    h.on_resume = [](sim::Tick k) {
      std::cerr << fmt::format("plant: commands are back at tick {}; lockstep resumes\n", k);
    };
    drivers::LockstepPlantDriver driver(std::move(plants), lo, std::move(h), host_);
    host_.on_delivery([&driver] { return driver.on_delivery(); });
    start_ns_ = steady_ns();
    const drivers::LockstepResult r = driver.run();
    end_ns_ = steady_ns();
    host_.on_delivery(nullptr);
    for (auto& v : vehicles_) v->recording.finish(r == drivers::LockstepResult::kDone);
    if (r == drivers::LockstepResult::kTimedOut) return exit_code::kNoPeer;
    return r == drivers::LockstepResult::kStopped ? exit_code::kInterrupted : exit_code::kOk;
  }

  SwarmFinal final_of(int i) const {
    const auto& p = *vehicles_[static_cast<std::size_t>(i - first_)]->plant;
    SwarmFinal f;
    f.p_W = p.state().p_W;
    f.rejected = p.stats().commands_rejected;
    return f;
  }
  std::int64_t wall_ns() const { return end_ns_ - start_ns_; }

 private:
  struct Vehicle {
    sim::Topics topics;
    std::unique_ptr<sim::PlantNode> plant;
    bool recorded = false;
    io::Recording recording;  ///< trajectory.csv when recorded
    msg::ControllerStatus status;
  };

  const io::Scenario& sc_;
  sim::TickClock clock_;
  dds::DdsTransport transport_;
  int first_;
  std::vector<std::unique_ptr<Vehicle>> vehicles_;
  std::unique_ptr<dds::NodeAnnouncer> announcer_;
  std::int64_t start_ns_ = 0, end_ns_ = 0;
  DdsDriverHost host_{transport_};
};

// One thread's share of the controllers (drivers::LockstepControllerDriver): each steps where its
// samples are delivered (on Cyclone's receive thread, delivery on arrival), the thread serves only
// discovery meanwhile.
class ControllerShard {
 public:
  ControllerShard(const io::Scenario& sc, const io::SwarmSpec& spec, int first, int last, bool sensor_qos,
                  const std::string& enclave)
      : transport_(dds::read_ros_environment(enclave)) {
    const model::State initial = io::initial_state(sc);
    std::vector<drivers::DrivenController> driven;
    for (int i = first; i < last; ++i) {
      sim::SwarmVehicle v = sim::swarm_vehicle(sc.simulation, initial, sc.controller, sc.schedule, spec.layout, i);
      auto c = std::make_unique<Vehicle>();
      const sim::Topics topics = sim::Topics::for_namespace(v.simulation.ns);
      if (sensor_qos) use_sensor_qos(transport_, topics);
      c->node =
          std::make_unique<sim::ControllerNode>(transport_, topics, v.controller, sim::ControllerNode::SampleFilter{},
                                                v.simulation.plant.realism.extra_sensors);
      driven.push_back({c->node.get(), std::move(v.schedule)});
      vehicles_.push_back(std::move(c));
    }
    driver_ = std::make_unique<drivers::LockstepControllerDriver>(std::move(driven), sc.simulation.plant.clock,
                                                                  sc.simulation.controller_divider, host_);
    announcer_ = std::make_unique<dds::NodeAnnouncer>(transport_.participant().handle(),
                                                      fmt::format("attitude_controllers_{}", first));
    announcer_->announce();
  }

  /// Steps each vehicle once per complete sample of a control tick, as `controller` does.
  int run() {
    try {
      driver_->run();
    } catch (const std::invalid_argument& e) {
      std::cerr << "controller: " << e.what() << '\n';
      return exit_code::kBadInput;
    }
    return exit_code::kOk;
  }

 private:
  struct Vehicle {
    std::unique_ptr<sim::ControllerNode> node;
  };
  dds::DdsTransport transport_;
  DdsDriverHost host_{transport_};
  std::vector<std::unique_ptr<Vehicle>> vehicles_;
  std::unique_ptr<drivers::LockstepControllerDriver> driver_;  ///< after the nodes: unhooks first
  std::unique_ptr<dds::NodeAnnouncer> announcer_;
};

}  // namespace

int run_plant_swarm(const PlantProcessOptions& o, io::Scenario sc) {
  const io::SwarmSpec spec = node_spec(sc, o.swarm.vehicles, o.swarm.ns_prefix);
  const int n = spec.layout.vehicles;
  const int threads = std::clamp(o.swarm.threads, 1, n);
  std::vector<bool> recorded(static_cast<std::size_t>(n), false);
  if (!o.swarm.out.empty()) {
    for (int i : spec.record_vehicles) recorded[static_cast<std::size_t>(i)] = true;
  }
  std::vector<std::unique_ptr<PlantShard>> shards(static_cast<std::size_t>(threads));
  // Participants are created one after the other (Cyclone's domain setup is not worth racing).
  for (int t = 0; t < threads; ++t) {
    shards[static_cast<std::size_t>(t)] = std::make_unique<PlantShard>(
        sc, spec, n * t / threads, n * (t + 1) / threads, recorded, fs::path(o.swarm.out), o.sensor_qos, o.enclave);
  }
  std::cerr << fmt::format("plant: {} vehicles ({}...), {} thread(s), lockstep, {} ticks of {} s\n", n,
                           sim::vehicle_namespace(spec.layout.ns_prefix, 0, n), threads, sc.simulation.duration_ticks,
                           sc.simulation.plant.clock.period_s());
  const int rc = run_threads(threads, [&](int t) {
    return shards[static_cast<std::size_t>(t)]->run(o.timeout_s, o.lockstep_only.on_timeout,
                                                    sc.simulation.controller_divider, sc.simulation.duration_ticks);
  });
  if (rc != exit_code::kOk) return rc;
  std::int64_t wall_ns = 0;
  for (const auto& s : shards) wall_ns = std::max(wall_ns, s->wall_ns());
  const double wall_s = static_cast<double>(wall_ns) / 1e9;
  const double sim_s = sc.simulation.plant.clock.seconds(sc.simulation.duration_ticks);
  std::cerr << fmt::format("plant: done; {} vehicles, {:g} s simulated in {:.3f} s ({:.2f}x real time)\n", n, sim_s,
                           wall_s, sim_s / wall_s);
  if (!o.stats.empty()) {
    write_stats(o.stats,
                {{"vehicles", n}, {"simulated_s", sim_s}, {"wall_s", wall_s}, {"real_time_factor", sim_s / wall_s}});
  }
  if (!o.swarm.out.empty()) {
    std::vector<SwarmFinal> rows(static_cast<std::size_t>(n));
    std::vector<std::string> namespaces(static_cast<std::size_t>(n));
    const model::State initial = io::initial_state(sc);
    for (int t = 0; t < threads; ++t) {
      for (int i = n * t / threads; i < n * (t + 1) / threads; ++i) {
        const sim::SwarmVehicle v =
            sim::swarm_vehicle(sc.simulation, initial, sc.controller, sc.schedule, spec.layout, i);
        SwarmFinal f = shards[static_cast<std::size_t>(t)]->final_of(i);
        // The reference of the last control step: the trajectory's then, or the vehicle's initial
        // setpoint with its whole schedule applied.
        control::NodeSettings node = v.controller.node;
        for (const auto& e : v.schedule) {
          if (control::node_parameters().find(e.name)) (void)control::node_parameters().set(node, e.name, e.value);
        }
        f.p_des_W = node.setpoint.p_des_W;
        if (const auto& trajectory = v.controller.trajectory) {
          const sim::Tick divider = sc.simulation.controller_divider;
          const sim::Tick last_step = sc.simulation.duration_ticks / divider * divider;
          f.p_des_W =
              trajectory->at(sc.simulation.plant.clock.seconds(last_step)).p_W + v.controller.trajectory_offset_W;
        }
        rows[static_cast<std::size_t>(i)] = f;
        namespaces[static_cast<std::size_t>(i)] = v.simulation.ns;
      }
    }
    write_swarm_summary(
        o.swarm.out, sc, spec, namespaces, rows,
        {{"transport", "dds"}, {"threads", threads}, {"wall_s", wall_s}, {"real_time_factor", sim_s / wall_s}},
        std::cout);
  }
  return exit_code::kOk;
}

int run_controller_swarm(const ControllerProcessOptions& o, io::Scenario sc) {
  const io::SwarmSpec spec = node_spec(sc, o.swarm.vehicles, o.swarm.ns_prefix);
  const int n = spec.layout.vehicles;
  const int threads = std::clamp(o.swarm.threads, 1, n);
  if (!o.apply_schedule) sc.schedule.clear();
  const std::int64_t period_ns = sc.simulation.plant.clock.period_ns * sc.simulation.controller_divider;
  std::vector<std::unique_ptr<ControllerShard>> shards;
  for (int t = 0; t < threads; ++t) {
    shards.push_back(
        std::make_unique<ControllerShard>(sc, spec, n * t / threads, n * (t + 1) / threads, o.sensor_qos, o.enclave));
  }
  std::cerr << fmt::format("controller: {} vehicles ({}...), {} thread(s), lockstep, period {} s\n", n,
                           sim::vehicle_namespace(spec.layout.ns_prefix, 0, n), threads,
                           static_cast<double>(period_ns) / 1e9);
  const int rc = run_threads(threads, [&](int t) { return shards[static_cast<std::size_t>(t)]->run(); });
  std::cerr << "controller: stopped\n";
  return rc;
}

}  // namespace quadcosim::hosts
