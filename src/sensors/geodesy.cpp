#include "sensors/geodesy.hpp"

#include <cmath>

namespace quadcosim::sensors {

Eigen::Vector3d to_ecef(const Geodetic& g) {
  const double s = std::sin(g.latitude_rad), c = std::cos(g.latitude_rad);
  const double n = wgs84::kA_m / std::sqrt(1.0 - wgs84::kE2 * s * s);  // prime vertical radius
  return {(n + g.height_m) * c * std::cos(g.longitude_rad), (n + g.height_m) * c * std::sin(g.longitude_rad),
          (n * (1.0 - wgs84::kE2) + g.height_m) * s};
}

Geodetic to_geodetic(const Eigen::Vector3d& r) {
  Geodetic g;
  g.longitude_rad = std::atan2(r.y(), r.x());
  const double p = std::hypot(r.x(), r.y());
  double lat = std::atan2(r.z(), p * (1.0 - wgs84::kE2));
  for (int i = 0; i < 8; ++i) {  // converges quadratically near the surface: 8 steps are plenty
    const double s = std::sin(lat);
    const double n = wgs84::kA_m / std::sqrt(1.0 - wgs84::kE2 * s * s);
    lat = std::atan2(r.z() + wgs84::kE2 * n * s, p);
  }
  const double s = std::sin(lat), c = std::cos(lat);
  g.latitude_rad = lat;
  // Height along the normal, well conditioned at any latitude (no division by cos(lat)).
  g.height_m = p * c + r.z() * s - wgs84::kA_m * std::sqrt(1.0 - wgs84::kE2 * s * s);
  return g;
}

Eigen::Matrix3d enu_to_ecef(double latitude_rad, double longitude_rad) {
  const double sp = std::sin(latitude_rad), cp = std::cos(latitude_rad);
  const double sl = std::sin(longitude_rad), cl = std::cos(longitude_rad);
  Eigen::Matrix3d m;
  m.col(0) << -sl, cl, 0.0;            // east
  m.col(1) << -sp * cl, -sp * sl, cp;  // north
  m.col(2) << cp * cl, cp * sl, sp;    // up
  return m;
}

LocalTangentPlane::LocalTangentPlane(const Geodetic& origin)
    : origin_(origin),
      origin_ecef_(to_ecef(origin)),
      enu_to_ecef_(enu_to_ecef(origin.latitude_rad, origin.longitude_rad)) {}

Geodetic LocalTangentPlane::to_geodetic(const Eigen::Vector3d& p_enu) const {
  return sensors::to_geodetic(origin_ecef_ + enu_to_ecef_ * p_enu);
}

Eigen::Vector3d LocalTangentPlane::to_enu(const Geodetic& g) const {
  return enu_to_ecef_.transpose() * (to_ecef(g) - origin_ecef_);
}

}  // namespace quadcosim::sensors
