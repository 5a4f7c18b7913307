// The seam every recording of a run plugs into (trajectory.csv, run.mcap, a Python run's series, the
// Foxglove live view, a quadcosim.Batch's state rows): a recorder is fed the run's truth once per plant
// tick and taps the messages the nodes publish on the bus; hosts/recording.hpp builds the recorders a
// run asks for (io/recording.hpp's and the live view), the same way for every host. A Batch feeds its
// vehicles' rows once per step instead (python/batch_class.hpp).
#pragma once

#include <cstdint>

#include "model/mixer.hpp"
#include "model/quadrotor.hpp"
#include "sim/clock.hpp"
#include "sim/messages.hpp"

namespace quadcosim::sim {

/// One plant tick as the recordings see it: the true state at t_k and the command acting over
/// [t_k, t_k+1), with what the controller last said of its step.
struct RecordedTick {
  Tick tick;
  double t_s;         ///< simulated time of the tick [s]
  std::int64_t t_ns;  ///< the same [ns] (the plant clock's ns(tick))
  const model::State& state;
  const model::RotorVector& command;    ///< rotor speeds latched for [t_k, t_k+1) [rad/s], one per rotor
  const msg::ControllerStatus* status;  ///< the controller's newest status; nullptr when none came (open loop)
  bool watchdog = false;                ///< the plant's watchdog holds the motors (no valid command)
};

/// A recording of a run. The host calls tick() once per plant tick, in order, after the tick's
/// command is latched; a recorder that taps the bus subscribed when it was built (the messages come
/// with their topic, their sender and, where the transport has them, their serialised bytes:
/// Transport::subscribe_tap). finish() completes the recording; a recorder must stay readable when
/// finish() is never called (a run that failed): its destructor closes what it holds.
class Recorder {
 public:
  virtual ~Recorder() = default;
  /// One plant tick (truth); also the point at which bus recordings may write what is settled.
  virtual void tick(const RecordedTick& tick) = 0;
  /// A host without plant ticks (a recorder of someone else's run) calls this between its waits.
  virtual void idle() {}
  /// Completes the recording. `completed`: the run ended as asked (a recording may then also write
  /// what describes it, e.g. run.mcap's metadata.yaml). Throws std::runtime_error on an I/O error.
  virtual void finish(bool completed) = 0;
};

}  // namespace quadcosim::sim
