#include "sim/swarm_layout.hpp"

#include <algorithm>
#include <cmath>

namespace quadcosim::sim {

std::string vehicle_namespace(const std::string& prefix, int index, int vehicles) {
  int width = 1;
  for (int n = std::max(vehicles - 1, 1); n >= 10; n /= 10) ++width;
  width = std::max(width, 4);
  std::string digits = std::to_string(index);
  if (static_cast<int>(digits.size()) < width) digits.insert(0, static_cast<std::size_t>(width) - digits.size(), '0');
  return prefix + digits;
}

Eigen::Vector3d vehicle_offset_W(const SwarmLayout& layout, int index) {
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(layout.vehicles))));
  const int column = index % columns, row = index / columns;
  return {column * layout.spacing_m, row * layout.spacing_m, (index % layout.altitude_layers) * layout.layer_spacing_m};
}

SwarmVehicle swarm_vehicle(const SimulationConfig& simulation, const model::State& initial,
                           const control::ControllerConfig& controller,
                           const std::vector<ScheduledParameter>& schedule, const SwarmLayout& layout,
                           int index) {
  const Eigen::Vector3d o = vehicle_offset_W(layout, index);
  SwarmVehicle v{simulation, initial, controller, schedule};
  v.simulation.ns = vehicle_namespace(layout.ns_prefix, index, layout.vehicles);
  v.initial.p_W.x() += o.x();
  v.initial.p_W.y() += o.y();
  v.controller.setpoint.p_des_W += o;
  for (ScheduledParameter& p : v.schedule) {
    const int axis = p.name == "x_des" ? 0 : p.name == "y_des" ? 1 : p.name == "z_des" ? 2 : -1;
    if (axis >= 0 && std::holds_alternative<double>(p.value)) p.value = std::get<double>(p.value) + o[axis];
  }
  return v;
}

}  // namespace quadcosim::sim
