#include "drivers/lockstep_plant_driver.hpp"

#include <utility>

namespace quadcosim::drivers {

std::string to_string(TimeoutPolicy p) { return p == TimeoutPolicy::kHold ? "hold" : "abort"; }

LockstepPlantDriver::LockstepPlantDriver(std::vector<DrivenPlant> plants, const LockstepOptions& options,
                                         LockstepHooks hooks, DriverHost& host)
    : o_(options), hooks_(std::move(hooks)), host_(host) {
  plants_.reserve(plants.size());
  for (DrivenPlant& p : plants) plants_.push_back(Slot{std::move(p)});
  round_trips_ns_.reserve(static_cast<std::size_t>(o_.duration_ticks / o_.controller_divider + 1));
}

LockstepResult LockstepPlantDriver::run() {
  host_.deliver_on_arrival(true);
  struct Off {  // also when a hook throws
    DriverHost& h;
    ~Off() { h.deliver_on_arrival(false); }
  } off{host_};
  for (;;) {
    phase_ = advance(false);
    if (phase_ == Phase::kRefused) return LockstepResult::kRefused;
    if (phase_ == Phase::kDone) return host_.stop_requested() ? LockstepResult::kStopped : LockstepResult::kDone;
    if (host_.stop_requested()) return LockstepResult::kStopped;
    if (!await_progress()) return LockstepResult::kTimedOut;
  }
}

bool LockstepPlantDriver::on_delivery() {
  // Not inside advance: a plant's own publications may reach its own host's readers at once.
  if (advancing_ || !waiting_ || phase_ != Phase::kAwaiting || !published_ || !all_answered(k_)) return false;
  if (!o_.ticks_on_delivery) return true;
  phase_ = advance(true);
  return phase_ != Phase::kAwaiting;  // wake the host's thread only when it has work
}

LockstepPlantDriver::Phase LockstepPlantDriver::advance(bool on_delivery) {
  advancing_ = true;
  struct Done {
    bool& f;
    ~Done() { f = false; }
  } done{advancing_};
  return advance_ticks(on_delivery);
}

LockstepPlantDriver::Phase LockstepPlantDriver::advance_ticks(bool on_delivery) {
  for (;;) {
    const sim::Tick k = k_;
    const bool control = k % o_.controller_divider == 0;
    if (!published_) {
      if (k > o_.duration_ticks || host_.stop_requested()) return Phase::kDone;
      if (on_delivery && (!waiting_ || (hooks_.main_thread_due && hooks_.main_thread_due(k)))) {
        return Phase::kMainThread;
      }
      if (hooks_.before_outputs && !hooks_.before_outputs(k)) return Phase::kRefused;
      for (Slot& s : plants_) {
        s.received_before = s.p.plant->command_receipt().received;
        s.p.plant->publish_outputs(k);
      }
      asked_ns_ = last_ask_ns_ = host_.now_ns();
      published_ = true;
      answered_ = 0;
      if (!waiting_) collect_while_holding(k);
      if (waiting_ && control) {
        for (Slot& s : plants_) s.status_expected = s.p.status_awaited && s.p.status_awaited();
      }
    }
    if (waiting_ && control) {
      if (!all_answered(k)) return Phase::kAwaiting;
      round_trips_ns_.push_back(host_.now_ns() - asked_ns_);
    }
    end_tick(k);
    ++k_;
    published_ = false;
  }
}

bool LockstepPlantDriver::answered(std::size_t i, sim::Tick k) const {
  const Slot& s = plants_[i];
  const std::int64_t t_ns = o_.clock.ns(k);
  const sim::CommandReceipt r = s.p.plant->command_receipt();
  const bool command = r.label_ns == t_ns || (r.label_ns < 0 && r.received > s.received_before);
  return command && (!s.status_expected || s.p.status_stamp_ns() == t_ns);
}

bool LockstepPlantDriver::all_answered(sim::Tick k) {
  // Plants answer in any order: the answered prefix is not asked again.
  while (answered_ < plants_.size() && answered(answered_, k)) ++answered_;
  return answered_ == plants_.size();
}

void LockstepPlantDriver::collect_while_holding(sim::Tick k) {
  host_.wait(0, {});
  for (const Slot& s : plants_) {
    if (s.p.plant->command_receipt().received <= s.received_before) return;
  }
  waiting_ = true;
  host_.deliver_on_arrival(true);
  if (hooks_.on_resume) hooks_.on_resume(k);
}

bool LockstepPlantDriver::await_progress() {
  const auto woken = [this] { return phase_ != Phase::kAwaiting || host_.stop_requested() || all_answered(k_); };
  while (phase_ == Phase::kAwaiting && !host_.stop_requested() && !all_answered(k_)) {
    const std::int64_t now = host_.now_ns();
    if (now - asked_ns_ >= o_.timeout_ns) {
      if (hooks_.on_timeout) hooks_.on_timeout(answered_, k_);
      if (o_.on_timeout == TimeoutPolicy::kAbort) return false;
      waiting_ = false;  // hold the last commands and go on, taking commands in between ticks
      host_.deliver_on_arrival(false);
      return true;
    }
    if (now - last_ask_ns_ >= o_.retry_ns) {
      for (std::size_t i = answered_; i < plants_.size(); ++i) {
        if (!answered(i, k_)) plants_[i].p.plant->publish_outputs(k_);
      }
      last_ask_ns_ = now;
    }
    // Not woken per tick the delivering thread runs: this thread looks again at the latest k_.
    host_.wait(last_ask_ns_ + o_.retry_ns - now, woken);
  }
  return true;
}

void LockstepPlantDriver::end_tick(sim::Tick k) {
  for (std::size_t i = 0; i < plants_.size(); ++i) {
    sim::SteppablePlant& p = *plants_[i].p.plant;
    p.latch_command(k);
    if (hooks_.after_latch) hooks_.after_latch(i, k);
    if (k < o_.duration_ticks) p.integrate(k);
  }
}

}  // namespace quadcosim::drivers
