// The paper's hierarchical flight controller (Algorithm 1): LQR attitude, PD altitude, PID position
// (position mode), allocation; registry type "paper". The stale-data safety of Algorithm 1 (lines
// 3-5) is the controller node's, as for every controller. It uses the reference's position, yaw and
// (attitude mode) roll and pitch; it has no feedforward, so a trajectory's velocity, acceleration and
// jerk are ignored.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "control/allocation.hpp"
#include "control/altitude_pd.hpp"
#include "control/attitude_lqr.hpp"
#include "control/controller.hpp"
#include "control/controller_config.hpp"
#include "control/position_pid.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::controllers {

struct PaperParams {
  control::LqrWeights roll{1.3, 2.4, 100.0};
  control::LqrWeights pitch{1.3, 2.4, 100.0};
  control::LqrWeights yaw{0.16, 0.65, 100.0};
  control::AltitudeGains altitude;
  control::PositionGains position;
};

class PaperController : public control::ControllerWith<PaperController, PaperParams> {
 public:
  static constexpr std::string_view kType = "paper";
  static constexpr std::string_view kDescription =
      "the paper's Algorithm 1: LQR attitude, PD altitude, PID position, allocation";

  /// Designs the three LQR axes for `vehicle` (the controller's knowledge of it); throws
  /// control::CareError if a design has no solution.
  explicit PaperController(const model::VehicleParams& vehicle, const PaperParams& params = {});

  std::string_view type() const override { return kType; }
  std::span<const std::string> output_names() const override;
  void reset() override { position_state_ = {}; }
  void step(const control::Observation& observation, const control::Reference& reference, double dt_s,
            control::ControllerOutput& out) override;

  const model::VehicleParams& vehicle() const { return vehicle_; }
  const control::AxisLqr& axis(int i) const { return axes_[i]; }  ///< 0 roll, 1 pitch, 2 yaw
  const control::PositionPidState& position_state() const { return position_state_; }

 protected:
  const control::ParameterTable<PaperParams>& table() const override;
  void configure(const PaperParams& next) override;

 private:
  model::VehicleParams vehicle_;
  std::array<control::AxisLqr, 3> axes_;
  control::RotorAllocation allocation_;  ///< the layout's: M^-1 (four rotors) or M^+
  control::PositionPidState position_state_;
};

/// The paper controller `config` flies, or nullptr when it flies another type (for the analyses that
/// are the paper controller's own: `quadcosim lqr`, `margins`, the BASELINE loop).
const PaperController* paper_controller(const control::ControllerConfig& config);

}  // namespace quadcosim::controllers
