// A co-simulation FMU as quadcosim's flight controller (control::Controller, type "fmu"): what a
// scenario's `controller: {fmu: ...}` and `quadcosim controller --fmu` fly. Every node flies its own
// instance (clone() instantiates the FMU again), initialised at its first step (start time 0), so
// that parameters the FMU declares fixed can still be set by the scenario until then.
//
// Per control step (period dt, the n-th step at t = n dt): set the sensor inputs and, where the FMU
// has them, the reference inputs; do_step(t, dt); get omega_cmd. Signals (default FMU names in
// fmi/quadrotor_variables.hpp; a scenario may name its own under `inputs:`/`outputs:`):
//   inputs  p_W [m], v_W [m/s], q_WB [1] (w x y z), w_B [rad/s], f_B [m/s2] (the observation; at
//           least one of them), ref.p_W [m], ref.v_W [m/s], ref.a_W [m/s2], ref.j_W [m/s3],
//           ref.yaw [rad], ref.yaw_rate [rad/s], ref.roll [rad], ref.pitch [rad] (the reference);
//           each optional: one the FMU lacks is not set; and the extra sensors' columns by the plant
//           FMU's output names (magnetometer.field[1..3] [T], barometer.pressure [Pa],
//           barometer.altitude [m], gnss.fix [1] (1 or 0), gnss.latitude_deg, gnss.longitude_deg
//           [deg], gnss.altitude_m [m], gnss.v[1..3] [m/s]; names::sensor_variable), set from
//           observation.sensors: the newest sample, NaN (a flag 0) before the first; an FMU with an
//           input of a sensor the vehicle does not carry is refused at load (check_sensors);
//   outputs omega_cmd [rad/s] xN, required: one per rotor, omega_cmd[1..N] by default (or the names
//           the scenario gives); an FMU whose N is not the vehicle's rotor count is refused at load.
// The status's U is the wrench of omega_cmd on the controller's vehicle (eq. (4)); the tracked
// attitude (roll_des, pitch_des, yaw_des) is the reference's; attitude_error is NaN; saturation flags
// are off. The FMU's other Real outputs (and locals it reports) are the controller's own figures
// (output_names()). Parameters: the FMU's Real parameters (tunable, and fixed ones until the first
// step), named without the `controller.` prefix when they have it, with their unit and min/max.
// A failed step (Error or Discard from doStep, a non-finite omega_cmd) throws std::runtime_error
// naming the FMU, the step and its time, and what the FMU logged: nothing non-finite is commanded.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "control/controller.hpp"
#include "fmi/fmu.hpp"
#include "fmi/fmu_mapping.hpp"
#include "model/quadrotor.hpp"
#include "sensors/readings.hpp"
#include "sensors/sensor_set.hpp"

namespace quadcosim::fmi {

std::span<const Signal> controller_inputs();
std::span<const Signal> controller_outputs();

class FmuController final : public control::Controller {
 public:
  /// Checks `mapping` against the FMU (MappingError naming the key) and instantiates it once (so
  /// that an FMU that does not load is refused now, not at the first step); `vehicle` is the
  /// controller's model of the vehicle (for the status's U).
  FmuController(std::shared_ptr<Fmu> fmu, const FmuMapping& mapping, const model::VehicleParams& vehicle);
  ~FmuController() override;

  std::string_view type() const override { return "fmu"; }
  /// A new instance of the same FMU with the same parameter values; its state starts afresh.
  std::unique_ptr<control::Controller> clone() const override;
  std::span<const control::ParameterSpec> parameters() const override;
  std::optional<control::ParameterValue> get_parameter(std::string_view name) const override;
  std::string set_parameters(std::span<const control::Setting> settings) override;
  std::span<const std::string> output_names() const override;
  /// Resets the instance; it is initialised again at the next step.
  void reset() override;
  void step(const control::Observation& observation, const control::Reference& reference, double dt_s,
            control::ControllerOutput& out) override;

  /// Empty when the vehicle with `carried` carries every extra sensor the FMU has inputs of; else
  /// why not, naming the FMU's input and the scenario key that turns the sensor on.
  std::string check_sensors(const sensors::SensorSet& carried) const;

  const std::shared_ptr<Fmu>& fmu() const;
  std::string describe() const;

  /// What every instance of one FMU and mapping shares: the resolved variables and the parameter
  /// table (whose names the specs' string_views point into).
  struct Shared;

 private:
  struct LogTail;
  FmuController(std::shared_ptr<const Shared> shared, std::vector<double> values, const model::Quadrotor& model);
  void instantiate();
  void initialise();
  /// Sets in_'s extra-sensor inputs from the observation's readings.
  void put_sensors(const sensors::Readings& readings);

  std::shared_ptr<const Shared> shared_;
  std::vector<double> values_;  ///< each declared parameter's current value
  std::vector<bool> changed_;   ///< set before initialisation: applied then
  std::unique_ptr<Instance> instance_;
  std::shared_ptr<LogTail> log_;  ///< what instance_ logged lately
  bool initialised_ = false;
  long long steps_ = 0;
  std::vector<double> in_, out_;
  model::Quadrotor model_;
};

/// The FMU controller a configuration flies, or nullptr.
const FmuController* fmu_controller(const control::Controller& c);

}  // namespace quadcosim::fmi
