// Builds the BASELINE loop's plain numbers from the framework's vehicle and controller parameters
// (setup only), so the baseline flies the same vehicle with the same gains.
#pragma once

#include "baseline/baseline_loop.hpp"
#include "controllers/paper/paper_controller.hpp"

namespace quadcosim::baseline {

/// The BASELINE loop for `vehicle` (its mass, inertia, mixer) and the paper controller's gains `p`
/// (per-axis LQR designs, altitude PD), holding altitude `z_des_m` [m]. Throws control::CareError when
/// an LQR design fails.
BaselineLoop make_baseline(const model::VehicleParams& vehicle, const controllers::PaperParams& p, double z_des_m);

}  // namespace quadcosim::baseline
