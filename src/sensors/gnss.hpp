// A GNSS receiver: position as latitude, longitude and ellipsoidal height (sensor_msgs/NavSatFix) and
// velocity in the world frame (ENU), at a receiver's rate (5-10 Hz) and latency. The world frame is the
// local tangent plane of the site (sensors/geodesy.hpp). Errors are white per sample and per axis in
// ENU: horizontal (east, north) and vertical sigmas, a velocity sigma; the fix carries their variances
// as a diagonal ENU covariance. Until fix_after_s (time to first fix), and over an outage window
// [outage_from_s, outage_to_s) (the fix lost in flight: a jammed or shadowed antenna), the receiver
// reports no fix: status NO_FIX, coordinates and velocity NaN. Multipath, atmospheric delays and
// their slow correlation are not modelled.
#pragma once

#include <string>

#include <Eigen/Core>

#include "model/quadrotor.hpp"
#include "model/random.hpp"
#include "sensors/geodesy.hpp"
#include "sensors/timing.hpp"

namespace quadcosim::sensors {

struct GnssConfig {
  Timing timing;
  Geodetic site;                    ///< the world origin
  double horizontal_sigma_m = 0.0;  ///< per horizontal axis and sample [m]
  double vertical_sigma_m = 0.0;    ///< per sample [m]
  double velocity_sigma_m_s = 0.0;  ///< per axis and sample [m/s]
  double fix_after_s = 0.0;         ///< no fix before this time [s]
  double outage_from_s = 0.0;       ///< no fix from this time ... [s]
  double outage_to_s = 0.0;         ///< ... until this one (an empty window when not after outage_from_s) [s]
};

/// "" when the outage window is a window (outage_to_s after outage_from_s, or both 0), else why not.
std::string check(const GnssConfig& c);

struct GnssSample {
  bool fix = false;
  Geodetic position;                                                ///< NaN without a fix
  Eigen::Vector3d velocity_W = Eigen::Vector3d::Zero();             ///< ENU [m/s]; NaN without a fix
  Eigen::Vector3d position_variance_enu = Eigen::Vector3d::Zero();  ///< [m^2]
  double velocity_variance = 0.0;                                   ///< per axis [m^2/s^2]
};

class Gnss {
 public:
  Gnss() = default;
  /// `rng`: the sensor's own stream.
  Gnss(const GnssConfig& config, model::Rng rng);
  /// The sample of the truth at time t_s (the time of the truth measured).
  GnssSample measure(const model::Outputs& truth, double t_s);
  const GnssConfig& config() const { return config_; }
  const LocalTangentPlane& plane() const { return plane_; }

 private:
  GnssConfig config_;
  LocalTangentPlane plane_;
  model::Rng rng_;
};

}  // namespace quadcosim::sensors
