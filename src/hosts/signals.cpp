#include "hosts/signals.hpp"

#include <semaphore.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <mutex>
#include <thread>

#include "isolation/child.hpp"

namespace quadcosim::hosts {

namespace {
// The one piece of process-wide state a signal handler may touch, and the semaphore it posts
// (sem_post is async-signal-safe) to wake the stop deadline below.
volatile std::sig_atomic_t g_stop = 0, g_signalled = 0;
sem_t g_stop_posted;
extern "C" void on_stop_signal(int) {
  g_stop = 1;
  g_signalled = 1;
  sem_post(&g_stop_posted);
}

// What wait_for_stop() sleeps on. A signal handler may not notify it (not async-signal-safe): the
// stop-deadline thread does, once the handler's semaphore post woke it; request_stop() does directly.
std::mutex g_wait_mutex;
std::condition_variable g_stop_wait;
void wake_stop_waiters() {
  { const std::lock_guard<std::mutex> lock(g_wait_mutex); }
  g_stop_wait.notify_all();
}

// Waits for the first stop request, then gives the command kStopDeadlineS to end by itself; one that
// is still running then is stuck in code that never returns to its loop (a Python step sleeping in C,
// say): the process ends with 130 and says so. What the outputs' writers had flushed stays.
void stop_deadline() {
  while (sem_wait(&g_stop_posted) != 0) {
  }
  wake_stop_waiters();
  std::this_thread::sleep_for(std::chrono::duration<double>(kStopDeadlineS));
  static const char kText[] =
      "\nerror: interrupted, and a step did not return within 1.5 s of the request (foreign code that never "
      "returns to quadcosim); exiting with status 130\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, kText, sizeof kText - 1);
  std::fflush(nullptr);
  _exit(130);
}
}  // namespace

void install_stop_handlers() {
  static const bool installed = [] {
    sem_init(&g_stop_posted, 0, 0);
    std::thread(stop_deadline).detach();
    return true;
  }();
  (void)installed;
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  // A wait on foreign code's process (an FMU's or a Python controller's step that does not return)
  // gives up when asked to stop.
  isolation::set_stop_check(&stop_requested);
}

bool stop_requested() { return g_stop != 0; }

bool stop_signalled() { return g_signalled != 0; }

void request_stop() {  // the command's own request: no deadline
  g_stop = 1;
  wake_stop_waiters();
}

bool wait_for_stop(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(g_wait_mutex);
  return g_stop_wait.wait_until(lock, deadline, [] { return stop_requested(); });
}

}  // namespace quadcosim::hosts
