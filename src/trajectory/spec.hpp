// A trajectory's description: the parameters a scenario's `trajectory:` section gives, kept beside the
// Trajectory they make so that it can be written out again (an exported controller FMU carries it in
// its configuration and builds the same Trajectory from it, docs/fmi.md).
#pragma once

#include <memory>
#include <variant>
#include <vector>

#include "trajectory/periodic.hpp"
#include "trajectory/piecewise_polynomial.hpp"
#include "trajectory/waypoints.hpp"

namespace quadcosim::trajectory {

/// `kind: waypoints`: the points and the method; the plan is made from them (plan_waypoints).
struct WaypointsSpec {
  std::vector<Waypoint> points;
  WaypointMethod method = WaypointMethod::kMinSnap;
};

/// circle, lissajous, figure8, waypoints, or a piecewise polynomial as read from a `kind: file`
/// (its segments, start and label: the file's content, not its path).
using TrajectorySpec = std::variant<CircleParams, LissajousParams, Figure8Params, WaypointsSpec, PiecewisePolynomial>;

/// The Trajectory `spec` describes. Throws std::invalid_argument as the make_* functions and
/// plan_waypoints do.
std::shared_ptr<const Trajectory> make_trajectory(const TrajectorySpec& spec);

}  // namespace quadcosim::trajectory
