// The lockstep driver: N steppable plants (one vehicle, or a swarm's share) advanced tick by tick,
// each control tick waiting for every plant's answer, so the run is deterministic however fast or
// slow the controllers are. The same driver runs in-process and over DDS; where the answers come
// from is the host's business (drivers/driver_host.hpp).
//
// Per tick k: the host's before_outputs(k) (a scheduled change), every plant publishes its outputs;
// on control ticks (k % controller_divider == 0) the driver waits for the answer of every plant;
// then each plant latches its command, after_latch(i, k) records it, and the plant integrates to
// t_k+1 (not after the last tick).
//
// The answer to tick k (one rule, for every plant and host):
//   - a command labelled with t_k (msg::command_stamp_ns), or, when the newest command taken carries
//     no label, any command that arrived after tick k's outputs were published;
//   - and, for a plant whose status_awaited() held when the control tick went out, the controller
//     status stamped t_k (a recorder writes it beside the tick).
// Timeouts and hold: a plant still unanswered after retry_ns is asked again (its outputs published
// again: a sample sent while discovery settled may be lost). After timeout_ns on_timeout(i, k) is
// told; under kAbort run() ends with kTimedOut, under kHold the driver stops waiting: it runs the
// ticks unpaced, holding the last commands (the plants' watchdogs act as configured), until every
// plant has received a command again, when on_resume(k) is told and lockstep resumes. So a vanished
// controller costs one timeout, not one per tick.
//
// Threading: run() runs on the host's thread. With delivery where answers arrive, the host calls
// on_delivery() after each delivery, never beside run() (the host's executor guarantees it: over DDS
// dds::ArrivalExecutor); with ticks_on_delivery the driver then runs the ticks whose answers are in
// right there, up to the next control tick's answer, so a control period wakes no other thread, and
// wakes the host's thread only when it has work: a tick whose main_thread_due(k) holds (a blocking
// service call), holding, the end.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "drivers/driver_host.hpp"
#include "sim/clock.hpp"
#include "sim/steppable_plant.hpp"

namespace quadcosim::drivers {

/// What a lockstep driver does when an answer does not come within its timeout.
enum class TimeoutPolicy {
  kAbort,  ///< end the run (exit code 4 in the app)
  kHold,   ///< hold the last commands and go on unpaced until commands come again
};
/// "abort" | "hold".
std::string to_string(TimeoutPolicy p);

struct LockstepOptions {
  sim::TickClock clock;
  sim::Tick duration_ticks = 1500;  ///< last tick
  int controller_divider = 2;       ///< control ticks: k % divider == 0
  std::int64_t timeout_ns = 10'000'000'000;
  TimeoutPolicy on_timeout = TimeoutPolicy::kAbort;
  std::int64_t retry_ns = 50'000'000;  ///< ask again after this long without the answer
  /// Run ticks on the delivering thread when their answer completes (one thread per period), or
  /// only wake the host's thread (a swarm's shards, whose participants share one receive thread).
  bool ticks_on_delivery = true;
};

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

enum class LockstepResult { kDone, kStopped, kTimedOut, kRefused };

class LockstepPlantDriver {
 public:
  LockstepPlantDriver(std::vector<DrivenPlant> plants, const LockstepOptions& options, LockstepHooks hooks,
                      DriverHost& host);
  LockstepPlantDriver(const LockstepPlantDriver&) = delete;
  LockstepPlantDriver& operator=(const LockstepPlantDriver&) = delete;

  /// Runs ticks 0..duration_ticks (or to a stop, a timeout under kAbort, a refusal).
  LockstepResult run();
  /// After each delivery, on the delivering thread (see Threading above). Returns true when the
  /// host's waiting thread is to wake.
  bool on_delivery();

  /// Ticks completed (latched, recorded, integrated but for the last).
  sim::Tick ticks_run() const { return k_; }
  /// Outputs published -> every answer in, per awaited control tick [ns, wall clock].
  const std::vector<std::int64_t>& round_trips_ns() const { return round_trips_ns_; }

 private:
  enum class Phase { kAwaiting, kMainThread, kDone, kRefused };
  Phase advance(bool on_delivery);
  Phase advance_ticks(bool on_delivery);
  bool answered(std::size_t i, sim::Tick k) const;
  bool all_answered(sim::Tick k);
  bool await_progress();
  void collect_while_holding(sim::Tick k);
  void end_tick(sim::Tick k);

  struct Slot {
    DrivenPlant p;
    std::uint64_t received_before = 0;  ///< commands received before k_'s outputs went out
    bool status_expected = false;       ///< status_awaited() when k_ (a control tick) went out
  };
  std::vector<Slot> plants_;
  LockstepOptions o_;
  LockstepHooks hooks_;
  DriverHost& host_;
  // Shared by the host's thread and the delivering thread (never at once: see Threading).
  Phase phase_ = Phase::kAwaiting;
  sim::Tick k_ = 0;          ///< the tick in progress
  bool published_ = false;   ///< k_'s outputs are out
  bool advancing_ = false;   ///< inside advance (a plant's own publications may be delivered to it)
  bool waiting_ = true;      ///< answers awaited (off while holding)
  std::size_t answered_ = 0;  ///< plants [0, answered_) have answered k_
  std::int64_t asked_ns_ = 0, last_ask_ns_ = 0;  ///< k_ first / last published [wall ns]
  std::vector<std::int64_t> round_trips_ns_;
};

}  // namespace quadcosim::drivers
