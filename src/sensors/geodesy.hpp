// WGS-84 coordinates and the local tangent plane of a site: how quadcosim's world frame (ENU: x east,
// y north, z up, origin at the site) maps to latitude, longitude and ellipsoidal height.
//
// The map is exact on the ellipsoid, not a flat-earth approximation: a world point p_ENU is
//   r_ECEF = r0_ECEF + R_ENU->ECEF(lat0, lon0) p_ENU
// (r0 the site's Earth-centred, Earth-fixed position, R the rotation whose columns are the site's east,
// north and up directions), then converted to geodetic coordinates by the fixed-point iteration
// tan(lat) = (z + e^2 N(lat) sin(lat)) / p (p the distance from the polar axis, N the prime vertical
// radius), which contracts by about e^2 = 0.0067 per step: 8 steps reach machine precision. The site's altitude is its
// height above the WGS-84 ellipsoid (the geoid undulation, up to about 100 m, is not modelled: a barometer's
// mean-sea-level altitude and the GNSS altitude of the same site are taken as equal).
#pragma once

#include <Eigen/Core>

namespace quadcosim::sensors {

namespace wgs84 {
inline constexpr double kA_m = 6378137.0;          ///< semi-major axis
inline constexpr double kF = 1.0 / 298.257223563;  ///< flattening
inline constexpr double kE2 = kF * (2.0 - kF);     ///< first eccentricity squared
inline constexpr double kB_m = kA_m * (1.0 - kF);  ///< semi-minor axis
}  // namespace wgs84

struct Geodetic {
  double latitude_rad = 0.0;
  double longitude_rad = 0.0;
  double height_m = 0.0;  ///< above the WGS-84 ellipsoid
};

/// Earth-centred, Earth-fixed position [m] of a geodetic point.
Eigen::Vector3d to_ecef(const Geodetic& g);
/// The geodetic point of an ECEF position [m].
Geodetic to_geodetic(const Eigen::Vector3d& ecef);
/// Columns: the east, north and up unit vectors of latitude/longitude in ECEF.
Eigen::Matrix3d enu_to_ecef(double latitude_rad, double longitude_rad);

/// The world frame of a site: ENU positions and velocities to geodetic coordinates.
class LocalTangentPlane {
 public:
  LocalTangentPlane() : LocalTangentPlane(Geodetic{}) {}
  explicit LocalTangentPlane(const Geodetic& origin);
  Geodetic to_geodetic(const Eigen::Vector3d& p_enu) const;
  Eigen::Vector3d to_enu(const Geodetic& g) const;
  const Geodetic& origin() const { return origin_; }

 private:
  Geodetic origin_;
  Eigen::Vector3d origin_ecef_;
  Eigen::Matrix3d enu_to_ecef_;
};

}  // namespace quadcosim::sensors
