// The ROS 2 interface descriptions behind quadcosim's type hashes (dds/type_hash.hpp): every type
// quadcosim puts on the wire and every type those reference, field by field as the .msg / .srv files
// of ROS 2 Jazzy declare them (common_interfaces, rcl_interfaces, rmw_dds_common, service_msgs),
// and quadcosim's own types as src/dds/idl/quadcosim_msgs.idl lays them out. The .msg syntax is
// kept, with nested types fully qualified; `char` is uint8 and `byte` is octet, as rosidl maps them.
// A field changed here changes the hash that ROS 2 tools see: keep it equal to the upstream file.
#include "dds/type_hash.hpp"

namespace quadcosim::dds {

const std::vector<MessageDescription>& message_descriptions() {
  static const std::vector<MessageDescription> table = {
      {"builtin_interfaces/msg/Time",
       "int32 sec\n"
       "uint32 nanosec"},
      {"std_msgs/msg/Header",
       "builtin_interfaces/msg/Time stamp\n"
       "string frame_id"},
      {"std_msgs/msg/MultiArrayDimension",
       "string label\n"
       "uint32 size\n"
       "uint32 stride"},
      {"std_msgs/msg/MultiArrayLayout",
       "std_msgs/msg/MultiArrayDimension[] dim\n"
       "uint32 data_offset"},
      {"std_msgs/msg/Float64MultiArray",
       "std_msgs/msg/MultiArrayLayout layout\n"
       "float64[] data"},
      {"geometry_msgs/msg/Point",
       "float64 x\n"
       "float64 y\n"
       "float64 z"},
      {"geometry_msgs/msg/Quaternion",
       "float64 x\n"
       "float64 y\n"
       "float64 z\n"
       "float64 w"},
      {"geometry_msgs/msg/Pose",
       "geometry_msgs/msg/Point position\n"
       "geometry_msgs/msg/Quaternion orientation"},
      {"geometry_msgs/msg/PoseStamped",
       "std_msgs/msg/Header header\n"
       "geometry_msgs/msg/Pose pose"},
      {"geometry_msgs/msg/Vector3",
       "float64 x\n"
       "float64 y\n"
       "float64 z"},
      {"geometry_msgs/msg/Transform",
       "geometry_msgs/msg/Vector3 translation\n"
       "geometry_msgs/msg/Quaternion rotation"},
      {"geometry_msgs/msg/TransformStamped",
       "std_msgs/msg/Header header\n"
       "string child_frame_id\n"
       "geometry_msgs/msg/Transform transform"},
      {"tf2_msgs/msg/TFMessage", "geometry_msgs/msg/TransformStamped[] transforms"},
      {"std_msgs/msg/String", "string data"},
      {"geometry_msgs/msg/Twist",
       "geometry_msgs/msg/Vector3 linear\n"
       "geometry_msgs/msg/Vector3 angular"},
      {"geometry_msgs/msg/TwistStamped",
       "std_msgs/msg/Header header\n"
       "geometry_msgs/msg/Twist twist"},
      {"sensor_msgs/msg/Imu",
       "std_msgs/msg/Header header\n"
       "geometry_msgs/msg/Quaternion orientation\n"
       "float64[9] orientation_covariance\n"
       "geometry_msgs/msg/Vector3 angular_velocity\n"
       "float64[9] angular_velocity_covariance\n"
       "geometry_msgs/msg/Vector3 linear_acceleration\n"
       "float64[9] linear_acceleration_covariance"},
      {"sensor_msgs/msg/MagneticField",
       "std_msgs/msg/Header header\n"
       "geometry_msgs/msg/Vector3 magnetic_field\n"
       "float64[9] magnetic_field_covariance"},
      {"sensor_msgs/msg/FluidPressure",
       "std_msgs/msg/Header header\n"
       "float64 fluid_pressure\n"
       "float64 variance"},
      {"sensor_msgs/msg/NavSatStatus",
       "int8 status\n"
       "uint16 service"},
      {"sensor_msgs/msg/NavSatFix",
       "std_msgs/msg/Header header\n"
       "sensor_msgs/msg/NavSatStatus status\n"
       "float64 latitude\n"
       "float64 longitude\n"
       "float64 altitude\n"
       "float64[9] position_covariance\n"
       "uint8 position_covariance_type"},
      {"rosgraph_msgs/msg/Clock", "builtin_interfaces/msg/Time clock"},
      {"quadcosim_msgs/msg/ControllerStatus",
       "std_msgs/msg/Header header\n"
       "string controller\n"
       "string mode\n"
       "float64[6] setpoint\n"
       "float64[4] u\n"
       "float64[3] position_error\n"
       "float64 yaw_error\n"
       "float64 attitude_error\n"
       "bool[4] rotor_saturated\n"
       "bool tilt_saturated\n"
       "bool safety\n"
       "uint64 rejected_non_finite\n"
       "uint64 rejected_bad_quaternion\n"
       "uint64 rejected_bad_stamp\n"
       "uint64 rejected_stamp_backwards\n"
       "uint64 rejected_stamp_ahead\n"
       "string[] output_names\n"
       "float64[] outputs"},
      {"quadcosim_msgs/msg/PlantStatus",
       "std_msgs/msg/Header header\n"
       "uint64 commands_accepted\n"
       "uint64 commands_clamped\n"
       "uint64 commands_rejected_length\n"
       "uint64 commands_rejected_non_finite\n"
       "string last_problem\n"
       "bool watchdog_active\n"
       "uint64 watchdog_trips\n"
       "uint64 watchdog_ticks\n"
       "uint64 commands_stale\n"
       "uint64 commands_foreign"},
      // ros_discovery_info (Jazzy: 16-byte GIDs).
      {"rmw_dds_common/msg/Gid", "char[16] data"},
      {"rmw_dds_common/msg/NodeEntitiesInfo",
       "string<=256 node_namespace\n"
       "string<=256 node_name\n"
       "rmw_dds_common/msg/Gid[] reader_gid_seq\n"
       "rmw_dds_common/msg/Gid[] writer_gid_seq"},
      {"rmw_dds_common/msg/ParticipantEntitiesInfo",
       "rmw_dds_common/msg/Gid gid\n"
       "rmw_dds_common/msg/NodeEntitiesInfo[] node_entities_info_seq"},
      // Parameters.
      {"rcl_interfaces/msg/ParameterValue",
       "uint8 type\n"
       "bool bool_value\n"
       "int64 integer_value\n"
       "float64 double_value\n"
       "string string_value\n"
       "byte[] byte_array_value\n"
       "bool[] bool_array_value\n"
       "int64[] integer_array_value\n"
       "float64[] double_array_value\n"
       "string[] string_array_value"},
      {"rcl_interfaces/msg/Parameter",
       "string name\n"
       "rcl_interfaces/msg/ParameterValue value"},
      {"rcl_interfaces/msg/SetParametersResult",
       "bool successful\n"
       "string reason"},
      {"rcl_interfaces/msg/FloatingPointRange",
       "float64 from_value\n"
       "float64 to_value\n"
       "float64 step"},
      {"rcl_interfaces/msg/IntegerRange",
       "int64 from_value\n"
       "int64 to_value\n"
       "uint64 step"},
      {"rcl_interfaces/msg/ParameterDescriptor",
       "string name\n"
       "uint8 type\n"
       "string description\n"
       "string additional_constraints\n"
       "bool read_only\n"
       "bool dynamic_typing\n"
       "rcl_interfaces/msg/FloatingPointRange[<=1] floating_point_range\n"
       "rcl_interfaces/msg/IntegerRange[<=1] integer_range"},
      {"rcl_interfaces/msg/ListParametersResult",
       "string[] names\n"
       "string[] prefixes"},
      {"rcl_interfaces/msg/ParameterEvent",
       "builtin_interfaces/msg/Time stamp\n"
       "string node\n"
       "rcl_interfaces/msg/Parameter[] new_parameters\n"
       "rcl_interfaces/msg/Parameter[] changed_parameters\n"
       "rcl_interfaces/msg/Parameter[] deleted_parameters"},
      // What every service's event message carries (service_msgs/msg/ServiceEventInfo).
      {"service_msgs/msg/ServiceEventInfo",
       "uint8 event_type\n"
       "builtin_interfaces/msg/Time stamp\n"
       "char[16] client_gid\n"
       "int64 sequence_number"},
  };
  return table;
}

const std::vector<ServiceDescription>& service_descriptions() {
  static const std::vector<ServiceDescription> table = {
      {"rcl_interfaces/srv/GetParameters", "string[] names", "rcl_interfaces/msg/ParameterValue[] values"},
      {"rcl_interfaces/srv/GetParameterTypes", "string[] names", "uint8[] types"},
      {"rcl_interfaces/srv/SetParameters", "rcl_interfaces/msg/Parameter[] parameters",
       "rcl_interfaces/msg/SetParametersResult[] results"},
      {"rcl_interfaces/srv/SetParametersAtomically", "rcl_interfaces/msg/Parameter[] parameters",
       "rcl_interfaces/msg/SetParametersResult result"},
      {"rcl_interfaces/srv/ListParameters",
       "string[] prefixes\n"
       "uint64 depth",
       "rcl_interfaces/msg/ListParametersResult result"},
      {"rcl_interfaces/srv/DescribeParameters", "string[] names",
       "rcl_interfaces/msg/ParameterDescriptor[] descriptors"},
  };
  return table;
}

}  // namespace quadcosim::dds
