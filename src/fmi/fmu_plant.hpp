// A co-simulation FMU as quadcosim's plant: the ExternalDynamicsFactory (sim/external_dynamics.hpp)
// behind a scenario's `plant: {fmu: ...}` and `quadcosim plant --fmu`. Each make() is one FMU
// instance (a swarm makes one per vehicle):
//   1. instantiate; set `vehicle.<name>` for every vehicle parameter (model::vehicle_parameters())
//      the FMU declares under that name, `initial.<output variable>` for the initial state
//      (position, velocity, attitude, rates, rotor speeds), then the scenario's `parameters:` by FMU
//      variable name (last, so they win); enter initialisation at start time 0, set omega_cmd to
//      the initial rotor speeds (the command acting until the first one arrives, as the native
//      plant latches them), exit initialisation;
//   2. per plant tick k: set the rotor speed commands, do_step(t_k, period), get the outputs.
// Signals (default FMU names in fmi/quadrotor_variables.hpp, a scenario may name its own):
//   inputs  omega_cmd [rad/s] xN, required: N (4..8) is the FMU's, omega_cmd[1..N] by default (the
//           count of the names the scenario gives, if it gives them); make() refuses a vehicle with
//           another rotor count;
//   outputs p_W [m] x3 and v_W [m/s] x3, required; q_WB [1] (w, x, y, z; default identity: level,
//           nose along +x), w_B [rad/s] (default zero), f_B [m/s2] (default R_BW (0, 0, g): what
//           the accelerometer of an unaccelerated vehicle at that attitude reads, (0, 0, g) when
//           level), omega [rad/s] xN (default: the command acting, as ideal motors give).
// The quaternion is used as given (not normalised); a non-finite output ends the run with a
// message naming the variable and the tick.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "fmi/fmu.hpp"
#include "fmi/fmu_mapping.hpp"
#include "sim/external_dynamics.hpp"

namespace quadcosim::fmi {

/// The plant's signals, in the order above.
std::span<const Signal> plant_inputs();
std::span<const Signal> plant_outputs();

class FmuPlant final : public sim::ExternalDynamicsFactory {
 public:
  /// Checks `mapping` against the FMU's description: every signal resolves, every parameter fits.
  /// Throws MappingError naming the scenario key.
  FmuPlant(std::shared_ptr<Fmu> fmu, const FmuMapping& mapping);

  /// Throws FmuError (what the FMU logged included) when instantiation or initialisation fails.
  std::unique_ptr<sim::ExternalDynamics> make(const model::VehicleParams& vehicle, const model::State& initial,
                                              const sim::TickClock& clock) const override;
  std::string describe() const override;
  /// Refuses a vehicle whose rotor count is not the FMU's (rotor_count()), naming both.
  std::string check(const model::VehicleParams& vehicle) const override;

  const std::shared_ptr<Fmu>& fmu() const { return fmu_; }

  /// The resolved value references (empty: an optional signal left at its default).
  struct Refs {
    SignalRefs omega_cmd, p_W, v_W, q_WB, w_B, f_B, omega;
  };
  const Refs& refs() const { return refs_; }
  /// How many rotors the FMU flies: its omega_cmd inputs (the scenario's names, else omega_cmd[1..N]).
  int rotor_count() const { return rotor_count_; }

 private:
  std::shared_ptr<Fmu> fmu_;
  FmuMapping mapping_;
  Refs refs_;
  int rotor_count_ = 4;
  std::vector<Signal> outputs_;  ///< plant_outputs() with omega's names for rotor_count_ rotors
  std::vector<ParameterSetting> parameters_;
  /// Instances made so far (they name them) and alive now (an FMU that can be instantiated only once
  /// per process refuses a second one while the first lives).
  mutable std::shared_ptr<std::atomic<int>> made_ = std::make_shared<std::atomic<int>>(0);
  mutable std::shared_ptr<std::atomic<int>> alive_ = std::make_shared<std::atomic<int>>(0);
};

}  // namespace quadcosim::fmi
