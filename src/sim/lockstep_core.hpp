// The lockstep tick loop, stated once: N steppable plants advanced tick by tick, each control tick
// waiting for every plant's answer, so the run is deterministic however fast or slow the controllers
// are. drivers::LockstepPlantDriver (drivers/lockstep_plant_driver.hpp) instantiates it over DDS
// (hooks through std::function, plants through sim::SteppablePlant, a drivers::DriverHost);
// sim::Simulation instantiates it for the in-process run (its own hooks and sim::PlantNode, statically
// dispatched and inlined, a synchronous host), so both run the same tick order at no cost in-process.
//
// Per tick k: hooks.before_outputs(k) (a scheduled change), every plant publishes its outputs,
// hooks.after_outputs(k) (a controller stepped on the tick); on control ticks
// (k % controller_divider == 0, from first_control_tick on) the loop waits for the answer of every plant; then each
// plant latches its command, hooks.after_latch(i, k) records it, and the plant integrates to t_k+1 (not after the last
// tick).
//
// The answer to tick k (one rule, for every plant and host):
//   - a command labelled with t_k (msg::command_stamp_ns), or, when the newest command taken carries
//     no label, any command that arrived after tick k's outputs were published;
//   - and, for a plant whose hooks.status_awaited(i) held when the control tick went out, the
//     controller status stamped t_k (hooks.status_stamp_ns(i); a recorder writes it beside the tick).
// A synchronous host (kSynchronous: the in-process transport) delivers within publish_outputs and
// after_outputs, so whatever answers tick k is in when they return and what is not in never comes
// (lost to an injected fault): the loop neither checks nor waits, the plant latches what it has
// (holding the last command, as a zero timeout under kHold would), and there is no wall clock.
//
// Timeouts and hold (asynchronous hosts): a plant still unanswered after retry_ns is asked again (its
// outputs published again: a sample sent while discovery settled may be lost). After timeout_ns
// hooks.on_timeout(i, k) is told; under kAbort run() ends with kTimedOut, under kHold the loop stops
// waiting: it runs the ticks unpaced, holding the last commands (the plants' watchdogs act as
// configured), until every plant has received a command again, when hooks.on_resume(k) is told and
// lockstep resumes. So a vanished controller costs one timeout, not one per tick.
//
// Threading (asynchronous hosts): run() runs on the host's thread. With delivery where answers
// arrive, the host calls on_delivery() after each delivery, never beside run() (the host's executor
// guarantees it: over DDS dds::ArrivalExecutor); with ticks_on_delivery the loop then runs the ticks
// whose answers are in right there, up to the next control tick's answer, so a control period wakes no
// other thread, and wakes the host's thread only when it has work: a tick whose
// hooks.main_thread_due(k) holds (a blocking service call), holding, the end.
//
// What the type parameters provide (all calls static, so a final Plant and inline hooks inline):
//   Plant: publish_outputs(k), latch_command(k), integrate(k), command_receipt() (sim::SteppablePlant);
//   Hooks: bool main_thread_due(k), bool before_outputs(k) (false refuses the run), after_outputs(k),
//          after_latch(i, k), on_timeout(i, k), on_resume(k), bool status_awaited(i),
//          std::int64_t status_stamp_ns(i);
//   Host (asynchronous only): now_ns(), wait(timeout_ns, woken), stop_requested(),
//          deliver_on_arrival(on) (drivers::DriverHost).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "sim/clock.hpp"
#include "sim/steppable_plant.hpp"
#include "util/log_histogram.hpp"

namespace quadcosim::sim {

/// What a lockstep loop does when an answer does not come within its timeout.
enum class TimeoutPolicy {
  kAbort,  ///< end the run (exit code 4 in the app)
  kHold,   ///< hold the last commands and go on unpaced until commands come again
};

struct LockstepOptions {
  TickClock clock;
  Tick duration_ticks = 1500;  ///< last tick
  int controller_divider = 2;  ///< control ticks: k % divider == 0 and k >= first_control_tick
  /// The first tick answered: 0 for a controller that steps on each control tick's samples; one
  /// control period for a timer on ROS time, which first fires one period after it starts.
  Tick first_control_tick = 0;
  std::int64_t timeout_ns = 10'000'000'000;
  TimeoutPolicy on_timeout = TimeoutPolicy::kAbort;
  std::int64_t retry_ns = 50'000'000;  ///< ask again after this long without the answer
  /// Run ticks on the delivering thread when their answer completes (one thread per period), or
  /// only wake the host's thread (a swarm's shards, whose participants share one receive thread).
  bool ticks_on_delivery = true;
};

enum class LockstepResult { kDone, kStopped, kTimedOut, kRefused };

/// A host that delivers nothing asynchronously: the type for kSynchronous instantiations.
struct SynchronousHost {};

template <class Plant, class Hooks, class Host, bool kSynchronous>
class LockstepCore {
 public:
  /// `plants` and `host` must outlive the loop.
  LockstepCore(std::vector<Plant*> plants, const LockstepOptions& options, Hooks hooks, Host& host)
      : plants_(std::move(plants)), slots_(plants_.size()), o_(options), hooks_(std::move(hooks)), host_(host) {
    if constexpr (!kSynchronous) round_trips_ns_ = std::make_unique<util::LogHistogram>();
  }
  LockstepCore(const LockstepCore&) = delete;
  LockstepCore& operator=(const LockstepCore&) = delete;

