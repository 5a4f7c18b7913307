// What a driver (drivers/*.hpp) needs from the place it runs in, and nothing else: a monotonic wall
// clock, a way to wait while the answers are delivered, and whether to stop. Over DDS the app builds
// one on a DdsTransport and its ArrivalExecutor (hosts/node_common.hpp); in-process and in tests a
// host delivers synchronously or from a queue. A host never decides anything about ticks.
#pragma once

#include <cstdint>
#include <functional>

namespace quadcosim::drivers {

class DriverHost {
 public:
  virtual ~DriverHost() = default;
  /// Monotonic wall clock [ns]: timeouts, retries, pacing and latency figures, never the numbers.
  virtual std::int64_t now_ns() = 0;
  /// Takes in deliveries for up to timeout_ns (0: what is there, without blocking), returning early
  /// once `woken()` holds (when given; asked on this thread between waits and, when answers are
  /// delivered where they arrive, after each delivery).
  virtual void wait(std::int64_t timeout_ns, const std::function<bool()>& woken) = 0;
  /// Waits until now_ns() >= deadline_ns, taking in deliveries. A host may override it to land the
  /// wake-up closer to the deadline (the real-time controller's host spins its last millisecond).
  virtual void wait_until(std::int64_t deadline_ns) {
    for (std::int64_t now = now_ns(); now < deadline_ns; now = now_ns()) wait(deadline_ns - now, {});
  }
  /// True when the run is to end (Ctrl-C): drivers stop at their next tick boundary.
  virtual bool stop_requested() { return false; }
  /// Lockstep: on while answers (or samples) are awaited, so the host delivers them where they
  /// arrive (over DDS on the receive thread, running the driver's on_delivery() after each); off
  /// while a plant driver holds after a timeout, and at the end. Default: nothing to switch.
  virtual void deliver_on_arrival(bool /*on*/) {}
  /// Lockstep: on, the outputs published from now on may wait to be sent with later ones (over DDS:
  /// packed into one datagram a writer); off, everything waiting is sent now. A plant holds the
  /// outputs of the ticks between control ticks, which nothing waits for, and releases them with
  /// the next control tick's. Default: every output is sent when published.
  virtual void hold_outputs(bool /*on*/) {}
};

}  // namespace quadcosim::drivers
