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
  mutex_.unlock();  // first: removing a listener waits for its delivery, which needs the lock
  try {
    transport_.set_arrival_sink(nullptr);
  } catch (const std::exception&) {  // DdsError: the participant's deletion removes the listeners too
  }
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
  const std::lock_guard<std::recursive_mutex> g(mutex_);
  if (failure_) return;  // delivery stopped; wait() rethrows
  try {
    delivered_ += transport_.take(subscription);
  } catch (...) {
    failure_ = std::current_exception();
  }
  after_delivery();
}

void ArrivalExecutor::after_delivery() {
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
}

int ArrivalExecutor::wait(std::int64_t timeout_ns) {
  check_owner("wait");
  mutex_.unlock();
  const dds_return_t rc = transport_.wait_waitset(timeout_ns);
  mutex_.lock();
  dds_set_guardcondition(wake_, false);
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
