// Internal to the parameter server and client: conversions between the C types idlc generates from
// rcl_interfaces.idl and the C++ types of parameter_types.hpp, and the per-service descriptors.
//
// Memory: from_c copies out of a sample (which may be a loan). to_c fills a C struct with memory from
// dds_alloc / dds_string_dup and sets every sequence's _release, so the whole sample is freed with
// dds_sample_free(sample, descriptor, DDS_FREE_CONTENTS or DDS_FREE_ALL).
#pragma once

#include <dds/dds.h>

#include <memory>
#include <string>
#include <vector>

#include "dds/parameter_types.hpp"
#include "rcl_interfaces.h"

namespace quadcosim::dds::wire {

struct ServiceTypes {
  const dds_topic_descriptor_t* request;
  const dds_topic_descriptor_t* response;
};
/// The request and response types of `service` ("rcl_interfaces::srv::dds_::GetParameters_Request_",
/// ...).
ServiceTypes service_types(ParamService service);

/// A zeroed heap sample of a generated type, freed (with everything to_c put in it) with
/// dds_sample_free(DDS_FREE_ALL) when the last owner lets go.
std::shared_ptr<void> new_sample(const dds_topic_descriptor_t* desc);

std::vector<std::string> from_c(const dds_sequence_string& s);
ParamValue from_c(const rcl_interfaces_msg_dds__ParameterValue_& c);
Param from_c(const rcl_interfaces_msg_dds__Parameter_& c);
SetResult from_c(const rcl_interfaces_msg_dds__SetParametersResult_& c);
ParamDescriptor from_c(const rcl_interfaces_msg_dds__ParameterDescriptor_& c);
ListResult from_c(const rcl_interfaces_msg_dds__ListParametersResult_& c);
std::vector<Param> from_c(const dds_sequence_rcl_interfaces_msg_dds__Parameter_& s);

void to_c(const std::vector<std::string>& v, dds_sequence_string& c);
void to_c(const ParamValue& v, rcl_interfaces_msg_dds__ParameterValue_& c);
void to_c(const Param& v, rcl_interfaces_msg_dds__Parameter_& c);
void to_c(const SetResult& v, rcl_interfaces_msg_dds__SetParametersResult_& c);
void to_c(const ParamDescriptor& v, rcl_interfaces_msg_dds__ParameterDescriptor_& c);
void to_c(const ListResult& v, rcl_interfaces_msg_dds__ListParametersResult_& c);
void to_c(const std::vector<Param>& v, dds_sequence_rcl_interfaces_msg_dds__Parameter_& c);
void to_c(const std::vector<ParamValue>& v, dds_sequence_rcl_interfaces_msg_dds__ParameterValue_& c);
void to_c(const std::vector<SetResult>& v, dds_sequence_rcl_interfaces_msg_dds__SetParametersResult_& c);
void to_c(const std::vector<ParamDescriptor>& v, dds_sequence_rcl_interfaces_msg_dds__ParameterDescriptor_& c);
void to_c(const std::vector<std::uint8_t>& v, dds_sequence_uint8& c);

/// "clientid=" / "serviceid=" USER_DATA value in rmw_cyclonedds's format: the 16 bytes as hex, the
/// first two digits wide, the rest unpadded, separated by '.'.
std::string endpoint_id(const dds_guid_t& participant, std::uint32_t counter);
/// endpoint_id of `participant` with a fresh counter (one counter per process, so ids are unique
/// on the domain), for a service's or a client's pair of endpoints.
std::string new_endpoint_id(dds_entity_t participant);

/// The value of `key` in an endpoint's USER_DATA ("k1=v1;k2=v2;"), or "" when absent.
std::string user_data_value(const dds_qos_t* qos, const std::string& key);

}  // namespace quadcosim::dds::wire
