// A controller's schedule of parameter changes (a scenario's `schedule:`), applied in tick order as
// simulated time passes. One piece for every host of a controller node: the in-process Simulation,
// the lockstep controller over DDS (LockstepStepper) and the real-time controller.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "control/parameters.hpp"
#include "sim/clock.hpp"
#include "sim/controller_node.hpp"

namespace quadcosim::sim {

struct ScheduledParameter {
  Tick tick = 0;
  std::string name;
  control::ParameterValue value;
};

class ParameterSchedule {
 public:
  /// Orders the changes by tick (changes of one tick keep their order).
  ParameterSchedule(std::vector<ScheduledParameter> schedule, const TickClock& clock);
  /// Sets on the node (or its core) every change due by `now_ns` [ns, simulated] not set yet. Throws
  /// std::invalid_argument naming the change's time and the node's reason when it refuses one.
  void apply(ControllerCore& core, std::int64_t now_ns) {
    if (now_ns >= next_due_ns_) apply_due(core, now_ns);  // one compare per tick on the hot path
  }
  void apply(ControllerNode& node, std::int64_t now_ns) { apply(node.core(), now_ns); }

 private:
  void apply_due(ControllerCore& core, std::int64_t now_ns);
  /// When schedule_[next_] is due [ns], or INT64_MAX after the last change.
  std::int64_t due_ns() const;
  std::vector<ScheduledParameter> schedule_;  ///< by tick
  std::size_t next_ = 0;                      ///< the first change not set yet
  TickClock clock_;
  std::int64_t next_due_ns_;
};

}  // namespace quadcosim::sim