  /// Synchronous hosts: tick k whole (outputs, latch, record, integrate). Call with k = 0, 1, ... in
  /// order (a swarm advances many loops tick by tick, or block by block). Returns false when
  /// before_outputs refused it (nothing else ran).
  bool tick(Tick k) {
    static_assert(kSynchronous, "asynchronous hosts run ticks through run() and on_delivery()");
    if (!publish(k)) return false;
    end_tick(k);
    k_ = k + 1;
    return true;
  }

  /// Runs the ticks from the next one to duration_ticks (or to a stop, a timeout under kAbort, a
  /// refusal).
  LockstepResult run() {
    if constexpr (kSynchronous) {
      for (; k_ <= o_.duration_ticks; ++k_) {
        if (!publish(k_)) return LockstepResult::kRefused;
        end_tick(k_);
      }
      return LockstepResult::kDone;
    } else {
      host_.deliver_on_arrival(true);
      struct Off {  // also when a hook throws
        Host& h;
        ~Off() { h.deliver_on_arrival(false); }
      } off{host_};
      for (;;) {
        phase_ = advance(false);
        if (phase_ == Phase::kRefused) return LockstepResult::kRefused;
        if (phase_ == Phase::kDone) {
          return host_.stop_requested() ? LockstepResult::kStopped : LockstepResult::kDone;
        }
        if (host_.stop_requested()) return LockstepResult::kStopped;
        if (!await_progress()) return LockstepResult::kTimedOut;
      }
    }
  }

  /// Asynchronous hosts: after each delivery, on the delivering thread (see Threading above).
  /// Returns true when the host's waiting thread is to wake.
  bool on_delivery() {
    static_assert(!kSynchronous, "a synchronous host has no deliveries of its own");
    // Not inside advance: a plant's own publications may reach its own host's readers at once.
    if (advancing_ || !waiting_ || phase_ != Phase::kAwaiting || !published_ || !all_answered(k_)) return false;
    if (!o_.ticks_on_delivery) return true;
    phase_ = advance(true);
    return phase_ != Phase::kAwaiting;  // wake the host's thread only when it has work
  }

  /// Ticks completed (latched, recorded, integrated but for the last).
  Tick ticks_run() const { return k_; }
  /// Outputs published -> every answer in, per awaited control tick [ns, wall clock]; none when
  /// synchronous.
  /// Lockstep round trips [ns] (outputs published -> every command back), one per control period; in
  /// fixed memory however long the run. Empty for a synchronous loop.
  const util::LogHistogram& round_trips_ns() const {
    static const util::LogHistogram kNone;
    return round_trips_ns_ ? *round_trips_ns_ : kNone;
  }
  /// False while holding after a timeout.
  bool awaiting_answers() const { return waiting_; }
  Hooks& hooks() { return hooks_; }

 private:
  enum class Phase { kAwaiting, kMainThread, kDone, kRefused };
  struct Slot {
    std::uint64_t received_before = 0;  ///< commands received before k_'s outputs went out
    bool status_expected = false;       ///< status_awaited() when k_ (a control tick) went out
  };

  /// before_outputs(k), every plant's outputs, after_outputs(k); false when refused.
  bool publish(Tick k) {
    if (!hooks_.before_outputs(k)) return false;
    // Outputs between control ticks wait for the next control tick's (sent with them), while the
    // answers are awaited: nothing waits for them before then.
    // A control tick's outputs are sent as they are written: each writer's send takes what it held.
    const bool hold = waiting_ && !(k % o_.controller_divider == 0 && k >= o_.first_control_tick);
    if constexpr (!kSynchronous) {
      if (hold) host_.hold_outputs(true);
    }
    for (std::size_t i = 0; i < plants_.size(); ++i) {
      if constexpr (!kSynchronous) slots_[i].received_before = plants_[i]->command_receipt().received;
      plants_[i]->publish_outputs(k);
    }
    if constexpr (!kSynchronous) {
      if (!hold) host_.hold_outputs(false);  // what no write of this tick took
    }
    hooks_.after_outputs(k);
    return true;
  }

