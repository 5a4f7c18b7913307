// The scenario key `trajectory:` (docs/scenarios.md, "Trajectories"): the reference the controller
// tracks, one of steps (none: setpoints from the controller parameters and the schedule), circle,
// lissajous, figure8, waypoints or file.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "io/yaml_reader.hpp"
#include "trajectory/spec.hpp"
#include "trajectory/trajectory.hpp"

namespace quadcosim::io {

/// Reads the `trajectory:` section `s`; nullptr for `kind: steps` (the default). A `file` path is
/// relative to `scenario_dir`. Throws ConfigError naming the file, the key path and the value (unknown
/// keys, values out of range, waypoint times not increasing, a polynomial file that cannot be read).
std::shared_ptr<const trajectory::Trajectory> read_trajectory(YamlSection& s, const std::string& scenario_dir);

/// The same section as a description (trajectory::make_trajectory builds what read_trajectory
/// returns from it); nothing for `kind: steps`. A `file` is read here: the description holds its
/// segments.
std::optional<trajectory::TrajectorySpec> read_trajectory_spec(YamlSection& s, const std::string& scenario_dir);

}  // namespace quadcosim::io
