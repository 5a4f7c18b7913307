// The steppable plant: the seam every plant host drives (src/drivers/). A plant advances on integer
// ticks in three moves per tick k:
//   1. publish_outputs(k): its outputs for the state at t_k (sensor samples, /clock, status), where
//      its controller hears them; a driver may call it again for the same k (it asks again);
//   2. latch_command(k): the command acting over [t_k, t_k+1) is fixed from what has arrived;
//   3. integrate(k): the state goes to t_k+1.
// Between 1 and 2 a lockstep driver waits for the answer to tick k, which it recognises by what
// command_receipt() reports (sim/lockstep_core.hpp states the rule). The native 6-DOF plant
// (sim::PlantNode) is one; an FMU or a batch of vehicles stepped as one is another.
#pragma once

#include <cstdint>

#include "sim/clock.hpp"

namespace quadcosim::sim {

/// What a plant has received of its commands, for matching answers to ticks.
struct CommandReceipt {
  std::uint64_t received = 0;  ///< commands that arrived so far (any verdict, repeats included)
  /// Tick label [ns] of the newest command taken (-1: it carried none, or none yet).
  std::int64_t label_ns = -1;
};

class SteppablePlant {
 public:
  virtual ~SteppablePlant() = default;
  /// Publishes the outputs for the state at tick k (again, when called twice for one k).
  virtual void publish_outputs(Tick k) = 0;
  /// Fixes the command that acts over [t_k, t_k+1).
  virtual void latch_command(Tick k) = 0;
  /// Integrates the state from t_k to t_k+1 under the latched command.
  virtual void integrate(Tick k) = 0;
  /// The commands received so far.
  virtual CommandReceipt command_receipt() const = 0;
};

}  // namespace quadcosim::sim
