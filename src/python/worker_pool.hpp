// Threads that run one job over a batch's vehicles in chunks, kept between steps (quadcosim.Batch).
//
// A step of 1,000 vehicles once per control period takes a few hundred microseconds, and Python calls
// the next one a few microseconds after the last returned. Waking a thread that went to sleep takes
// the kernel (and, on a virtual machine, the hypervisor) tens to hundreds of microseconds, as long as
// the step's work itself; so, as OpenMP runtimes do, a thread that finished its part keeps polling
// for the next job for a while (kSpin) before it sleeps, and the calling thread polls for the last
// chunk instead of sleeping on it. The polling pauses the core between looks and yields to other
// threads after kSpinPause, so a loaded machine loses little to it; a batch stepped now and then
// costs one wake-up per step, as before.
//
// Each thread (the calling thread is one) owns a contiguous range of the chunks, the same from job
// to job, and takes its own first: a vehicle is stepped by the same thread each time, so its data
// stays in that core's cache, not moved from the other core's at every step (which cost more than the
// second thread gained). A thread done with its own range takes the chunks left in the others', so a
// thread the OS does not run for a while (the machine is shared) delays a step by one chunk at most.
// Which thread steps which vehicle changes nothing (the vehicles do not interact).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace quadcosim::python {

class WorkerPool {
 public:
  /// How long a thread polls for work before it sleeps, and after how long of it it yields the core.
  static constexpr std::chrono::microseconds kSpin{2000}, kSpinPause{100};

  explicit WorkerPool(int threads) : threads_(std::max(threads, 1)), next_(static_cast<std::size_t>(threads_)) {
    for (int t = 1; t < threads_; ++t) workers_.emplace_back([this, t] { work(t); });
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  ~WorkerPool() {
    {
      std::lock_guard lock(mutex_);
      stop_.store(true, std::memory_order_release);
    }
    start_.notify_all();
    for (auto& w : workers_) w.join();
  }

  int size() const { return threads_; }

  /// Runs job(c) for every chunk c in [0, chunks) on the pool and the calling thread, and returns
  /// when all are done. Rethrows the first exception a chunk raised (the other chunks still ran).
  void run(std::uint32_t chunks, const std::function<void(std::uint32_t)>& job) {
    if (threads_ == 1 || chunks <= 1) {
      for (std::uint32_t c = 0; c < chunks; ++c) job(c);
      return;
    }
    std::uint64_t generation = 0;
    {
      std::lock_guard lock(mutex_);
      job_ = &job;
      chunks_ = chunks;
      done_chunks_.store(0, std::memory_order_relaxed);
      failure_ = nullptr;
      generation = generation_.load(std::memory_order_relaxed) + 1;
      for (int t = 0; t < threads_; ++t)
        next_[t].value.store(generation << 32 | first_chunk(t, chunks), std::memory_order_relaxed);
      generation_.store(generation, std::memory_order_release);
      if (sleeping_ > 0) start_.notify_all();
    }
    take_chunks(0, generation, job, chunks);
    // The other threads' last chunks: polled, then slept on.
    if (!poll([&] { return done_chunks_.load(std::memory_order_acquire) == chunks; })) {
      std::unique_lock lock(mutex_);
      ++waiting_for_done_;
      done_.wait(lock, [&] { return done_chunks_.load(std::memory_order_acquire) == chunks; });
      --waiting_for_done_;
    }
    std::lock_guard lock(mutex_);
    job_ = nullptr;
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  /// Calls ready() until it holds or kSpin has passed, pausing between calls; true when it held.
  template <class Ready>
  static bool poll(const Ready& ready) {
    const auto start = std::chrono::steady_clock::now();
    for (unsigned n = 0;; ++n) {
      if (ready()) return true;
      if (n % 64 == 63) {
        const auto waited = std::chrono::steady_clock::now() - start;
        if (waited >= kSpin) return false;
        if (waited >= kSpinPause) std::this_thread::yield();
      }
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    }
  }

  /// The first chunk of thread t's range (its end is the next thread's first).
  std::uint32_t first_chunk(int t, std::uint32_t chunks) const {
    return static_cast<std::uint32_t>(std::uint64_t{chunks} * static_cast<std::uint64_t>(t) /
                                      static_cast<std::uint64_t>(threads_));
  }

  /// Thread `self` takes chunks of `generation`: its own range's, then what is left of the others'.
  void take_chunks(int self, std::uint64_t generation, const std::function<void(std::uint32_t)>& job,
                   std::uint32_t chunks) {
    for (int i = 0; i < threads_; ++i) {
      const int t = (self + i) % threads_;
      take_range(next_[t].value, first_chunk(t + 1, chunks), generation, job, chunks);
    }
  }

  /// Takes chunks from `next` (a range's counter) up to `end` until none is left (the counter holds the
  /// generation in its high half, so a thread that comes late never takes a chunk of a later job
  /// with an earlier one).
  void take_range(std::atomic<std::uint64_t>& next, std::uint32_t end, std::uint64_t generation,
                  const std::function<void(std::uint32_t)>& job, std::uint32_t chunks) {
    for (;;) {
      std::uint64_t v = next.load(std::memory_order_acquire);
      std::uint32_t c = 0;
      do {
        if ((v >> 32) != generation || static_cast<std::uint32_t>(v) >= end) return;
        c = static_cast<std::uint32_t>(v);
      } while (!next.compare_exchange_weak(v, v + 1, std::memory_order_acq_rel));
      try {
        job(c);
      } catch (...) {
        std::lock_guard lock(mutex_);
        if (!failure_) failure_ = std::current_exception();
      }
      if (done_chunks_.fetch_add(1, std::memory_order_acq_rel) + 1 == chunks) {
        std::lock_guard lock(mutex_);
        if (waiting_for_done_ > 0) done_.notify_all();
      }
    }
  }

  void work(int self) {
    std::uint64_t seen = 0;
    for (;;) {
      // Polls for the next job, then sleeps on it.
      if (!poll([&] {
            return generation_.load(std::memory_order_acquire) != seen || stop_.load(std::memory_order_acquire);
          })) {
        std::unique_lock lock(mutex_);
        ++sleeping_;
        start_.wait(lock, [&] { return stop_.load(std::memory_order_relaxed) || generation_.load() != seen; });
        --sleeping_;
      }
      const std::function<void(std::uint32_t)>* job = nullptr;
      std::uint32_t chunks = 0;
      {
        // The job, its chunk count and its generation as one (run() writes them under the lock).
        std::lock_guard lock(mutex_);
        if (stop_.load(std::memory_order_relaxed)) return;
        seen = generation_.load(std::memory_order_relaxed);
        job = job_;
        chunks = chunks_;
      }
      if (job) take_chunks(self, seen, *job, chunks);
    }
  }

  int threads_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  // Written under mutex_; generation_ also read without it, by threads polling for a new job.
  const std::function<void(std::uint32_t)>* job_ = nullptr;
  std::uint32_t chunks_ = 0;
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<bool> stop_{false};
  int sleeping_ = 0;          ///< workers asleep on start_ (under mutex_)
  int waiting_for_done_ = 0;  ///< run() asleep on done_ (under mutex_)
  std::atomic<std::uint32_t> done_chunks_{0};
  /// Per thread's range: generation << 32 | its next chunk to take (a cache line each).
  struct alignas(64) Counter {
    std::atomic<std::uint64_t> value{0};
  };
  std::vector<Counter> next_;
  std::exception_ptr failure_;
};

}  // namespace quadcosim::python
