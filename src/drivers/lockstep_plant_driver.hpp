// The lockstep driver: N steppable plants (one vehicle, or a swarm's share) advanced tick by tick,
// each control tick waiting for every plant's answer, so the run is deterministic however fast or
// slow the controllers are. It is sim::LockstepCore (sim/lockstep_core.hpp states the tick order, the
// answer rule, timeouts, hold and threading) over a DriverHost that delivers asynchronously (DDS, a
// test's queue), with plants through sim::SteppablePlant and hooks through std::function; the
// in-process run (sim::Simulation) is the same core over a synchronous host.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "drivers/driver_host.hpp"
#include "sim/clock.hpp"
#include "sim/lockstep_core.hpp"
#include "sim/steppable_plant.hpp"

namespace quadcosim::drivers {

using sim::LockstepOptions;
using sim::LockstepResult;
using sim::TimeoutPolicy;
/// "abort" | "hold".
std::string to_string(TimeoutPolicy p);

/// One plant as the driver sees it.
struct DrivenPlant {
  sim::SteppablePlant* plant = nullptr;
  /// Asked as a control tick's outputs go out: whether the answer includes a status (empty: never).
  std::function<bool()> status_awaited;
  /// Stamp [ns] of the newest controller status received (-1 before one); used with status_awaited.
  std::function<std::int64_t()> status_stamp_ns;
};

struct LockstepHooks {
  /// True when tick k needs the host's own thread before its outputs go out (e.g. a scheduled
  /// change through a blocking service call); on the delivering thread the driver then stops there.
  std::function<bool(sim::Tick)> main_thread_due;
  /// Before tick k's outputs go out, on whichever thread runs the tick (the host's when
  /// main_thread_due(k)); false refuses the run (run() returns kRefused).
  std::function<bool(sim::Tick)> before_outputs;
  /// After plant i latched tick k's command, before it integrates: record, log.
  std::function<void(std::size_t, sim::Tick)> after_latch;
  /// Plant i's answer to tick k did not come within the timeout (before the policy acts).
  std::function<void(std::size_t, sim::Tick)> on_timeout;
  /// Under hold, commands came again at tick k: lockstep resumes.
  std::function<void(sim::Tick)> on_resume;
};

class LockstepPlantDriver {
 public:
  LockstepPlantDriver(std::vector<DrivenPlant> plants, const LockstepOptions& options, LockstepHooks hooks,
                      DriverHost& host);
  LockstepPlantDriver(const LockstepPlantDriver&) = delete;
  LockstepPlantDriver& operator=(const LockstepPlantDriver&) = delete;

  /// Runs ticks 0..duration_ticks (or to a stop, a timeout under kAbort, a refusal).
  LockstepResult run() { return core_.run(); }
  /// After each delivery, on the delivering thread (see Threading in sim/lockstep_core.hpp). Returns
  /// true when the host's waiting thread is to wake.
  bool on_delivery() { return core_.on_delivery(); }

  /// Ticks completed (latched, recorded, integrated but for the last).
  sim::Tick ticks_run() const { return core_.ticks_run(); }
  /// Outputs published -> every answer in, per awaited control tick [ns, wall clock].
  const util::LogHistogram& round_trips_ns() const { return core_.round_trips_ns(); }

 private:
  /// LockstepHooks and the plants' status functions as sim::LockstepCore calls them (empty: nothing).
  struct Hooks {
    LockstepHooks h;
    std::vector<DrivenPlant> plants;
    bool main_thread_due(sim::Tick k) const { return h.main_thread_due && h.main_thread_due(k); }
    bool before_outputs(sim::Tick k) const { return !h.before_outputs || h.before_outputs(k); }
    void after_outputs(sim::Tick /*k*/) const {}
    void after_latch(std::size_t i, sim::Tick k) const {
      if (h.after_latch) h.after_latch(i, k);
    }
    void on_timeout(std::size_t i, sim::Tick k) const {
      if (h.on_timeout) h.on_timeout(i, k);
    }
    void on_resume(sim::Tick k) const {
      if (h.on_resume) h.on_resume(k);
    }
    bool status_awaited(std::size_t i) const { return plants[i].status_awaited && plants[i].status_awaited(); }
    std::int64_t status_stamp_ns(std::size_t i) const { return plants[i].status_stamp_ns(); }
  };
  static std::vector<sim::SteppablePlant*> plant_pointers(const std::vector<DrivenPlant>& plants);

  sim::LockstepCore<sim::SteppablePlant, Hooks, DriverHost, false> core_;
};

}  // namespace quadcosim::drivers
