#include "trajectory/periodic.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace quadcosim::trajectory {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

std::string g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

const char* yaw_name(YawMode m) {
  switch (m) {
    case YawMode::kFixed: return "fixed";
    case YawMode::kTangent: return "tangent";
    case YawMode::kCentre: return "centre";
  }
  return "?";
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

struct Curve {
  Eigen::Vector2d centre_m, amplitude_m, omega_rad_s, phase_rad;
  double altitude_m = 0, start_s = 0, ramp_s = 0;
  YawMode yaw_mode = YawMode::kFixed;
  double yaw_rad = 0;
  std::string text;  // describe()
};

class Periodic final : public Trajectory {
 public:
  explicit Periodic(Curve c) : c_(std::move(c)) {}

  FlatOutput at(double t_s) const override {
    // Time warp s(t) and its derivatives (header comment).
    double s = 0, s1 = 0, s2 = 0, s3 = 0;
    const double tau = t_s - c_.start_s;
    const double r = c_.ramp_s;
    if (tau <= 0) {
    } else if (tau < r) {
      const double u = tau / r, u2 = u * u, u3 = u2 * u;
      s = r * u2 * u2 * (2.5 - 3.0 * u + u2);
      s1 = u3 * (10.0 - 15.0 * u + 6.0 * u2);
      s2 = u2 * (30.0 - 60.0 * u + 30.0 * u2) / r;
      s3 = u * (60.0 - 180.0 * u + 120.0 * u2) / (r * r);
    } else {
      s = tau - 0.5 * r;
      s1 = 1.0;
    }
    // Derivatives of the curve in s (f0..f3), then in t by the chain rule.
    Eigen::Vector2d f0, f1, f2, f3;
    for (int i = 0; i < 2; ++i) {
      const double A = c_.amplitude_m[i], w = c_.omega_rad_s[i];
      const double sn = std::sin(w * s + c_.phase_rad[i]), cs = std::cos(w * s + c_.phase_rad[i]);
      f0[i] = A * sn;
      f1[i] = A * w * cs;
      f2[i] = -A * w * w * sn;
      f3[i] = -A * w * w * w * cs;
    }
    FlatOutput out;
    out.p_W << c_.centre_m + f0, c_.altitude_m;
    out.v_W << f1 * s1, 0.0;
    out.a_W << f2 * s1 * s1 + f1 * s2, 0.0;
    out.j_W << f3 * s1 * s1 * s1 + 3.0 * f2 * s1 * s2 + f1 * s3, 0.0;
    switch (c_.yaw_mode) {
      case YawMode::kFixed: out.yaw_rad = c_.yaw_rad; break;
      case YawMode::kTangent: {
        // Heading of f1 (v = f1 ds/dt with ds/dt >= 0); its rate = ds/dt (f1 x f2) / |f1|^2.
        out.yaw_rad = std::atan2(f1.y(), f1.x());
        const double n2 = f1.squaredNorm();
        out.yaw_rate_rad_s = n2 > 0 ? s1 * (f1.x() * f2.y() - f1.y() * f2.x()) / n2 : 0.0;
        break;
      }
      case YawMode::kCentre: {
        // d = centre - p, d' = -v: rate = (d x d') / |d|^2 (|d| = radius > 0).
        const Eigen::Vector2d d = -f0, dd = -out.v_W.head<2>();
        out.yaw_rad = std::atan2(d.y(), d.x());
        out.yaw_rate_rad_s = (d.x() * dd.y() - d.y() * dd.x()) / d.squaredNorm();
        break;
      }
    }
    return out;
  }

  double end_s() const override { return std::numeric_limits<double>::infinity(); }
  std::string describe() const override { return c_.text; }

 private:
  Curve c_;
};

std::string common_text(const Eigen::Vector2d& centre, double altitude, double start, double ramp, YawMode mode,
                        double yaw) {
  std::string t = " about (" + g(centre.x()) + ", " + g(centre.y()) + ") at " + g(altitude) + " m, from " + g(start) +
                  " s (spin-up " + g(ramp) + " s), yaw " + yaw_name(mode);
  if (mode == YawMode::kFixed) t += " " + g(yaw) + " rad";
  return t;
}

void check_common(const Eigen::Vector2d& centre, double altitude, double start, double ramp, double yaw) {
  require(centre.allFinite(), "centre must be finite");
  require(std::isfinite(altitude), "altitude must be finite");
  require(std::isfinite(start), "start_s must be finite");
  require(std::isfinite(ramp) && ramp >= 0, "ramp_s must be finite and >= 0");
  require(std::isfinite(yaw), "yaw must be finite");
}

}  // namespace

