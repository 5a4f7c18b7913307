#include "trajectory/spec.hpp"

namespace quadcosim::trajectory {

std::shared_ptr<const Trajectory> make_trajectory(const TrajectorySpec& spec) {
  struct Make {
    std::shared_ptr<const Trajectory> operator()(const CircleParams& p) const { return make_circle(p); }
    std::shared_ptr<const Trajectory> operator()(const LissajousParams& p) const { return make_lissajous(p); }
    std::shared_ptr<const Trajectory> operator()(const Figure8Params& p) const { return make_figure8(p); }
    std::shared_ptr<const Trajectory> operator()(const WaypointsSpec& w) const {
      return std::make_shared<const PiecewisePolynomial>(plan_waypoints(w.points, w.method));
    }
    std::shared_ptr<const Trajectory> operator()(const PiecewisePolynomial& p) const {
      return std::make_shared<const PiecewisePolynomial>(p);
    }
  };
  return std::visit(Make{}, spec);
}

}  // namespace quadcosim::trajectory