  void end_tick(Tick k) {
    for (std::size_t i = 0; i < plants_.size(); ++i) {
      Plant& p = *plants_[i];
      p.latch_command(k);
      hooks_.after_latch(i, k);
      if (k < o_.duration_ticks) p.integrate(k);
    }
  }

  Phase advance(bool on_delivery) {
    advancing_ = true;
    struct Done {
      bool& f;
      ~Done() { f = false; }
    } done{advancing_};
    return advance_ticks(on_delivery);
  }

  Phase advance_ticks(bool on_delivery) {
    for (;;) {
      const Tick k = k_;
      const bool control = k % o_.controller_divider == 0 && k >= o_.first_control_tick;
      if (!published_) {
        if (k > o_.duration_ticks || host_.stop_requested()) {
          if constexpr (!kSynchronous) host_.hold_outputs(false);
          return Phase::kDone;
        }
        if (on_delivery && (!waiting_ || hooks_.main_thread_due(k))) return Phase::kMainThread;
        if (!publish(k)) return Phase::kRefused;
        asked_ns_ = last_ask_ns_ = host_.now_ns();
        published_ = true;
        answered_ = 0;
        if (!waiting_) collect_while_holding(k);
        if (waiting_ && control) {
          for (std::size_t i = 0; i < plants_.size(); ++i) slots_[i].status_expected = hooks_.status_awaited(i);
        }
      }
      if (waiting_ && control) {
        if (!all_answered(k)) return Phase::kAwaiting;
        round_trips_ns_->record(host_.now_ns() - asked_ns_);
      }
      end_tick(k);
      ++k_;
      published_ = false;
    }
  }

  bool answered(std::size_t i, Tick k) const {
    const Slot& s = slots_[i];
    const std::int64_t t_ns = o_.clock.ns(k);
    const CommandReceipt r = plants_[i]->command_receipt();
    const bool command = r.label_ns == t_ns || (r.label_ns < 0 && r.received > s.received_before);
    return command && (!s.status_expected || hooks_.status_stamp_ns(i) == t_ns);
  }

  bool all_answered(Tick k) {
    // Plants answer in any order: the answered prefix is not asked again.
    while (answered_ < plants_.size() && answered(answered_, k)) ++answered_;
    return answered_ == plants_.size();
  }

  void collect_while_holding(Tick k) {
    host_.wait(0, {});
    for (std::size_t i = 0; i < plants_.size(); ++i) {
      if (plants_[i]->command_receipt().received <= slots_[i].received_before) return;
    }
    waiting_ = true;
    host_.deliver_on_arrival(true);
    hooks_.on_resume(k);
  }

  bool await_progress() {
    const auto woken = [this] { return phase_ != Phase::kAwaiting || host_.stop_requested() || all_answered(k_); };
    while (phase_ == Phase::kAwaiting && !host_.stop_requested() && !all_answered(k_)) {
      const std::int64_t now = host_.now_ns();
      if (now - asked_ns_ >= o_.timeout_ns) {
        hooks_.on_timeout(answered_, k_);
        if (o_.on_timeout == TimeoutPolicy::kAbort) return false;
        waiting_ = false;  // hold the last commands and go on, taking commands in between ticks
        host_.deliver_on_arrival(false);
        return true;
      }
      if (now - last_ask_ns_ >= o_.retry_ns) {
        for (std::size_t i = answered_; i < plants_.size(); ++i) {
          if (!answered(i, k_)) plants_[i]->publish_outputs(k_);
        }
        last_ask_ns_ = now;
      }
      // Not woken per tick the delivering thread runs: this thread looks again at the latest k_.
      host_.wait(last_ask_ns_ + o_.retry_ns - now, woken);
    }
    return true;
  }

  std::vector<Plant*> plants_;
  std::vector<Slot> slots_;
  LockstepOptions o_;
  Hooks hooks_;
  Host& host_;
  // Shared by the host's thread and the delivering thread (never at once: see Threading).
  Phase phase_ = Phase::kAwaiting;
  Tick k_ = 0;                                   ///< the tick in progress
  bool published_ = false;                       ///< k_'s outputs are out
  bool advancing_ = false;                       ///< inside advance (a plant's own publications may be delivered to it)
  bool waiting_ = true;                          ///< answers awaited (off while holding)
  std::size_t answered_ = 0;                     ///< plants [0, answered_) have answered k_
  std::int64_t asked_ns_ = 0, last_ask_ns_ = 0;  ///< k_ first / last published [wall ns]
  std::unique_ptr<util::LogHistogram> round_trips_ns_;  ///< asynchronous loops only (30 kB)
};

}  // namespace quadcosim::sim
