// The controller node's declared parameter table (control/parameters.hpp) as ROS 2 parameters, for
// the DDS parameter services: numbers are DOUBLE (with their range as floating_point_range), choices
// are STRING; setting goes through ControllerNode::set_parameter, whose reason a refusal carries.
#pragma once

#include "dds/parameter_service.hpp"
#include "sim/controller_node.hpp"

namespace quadcosim::hosts {

/// A declared parameter's value as a ROS 2 ParameterValue: numbers DOUBLE, choices STRING.
dds::ParamValue to_ros(const control::ParameterValue& value);

/// Callbacks bound to `node` (which must outlive them).
dds::ParameterCallbacks controller_parameter_callbacks(sim::ControllerNode& node);

}  // namespace quadcosim::hosts
