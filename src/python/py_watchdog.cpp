// python/py_watchdog.hpp: the thread that enforces step_timeout_s.
#include "python/py_watchdog.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include "python/py_runtime.hpp"

namespace quadcosim::python {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

namespace {

class Watchdog {
 public:
  static Watchdog& get() {
    static Watchdog* w = new Watchdog;  // never destroyed: its thread may outlive static destruction
    return *w;
  }

  void add(const std::shared_ptr<PyController::Watch>& watch) {
    {
      const std::lock_guard lock(mutex_);
      watches_.push_back(watch);
      if (!started_) {
        std::thread([this] { loop(); }).detach();
        started_ = true;
      }
    }
    wake_.notify_one();
  }

 private:
  void loop() {
    std::unique_lock lock(mutex_);
    for (;;) {
      std::int64_t shortest = std::numeric_limits<std::int64_t>::max();
      std::erase_if(watches_, [](const auto& w) { return w.expired(); });
      for (const auto& weak : watches_) {
        if (auto w = weak.lock(); w && w->timeout_ns.load() > 0) shortest = std::min(shortest, w->timeout_ns.load());
      }
      if (watches_.empty()) {
        wake_.wait(lock);
        continue;
      }
      const std::int64_t poll_ns = shortest == std::numeric_limits<std::int64_t>::max()
                                       ? 50'000'000
                                       : std::clamp<std::int64_t>(shortest / 10, 1'000'000, 50'000'000);
      wake_.wait_for(lock, std::chrono::nanoseconds(poll_ns));
      const std::int64_t now = now_ns();
      std::vector<std::shared_ptr<PyController::Watch>> overdue;
      for (const auto& weak : watches_) {
        auto w = weak.lock();
        if (!w) continue;
        const std::int64_t deadline = w->deadline_ns.load(std::memory_order_acquire);
        if (deadline != 0 && now > deadline) overdue.push_back(std::move(w));
      }
      if (overdue.empty()) continue;
      lock.unlock();
      for (const auto& w : overdue) fire(*w);
      lock.lock();
    }
  }

  static void fire(PyController::Watch& w) {
    if (!python_alive()) return;
    const PyGILState_STATE state = PyGILState_Ensure();
    // Under the GIL the stepping thread is either inside its step (the deadline set, possibly in a
    // C call without the GIL) or outside it (the deadline cleared before it released the GIL): the
    // exception never lands outside the step.
    const std::int64_t deadline = w.deadline_ns.load(std::memory_order_acquire);
    if (deadline != 0 && now_ns() > deadline) {
      w.fired.store(true);
      PyThreadState_SetAsyncExc(w.thread_id.load(), globals().step_timeout.ptr());
    }
    PyGILState_Release(state);
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<std::weak_ptr<PyController::Watch>> watches_;
  bool started_ = false;
};

}  // namespace

void add_to_watchdog(const std::shared_ptr<PyController::Watch>& watch) { Watchdog::get().add(watch); }

}  // namespace quadcosim::python
