#include "io/trajectory_yaml.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "trajectory/periodic.hpp"
#include "trajectory/polynomial_file.hpp"
#include "trajectory/waypoints.hpp"

namespace quadcosim::io {

namespace {

constexpr double kFar = 1e6;  // [m], [s]: bound on positions and times

const model::Range kPositive{0.0, kFar, model::Range::End::kOpen, model::Range::End::kClosed};

Eigen::Vector2d vec2(YamlSection& s, const std::string& key, const Eigen::Vector2d& fallback,
                     const model::Range& range) {
  const auto v = s.numbers(key, {fallback.x(), fallback.y()}, 2);
  for (double e : v) {
    if (!range.contains(e)) s.fail(key, fmt::format("got an entry {:g}, expected numbers in {}", e, range.text()));
  }
  return {v[0], v[1]};
}

// yaw_mode (fixed | tangent [| centre]) and yaw_rad (fixed only).
void read_yaw(YamlSection& s, bool centre_allowed, trajectory::YawMode& mode, double& yaw_rad) {
  std::vector<std::string> modes = {"fixed", "tangent"};
  if (centre_allowed) modes.push_back("centre");
  const std::string m = s.choice("yaw_mode", "fixed", modes);
  mode = m == "fixed" ? trajectory::YawMode::kFixed
                      : (m == "tangent" ? trajectory::YawMode::kTangent : trajectory::YawMode::kCentre);
  if (mode != trajectory::YawMode::kFixed && s.has("yaw_rad")) {
    s.fail("yaw_rad", "given with yaw_mode '" + m + "'; yaw_rad is for yaw_mode: fixed only");
  }
  yaw_rad = s.number("yaw_rad", 0.0, -10.0, 10.0);
}

void read_start(YamlSection& s, Eigen::Vector2d& centre, double& altitude, double& start, double& ramp) {
  centre = vec2(s, "centre_m", centre, {-kFar, kFar});
  altitude = s.number("altitude_m", altitude, 0.0, kFar);
  start = s.number("start_s", start, 0.0, 1e7);
  ramp = s.number("ramp_s", ramp, 0.0, kFar);
}

trajectory::WaypointsSpec read_waypoints(YamlSection& s) {
  const std::string method = s.choice("method", "min_snap", {"min_snap", "min_jerk"});
  std::vector<trajectory::Waypoint> points;
  int index = 0;
  for (const YAML::Node& n : s.sequence("points")) {
    const std::string where = "points[" + std::to_string(index++) + "]";
    if (!n.IsMap()) s.fail(where, "got " + YamlSection::describe(n) + ", expected a mapping with t_s and position_m");
    YamlSection p(n, s.file(), s.key_path(where));
    trajectory::Waypoint w;
    if (!p.has("t_s")) p.fail("t_s", "missing; expected the time of the waypoint [s]");
    if (!p.has("position_m")) p.fail("position_m", "missing; expected [x, y, z] [m]");
    w.t_s = p.number("t_s", 0.0, 0.0, 1e7);
    if (!points.empty() && w.t_s <= points.back().t_s) {
      p.fail("t_s",
             fmt::format("got {:g}, expected a time after the previous waypoint's ({:g} s)", w.t_s, points.back().t_s));
    }
    const auto xyz = p.numbers("position_m", {}, 3);
    for (double e : xyz) {
      if (std::abs(e) > kFar) p.fail("position_m", fmt::format("got an entry {:g}, expected |x|, |y|, |z| <= 1e6", e));
    }
    if (xyz[2] < 0.0) p.fail("position_m", fmt::format("got z = {:g}, expected z >= 0 (the ground is z = 0)", xyz[2]));
    w.p_W = {xyz[0], xyz[1], xyz[2]};
    if (p.has("yaw_rad")) w.yaw_rad = p.number("yaw_rad", 0.0, -10.0, 10.0);
    p.reject_unknown_keys();
    points.push_back(w);
  }
  if (points.size() < 2) {
    s.fail("points", "got " + std::to_string(points.size()) + " waypoints, expected at least two");
  }
  return {std::move(points),
          method == "min_snap" ? trajectory::WaypointMethod::kMinSnap : trajectory::WaypointMethod::kMinJerk};
}

}  // namespace

std::optional<trajectory::TrajectorySpec> read_trajectory_spec(YamlSection& s, const std::string& scenario_dir) {
  const std::string kind = s.choice("kind", "steps", {"steps", "circle", "lissajous", "figure8", "waypoints", "file"});
  std::optional<trajectory::TrajectorySpec> out;
  try {
    if (kind == "circle") {
      trajectory::CircleParams c;
      read_start(s, c.centre_m, c.altitude_m, c.start_s, c.ramp_s);
      c.radius_m = s.number("radius_m", c.radius_m, kPositive);
      c.period_s = s.number("period_s", c.period_s, kPositive);
      c.clockwise = s.choice("direction", "ccw", {"ccw", "cw"}) == "cw";
      c.phase_rad = s.number("phase_rad", 0.0, -100.0, 100.0);
      read_yaw(s, true, c.yaw_mode, c.yaw_rad);
      out = c;
    } else if (kind == "lissajous") {
      trajectory::LissajousParams l;
      read_start(s, l.centre_m, l.altitude_m, l.start_s, l.ramp_s);
      l.amplitude_m = vec2(s, "amplitude_m", l.amplitude_m, {0.0, kFar});
      l.period_s = vec2(s, "period_s", l.period_s, kPositive);
      l.phase_rad = vec2(s, "phase_rad", l.phase_rad, {-100.0, 100.0});
      read_yaw(s, false, l.yaw_mode, l.yaw_rad);
      if (l.yaw_mode == trajectory::YawMode::kTangent && l.amplitude_m.minCoeff() <= 0.0) {
        s.fail("amplitude_m",
               "a zero amplitude with yaw_mode 'tangent': expected both > 0 (on a line the direction "
               "of travel flips)");
      }
      out = l;
    } else if (kind == "figure8") {
      trajectory::Figure8Params f;
      read_start(s, f.centre_m, f.altitude_m, f.start_s, f.ramp_s);
      f.amplitude_m = vec2(s, "amplitude_m", f.amplitude_m, kPositive);
      f.period_s = s.number("period_s", f.period_s, kPositive);
      read_yaw(s, false, f.yaw_mode, f.yaw_rad);
      out = f;
    } else if (kind == "waypoints") {
      out = read_waypoints(s);
    } else if (kind == "file") {
      if (!s.has("path")) s.fail("path", "missing; expected a polynomial file (relative to the scenario's folder)");
      const std::string name = s.text("path", "");
      const double start_s = s.number("start_s", 0.0, 0.0, 1e7);
      const std::filesystem::path p(name);
      const std::string full = p.is_absolute() ? name : (std::filesystem::path(scenario_dir) / p).string();
      try {
        out = trajectory::read_polynomial_csv(full, start_s);
      } catch (const trajectory::FileError& e) {
        s.fail("path", "got '" + name + "': " + e.what());
      }
    }
    // Made here as a check, so that a description the trajectory code refuses is refused with the key path.
    if (out) trajectory::make_trajectory(*out);
  } catch (const std::invalid_argument& e) {  // the keys are checked above; this is a backstop
    s.fail("", std::string("got an invalid ") + kind + ": " + e.what());
  }
  s.reject_unknown_keys();
  return out;
}

std::shared_ptr<const trajectory::Trajectory> read_trajectory(YamlSection& s, const std::string& scenario_dir) {
  const std::optional<trajectory::TrajectorySpec> spec = read_trajectory_spec(s, scenario_dir);
  return spec ? trajectory::make_trajectory(*spec) : nullptr;
}

}  // namespace quadcosim::io
