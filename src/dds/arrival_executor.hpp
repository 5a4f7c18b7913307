// Delivery on arrival for one DdsTransport: each subscription's samples are delivered on the
// Cyclone thread that received them (a DATA_AVAILABLE listener) or, when they came while the owner
// worked, at the owner's next wait, so a node that reacts where it is delivered (a lockstep controller stepping on a
// complete sample, a lockstep plant running its next ticks once the answer is in) answers without waking another
// thread.
//
// The threading rule, stated here once (callers need nothing else):
//   - The thread that creates the executor owns it. It holds the executor's (recursive) lock from
//     then on, except while it waits in wait()/wait_until() or runs unlocked(): deliveries run
//     only then, one at a time, never beside each other or beside the owner's own work. So a node
//     never sees a callback while its thread is in the middle of a step, and nobody else takes a
//     lock: what the owner does between waits is as single-threaded as without the executor.
//   - after_each(hook): the hook runs after each delivery, on the delivering thread, under the same
//     lock; when it returns true, the owner's wait returns. Without a hook, deliveries do not end
//     waits (wait_until's condition is asked after each delivery too).
//   - A delivery may publish (also to this transport's own readers: the lock is recursive).
//   - A receive thread never blocks on the lock. Cyclone runs one listener of a reader at a time:
//     a receive thread waiting inside reader R's listener for the owner, while the owner's own
//     write delivers to R locally (R records a topic the owner publishes and someone else on the
//     domain publishes too), would wait for each other for ever. A delivery that finds the lock
//     taken takes its samples out of the reader (so the reader's history depth drops none), holds
//     them and wakes the owner. Held samples are delivered in the order held, before anything
//     newer: by the owner's wait() (first thing, and again after its wait) and by the next receive
//     thread that gets the lock (before its own); a delivery on the owner's thread (its own local
//     write) or inside a delivery first delivers only what its own reader held, so each reader
//     keeps its order. So the order is the one blocking would give: what arrived while the owner
//     worked comes after the owner's own messages of that work. Deliveries then run on the owner's
//     thread too, still only while it waits or inside its own writes.
//   - An exception a delivery (or the hook) throws is kept, later deliveries are dropped, the
//     owner's wait returns at once and rethrows it.
//   - Extra work of the transport (parameter services) is served by wait() on the owner's thread,
//     under the lock, as spin_once serves it.
//   - wait, wait_until, unlocked and after_each from another thread: std::logic_error naming the
//     call. The transport's own spin_once is refused while the executor exists.
//   - Destruction (on the owner's thread) returns the transport to delivery by spin_once, waiting
//     for a delivery in progress: declare the executor after what the deliveries use.
#pragma once

#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "dds/dds_transport.hpp"

namespace quadcosim::dds {

class ArrivalExecutor {
 public:
  /// From now on `transport`'s samples are delivered on arrival; what came before is delivered now
  /// (what such a delivery throws is kept, as on arrival: the first wait() rethrows it).
  explicit ArrivalExecutor(DdsTransport& transport);
  ~ArrivalExecutor();
  ArrivalExecutor(const ArrivalExecutor&) = delete;
  ArrivalExecutor& operator=(const ArrivalExecutor&) = delete;

  /// Lets deliveries run for up to timeout_ns, until the hook (or a failure) wakes it, matching
  /// changes or extra work come; then serves the extra work. Returns the messages delivered since
  /// the last call. Rethrows what a delivery threw.
  int wait(std::int64_t timeout_ns);
  /// Waits until `done()` holds (asked between waits and after each delivery) or timeout_ns
  /// passes; returns done().
  bool wait_until(const std::function<bool()>& done, std::int64_t timeout_ns);
  /// Runs `blocking()` with deliveries let through, as in wait(): for a blocking call that needs
  /// Cyclone's receive thread (a service reply on another reader), which a delivery waiting for
  /// the lock would otherwise hold up. `blocking` must not touch what deliveries touch.
  template <class F>
  auto unlocked(F blocking) {
    check_owner("unlocked");
    struct Relock {
      std::recursive_mutex& m;
      ~Relock() { m.lock(); }
    };
    mutex_.unlock();
    const Relock relock{mutex_};
    return blocking();
  }
  /// The hook run after each delivery (empty: none); true wakes the owner's wait.
  void after_each(std::function<bool()> hook);

 private:
  void on_data(std::size_t subscription);
  /// Delivers one subscription's samples (or held ones) and runs the hook; true when that wakes
  /// the owner (or delivery has stopped).
  bool deliver(std::size_t subscription);
  bool deliver(DdsTransport::Held& held);
  /// Runs take() (it delivers; returns how many) as a delivery: counted, its failure kept, the hook run.
  template <class Take>
  bool delivery(Take take);
  /// The oldest held batch (of subscription *only, when given) out of noted_.
  bool next_noted(DdsTransport::Held& held, const std::size_t* only);
  /// Delivers the held batches in order (under mutex_); with stop_at_wake, stops after the first
  /// delivery that wakes the owner (the rest stay held) and returns true.
  bool take_noted(bool stop_at_wake);
  void take_noted_of(std::size_t subscription);
  bool after_delivery();
  void check_owner(const char* what) const;

  DdsTransport& transport_;
  std::thread::id owner_;
  std::recursive_mutex mutex_;
  Entity wake_;        ///< guard condition on the transport's waitset: a delivery wakes wait()
  int wake_work_ = 0;  ///< its extra-work id
  // Under mutex_:
  int delivered_ = 0;
  std::exception_ptr failure_;
  std::function<bool()> after_;
  const std::function<bool()>* until_ = nullptr;  ///< wait_until's condition while it runs
  int depth_ = 0;  ///< deliveries in progress on the thread that holds the lock (nested: > 1)
  // Samples whose delivery found the lock taken, taken out of their readers, oldest first (under
  // noted_mutex_, which is never held while a delivery runs); what taking them threw.
  std::mutex noted_mutex_;
  std::deque<DdsTransport::Held> noted_;
  std::exception_ptr noted_failure_;
};

}  // namespace quadcosim::dds
