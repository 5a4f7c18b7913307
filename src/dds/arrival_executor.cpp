#include "dds/arrival_executor.hpp"

#include <chrono>
#include <stdexcept>
#include <string>
#include <utility>

namespace quadcosim::dds {

ArrivalExecutor::ArrivalExecutor(DdsTransport& transport) : transport_(transport), owner_(std::this_thread::get_id()) {
  if (transport_.arrival_sink_) throw std::logic_error("ArrivalExecutor: a second executor on one transport");
  wake_ = Entity(check(dds_create_guardcondition(transport_.participant().handle()), "dds_create_guardcondition"));
  // wait() resets the guard itself, right after its wait.
  wake_work_ = transport_.add_extra_work({wake_.get()}, [] {});
  mutex_.lock();  // held by the owner but in its waits
  try {
    transport_.set_arrival_sink([this](std::size_t i) { on_data(i); });
  } catch (...) {  // no executor then: undo what was set up (the destructor will not run; wake_ goes)
    mutex_.unlock();
    transport_.remove_extra_work(wake_work_);
    throw;
  }
  // What came before the listeners. A delivery that throws is kept as on_data keeps it (the sink
  // is set: throwing out of here would leave it pointing at this executor): the first wait()
  // rethrows it, the rest is dropped.
  try {
    for (std::size_t i = 0; i < transport_.subscription_count(); ++i) delivered_ += transport_.take(i);
  } catch (...) {
    failure_ = std::current_exception();
    dds_set_guardcondition(wake_, true);
  }
}

ArrivalExecutor::~ArrivalExecutor() {
  take_noted(false);  // held samples are data: delivered, not dropped (a failure now is not reported)
  mutex_.unlock();    // then deliveries on arrival until the listeners go
  try {
    transport_.set_arrival_sink(nullptr);
  } catch (const std::exception&) {  // DdsError: the participant's deletion removes the listeners too
  }
  mutex_.lock();  // what a delivery found the lock taken for meanwhile
  take_noted(false);
  mutex_.unlock();
  transport_.remove_extra_work(wake_work_);  // then wake_ goes, with the members
}

void ArrivalExecutor::check_owner(const char* what) const {
  if (std::this_thread::get_id() != owner_) {
    throw std::logic_error(std::string("ArrivalExecutor::") + what +
                           " called from a thread other than the one that created the executor");
  }
}

void ArrivalExecutor::after_each(std::function<bool()> hook) {
  check_owner("after_each");
  after_ = std::move(hook);
}

void ArrivalExecutor::on_data(std::size_t subscription) {
  const bool owner = std::this_thread::get_id() == owner_;
  std::unique_lock<std::recursive_mutex> g(mutex_, std::defer_lock);
  if (owner) {
    g.lock();  // the owner's own local delivery: it holds the lock already (it is recursive)
  } else if (!g.try_lock()) {
    std::vector<DdsTransport::Held> taken;  // out of the reader: its history depth drops nothing
    std::exception_ptr failed;
    try {
      transport_.hold(subscription, taken);
    } catch (...) {
      failed = std::current_exception();
    }
    {
      const std::lock_guard<std::mutex> n(noted_mutex_);
      noted_.insert(noted_.end(), taken.begin(), taken.end());
      if (failed && !noted_failure_) noted_failure_ = failed;
    }
    dds_set_guardcondition(wake_, true);
    return;
  }
  if (owner || depth_ > 0) {
    take_noted_of(subscription);  // the reader's own order: what it held comes first
  } else {
    take_noted(false);  // a receive thread's outermost delivery: what was held before it is older
  }
  deliver(subscription);
  if (!owner && depth_ == 0) take_noted(false);  // held while this one ran
}

template <class Take>
bool ArrivalExecutor::delivery(Take take) {
  ++depth_;
  try {
    delivered_ += take();
  } catch (...) {
    failure_ = std::current_exception();
  }
  --depth_;
  return after_delivery();
}

bool ArrivalExecutor::deliver(std::size_t subscription) {
  if (failure_) return true;  // delivery stopped; wait() rethrows
  return delivery([&] { return transport_.take(subscription); });
}

bool ArrivalExecutor::deliver(DdsTransport::Held& held) {
  if (failure_) {  // delivery stopped: the memory goes back
    transport_.drop_held(held);
    return true;
  }
  return delivery([&] { return transport_.deliver_held(held); });
}

bool ArrivalExecutor::next_noted(DdsTransport::Held& held, const std::size_t* only) {
  const std::lock_guard<std::mutex> n(noted_mutex_);
  if (noted_failure_ && !failure_) failure_ = std::exchange(noted_failure_, nullptr);
  for (auto it = noted_.begin(); it != noted_.end(); ++it) {
    if (only != nullptr && it->index != *only) continue;
    held = *it;
    noted_.erase(it);
    return true;
  }
  return false;
}

bool ArrivalExecutor::take_noted(bool stop_at_wake) {
  DdsTransport::Held held;
  while (next_noted(held, nullptr)) {
    if (deliver(held) && stop_at_wake) return true;
  }
  return false;
}

void ArrivalExecutor::take_noted_of(std::size_t subscription) {
  DdsTransport::Held held;
  while (next_noted(held, &subscription)) deliver(held);
}

bool ArrivalExecutor::after_delivery() {
  bool wake = static_cast<bool>(failure_);
  if (!wake) {
    try {
      if (after_) wake = after_();
      if (until_ && (*until_)()) wake = true;
    } catch (...) {
      failure_ = std::current_exception();
      wake = true;
    }
  }
  if (wake) dds_set_guardcondition(wake_, true);
  return wake;
}

int ArrivalExecutor::wait(std::int64_t timeout_ns) {
  check_owner("wait");
  // What came while the owner worked, before anything newer; a delivery of it that wakes the
  // owner ends this wait at once (the rest stay noted for the next).
  const bool woken = take_noted(true);
  mutex_.unlock();
  const dds_return_t rc = transport_.wait_waitset(woken ? 0 : timeout_ns);
  mutex_.lock();
  dds_set_guardcondition(wake_, false);
  if (!woken) take_noted(true);
  if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
  const int served = transport_.serve_wait(rc);  // extra work (no subscription is on the waitset)
  return std::exchange(delivered_, 0) + served;
}

bool ArrivalExecutor::wait_until(const std::function<bool()>& done, std::int64_t timeout_ns) {
  check_owner("wait_until");
  struct Until {  // a delivery that makes `done` hold ends the wait (after_delivery asks it)
    const std::function<bool()>*& slot;
    const std::function<bool()>* saved;
    ~Until() { slot = saved; }
  } until{until_, std::exchange(until_, &done)};
  using clock = std::chrono::steady_clock;
  const auto deadline = clock::now() + std::chrono::nanoseconds(timeout_ns);
  while (!done()) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - clock::now()).count();
    if (left <= 0) return done();
    wait(left);
  }
  return true;
}

}  // namespace quadcosim::dds
