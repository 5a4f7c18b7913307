#include "app/node_common.hpp"

namespace quadcosim::app {

io::Scenario scenario_or_defaults(const std::string& path, const std::string& vehicle_file) {
  io::Scenario sc;
  if (!path.empty()) {
    sc = io::load_scenario(path);
  } else {
    sc.name = "defaults";
  }
  if (!vehicle_file.empty()) sc.vehicle = io::load_vehicle(vehicle_file);
  sc.controller.params.vehicle = sc.vehicle;
  return sc;
}

void refuse_faults_over_dds(const io::Scenario& sc) {
  if (!sc.simulation.faults.active()) return;
  throw io::ConfigError((sc.path.empty() ? std::string("scenario") : sc.path) +
                        ": message_faults: message loss and delay are injected by the in-process transport only "
                        "(quadcosim run without --transport dds); over DDS use tc netem (docs/reliability.md)");
}

void use_sensor_qos(dds::DdsTransport& transport, const sim::Topics& topics) {
  for (const auto* t : {&topics.pose, &topics.velocity, &topics.imu}) {
    transport.set_qos(*t, dds::QosProfile::sensor_data());
  }
}

}  // namespace quadcosim::app
