// A minimal controller, the worked example of docs/controllers.md: PD on position (with the
// reference's acceleration as feedforward) to a collective thrust and a tilt, PD on attitude scaled by
// the inertia to torques, then the mixer. Registry type "example_pd".
#pragma once

#include <Eigen/Core>

#include "control/allocation.hpp"
#include "control/controller.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::controllers {

struct ExamplePdParams {
  double position_kp = 1.0;   ///< [1/s^2] acceleration per metre of position error
  double position_kd = 1.6;   ///< [1/s] acceleration per m/s of velocity error
  double attitude_kp = 64.0;  ///< [1/s^2] angular acceleration per radian of attitude error
  double attitude_kd = 12.0;  ///< [1/s] angular acceleration per rad/s of body rate
  double max_tilt = 0.5;      ///< [rad] bound on the commanded roll and pitch
};

class ExamplePdController : public control::ControllerWith<ExamplePdController, ExamplePdParams> {
 public:
  static constexpr std::string_view kType = "example_pd";
  static constexpr std::string_view kDescription = "a minimal PD example (docs/controllers.md)";
  explicit ExamplePdController(const model::VehicleParams& vehicle);

  std::string_view type() const override { return kType; }
  std::span<const std::string> output_names() const override;
  void reset() override {}
  void step(const control::Observation& observation, const control::Reference& reference, double dt_s,
            control::ControllerOutput& out) override;

 protected:
  const control::ParameterTable<ExamplePdParams>& table() const override;
  void configure(const ExamplePdParams&) override {}

 private:
  model::VehicleParams vehicle_;
  control::RotorAllocation allocation_;  ///< the layout's: M^-1 (four rotors) or M^+
};

}  // namespace quadcosim::controllers