std::unique_ptr<Trajectory> make_circle(const CircleParams& p) {
  check_common(p.centre_m, p.altitude_m, p.start_s, p.ramp_s, p.yaw_rad);
  require(std::isfinite(p.radius_m) && p.radius_m > 0, "radius must be finite and > 0");
  require(std::isfinite(p.period_s) && p.period_s > 0, "period must be finite and > 0");
  require(std::isfinite(p.phase_rad), "phase must be finite");
  Curve c;
  c.centre_m = p.centre_m;
  c.altitude_m = p.altitude_m;
  c.amplitude_m = {p.radius_m, p.radius_m};
  const double w = (p.clockwise ? -kTwoPi : kTwoPi) / p.period_s;
  c.omega_rad_s = {w, w};
  c.phase_rad = {p.phase_rad + 0.5 * std::numbers::pi, p.phase_rad};  // x = r cos, y = r sin
  c.start_s = p.start_s;
  c.ramp_s = p.ramp_s;
  c.yaw_mode = p.yaw_mode;
  c.yaw_rad = p.yaw_rad;
  c.text = "circle r=" + g(p.radius_m) + " m, period " + g(p.period_s) + " s " + (p.clockwise ? "cw" : "ccw") +
           common_text(p.centre_m, p.altitude_m, p.start_s, p.ramp_s, p.yaw_mode, p.yaw_rad);
  return std::make_unique<Periodic>(std::move(c));
}

std::unique_ptr<Trajectory> make_lissajous(const LissajousParams& p) {
  check_common(p.centre_m, p.altitude_m, p.start_s, p.ramp_s, p.yaw_rad);
  require(p.amplitude_m.allFinite() && p.amplitude_m.minCoeff() >= 0, "amplitudes must be finite and >= 0");
  require(p.period_s.allFinite() && p.period_s.minCoeff() > 0, "periods must be finite and > 0");
  require(p.phase_rad.allFinite(), "phases must be finite");
  require(p.yaw_mode != YawMode::kCentre, "yaw 'centre' is for circles only (a Lissajous curve may cross its centre)");
  require(p.yaw_mode != YawMode::kTangent || p.amplitude_m.minCoeff() > 0,
          "yaw 'tangent' needs both amplitudes > 0 (on a line the direction of travel flips)");
  Curve c;
  c.centre_m = p.centre_m;
  c.altitude_m = p.altitude_m;
  c.amplitude_m = p.amplitude_m;
  c.omega_rad_s = {kTwoPi / p.period_s.x(), kTwoPi / p.period_s.y()};
  c.phase_rad = p.phase_rad;
  c.start_s = p.start_s;
  c.ramp_s = p.ramp_s;
  c.yaw_mode = p.yaw_mode;
  c.yaw_rad = p.yaw_rad;
  c.text = "lissajous A=(" + g(p.amplitude_m.x()) + ", " + g(p.amplitude_m.y()) + ") m, periods (" + g(p.period_s.x()) +
           ", " + g(p.period_s.y()) + ") s, phases (" + g(p.phase_rad.x()) + ", " + g(p.phase_rad.y()) + ") rad" +
           common_text(p.centre_m, p.altitude_m, p.start_s, p.ramp_s, p.yaw_mode, p.yaw_rad);
  return std::make_unique<Periodic>(std::move(c));
}

std::unique_ptr<Trajectory> make_figure8(const Figure8Params& p) {
  check_common(p.centre_m, p.altitude_m, p.start_s, p.ramp_s, p.yaw_rad);
  require(p.amplitude_m.allFinite() && p.amplitude_m.minCoeff() > 0, "amplitudes must be finite and > 0");
  require(std::isfinite(p.period_s) && p.period_s > 0, "period must be finite and > 0");
  require(p.yaw_mode != YawMode::kCentre, "yaw 'centre' is for circles only (a figure 8 crosses its centre)");
  Curve c;
  c.centre_m = p.centre_m;
  c.altitude_m = p.altitude_m;
  c.amplitude_m = p.amplitude_m;
  c.omega_rad_s = {kTwoPi / p.period_s, 2.0 * kTwoPi / p.period_s};
  c.phase_rad = Eigen::Vector2d::Zero();
  c.start_s = p.start_s;
  c.ramp_s = p.ramp_s;
  c.yaw_mode = p.yaw_mode;
  c.yaw_rad = p.yaw_rad;
  c.text = "figure8 A=(" + g(p.amplitude_m.x()) + ", " + g(p.amplitude_m.y()) + ") m, period " + g(p.period_s) + " s" +
           common_text(p.centre_m, p.altitude_m, p.start_s, p.ramp_s, p.yaw_mode, p.yaw_rad);
  return std::make_unique<Periodic>(std::move(c));
}

}  // namespace quadcosim::trajectory
