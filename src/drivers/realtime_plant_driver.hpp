// The real-time driver: N steppable plants advanced on the wall clock, one tick per plant period
// (divided by rate_factor), without waiting for anyone: a command acts from the tick it arrived
// in, and a controller that falls silent is the plants' watchdogs' business. Per tick k: the host's
// before_outputs(k) (a scheduled change), every plant publishes its outputs, the host takes in
// deliveries until the tick's wall time, then each plant latches its command, after_latch(i, k)
// records it, and the plant integrates (not after the last tick). In-process or over DDS alike.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "drivers/driver_host.hpp"
#include "sim/clock.hpp"
#include "sim/steppable_plant.hpp"

namespace quadcosim::drivers {

struct RealtimeOptions {
  sim::TickClock clock;
  sim::Tick duration_ticks = 1500;  ///< last tick
  double rate_factor = 1.0;         ///< wall period = plant period / rate_factor
};

struct RealtimeHooks {
  /// Before tick k's outputs go out; false refuses the run.
  std::function<bool(sim::Tick)> before_outputs;
  /// After plant i latched tick k's command, before it integrates.
  std::function<void(std::size_t, sim::Tick)> after_latch;
};

enum class RealtimeResult { kDone, kStopped, kRefused };

class RealtimePlantDriver {
 public:
  RealtimePlantDriver(std::vector<sim::SteppablePlant*> plants, const RealtimeOptions& options, RealtimeHooks hooks,
                      DriverHost& host);
  /// Runs ticks 0..duration_ticks paced from now (or until a stop or a refusal).
  RealtimeResult run();

  /// Ticks completed.
  sim::Tick ticks_run() const { return ticks_run_; }
  /// The latest the loop reached a tick's wall time [ns].
  std::int64_t max_late_ns() const { return max_late_ns_; }
  /// Ticks reached more than one wall period late (a stalled loop, e.g. under a flood of messages).
  std::int64_t late_ticks() const { return late_ticks_; }

 private:
  void pace();
  std::vector<sim::SteppablePlant*> plants_;
  RealtimeOptions o_;
  RealtimeHooks hooks_;
  DriverHost& host_;
  std::int64_t wall_period_ns_;
  std::int64_t next_wall_ns_ = 0;
  sim::Tick ticks_run_ = 0;
  std::int64_t max_late_ns_ = 0;
  std::int64_t late_ticks_ = 0;
};

}  // namespace quadcosim::drivers
