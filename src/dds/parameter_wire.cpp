#include "dds/parameter_wire.hpp"

#include <atomic>
#include <cstring>
#include <iomanip>
#include <sstream>

namespace quadcosim::dds::wire {

ServiceTypes service_types(ParamService service) {
  switch (service) {
    case ParamService::kGet:
      return {&rcl_interfaces_srv_dds__GetParameters_Request__desc,
              &rcl_interfaces_srv_dds__GetParameters_Response__desc};
    case ParamService::kGetTypes:
      return {&rcl_interfaces_srv_dds__GetParameterTypes_Request__desc,
              &rcl_interfaces_srv_dds__GetParameterTypes_Response__desc};
    case ParamService::kSet:
      return {&rcl_interfaces_srv_dds__SetParameters_Request__desc,
              &rcl_interfaces_srv_dds__SetParameters_Response__desc};
    case ParamService::kSetAtomically:
      return {&rcl_interfaces_srv_dds__SetParametersAtomically_Request__desc,
              &rcl_interfaces_srv_dds__SetParametersAtomically_Response__desc};
    case ParamService::kDescribe:
      return {&rcl_interfaces_srv_dds__DescribeParameters_Request__desc,
              &rcl_interfaces_srv_dds__DescribeParameters_Response__desc};
    case ParamService::kList:
      return {&rcl_interfaces_srv_dds__ListParameters_Request__desc,
              &rcl_interfaces_srv_dds__ListParameters_Response__desc};
  }
  return {nullptr, nullptr};
}

std::shared_ptr<void> new_sample(const dds_topic_descriptor_t* desc) {
  void* p = dds_alloc(desc->m_size);
  std::memset(p, 0, desc->m_size);
  return std::shared_ptr<void>(p, [desc](void* q) { dds_sample_free(q, desc, DDS_FREE_ALL); });
}

namespace {

std::string own(const char* s) { return s ? std::string(s) : std::string(); }
char* dup(const std::string& s) { return dds_string_dup(s.c_str()); }

// A generated sequence sized `n`, zeroed, owned by the sample (freed with it).
template <class Seq>
void alloc(Seq& seq, std::size_t n) {
  using Elem = std::remove_pointer_t<decltype(seq._buffer)>;
  seq._maximum = seq._length = static_cast<std::uint32_t>(n);
  seq._release = true;
  seq._buffer = nullptr;
  if (n > 0) {
    seq._buffer = static_cast<Elem*>(dds_alloc(n * sizeof(Elem)));
    std::memset(static_cast<void*>(seq._buffer), 0, n * sizeof(Elem));
  }
}

template <class Seq, class T>
void copy_plain(const std::vector<T>& v, Seq& seq) {
  alloc(seq, v.size());
  for (std::size_t i = 0; i < v.size(); ++i) seq._buffer[i] = v[i];
}

template <class Seq, class T>
void copy_plain(const Seq& seq, std::vector<T>& v) {
  v.clear();
  v.reserve(seq._length);
  for (std::uint32_t i = 0; i < seq._length; ++i) v.push_back(seq._buffer[i]);
}

template <class T, class Seq>
std::vector<T> from_seq(const Seq& seq) {
  std::vector<T> v;
  v.reserve(seq._length);
  for (std::uint32_t i = 0; i < seq._length; ++i) v.push_back(from_c(seq._buffer[i]));
  return v;
}

template <class T, class Seq>
void to_seq(const std::vector<T>& v, Seq& seq) {
  alloc(seq, v.size());
  for (std::size_t i = 0; i < v.size(); ++i) to_c(v[i], seq._buffer[i]);
}

}  // namespace

std::vector<std::string> from_c(const dds_sequence_string& s) {
  std::vector<std::string> v;
  v.reserve(s._length);
  for (std::uint32_t i = 0; i < s._length; ++i) v.push_back(own(s._buffer[i]));
  return v;
}

void to_c(const std::vector<std::string>& v, dds_sequence_string& c) {
  alloc(c, v.size());
  for (std::size_t i = 0; i < v.size(); ++i) c._buffer[i] = dup(v[i]);
}

ParamValue from_c(const rcl_interfaces_msg_dds__ParameterValue_& c) {
  ParamValue v;
  v.type = static_cast<ParamType>(c.type);
  v.bool_value = c.bool_value;
  v.integer_value = c.integer_value;
  v.double_value = c.double_value;
  v.string_value = own(c.string_value);
  copy_plain(c.byte_array_value, v.byte_array_value);
  copy_plain(c.bool_array_value, v.bool_array_value);
  copy_plain(c.integer_array_value, v.integer_array_value);
  copy_plain(c.double_array_value, v.double_array_value);
  v.string_array_value = from_c(c.string_array_value);
  return v;
}

void to_c(const ParamValue& v, rcl_interfaces_msg_dds__ParameterValue_& c) {
  c.type = static_cast<std::uint8_t>(v.type);
  c.bool_value = v.bool_value;
  c.integer_value = v.integer_value;
  c.double_value = v.double_value;
  c.string_value = dup(v.string_value);
  copy_plain(v.byte_array_value, c.byte_array_value);
  alloc(c.bool_array_value, v.bool_array_value.size());  // std::vector<bool> has no contiguous storage
  for (std::size_t i = 0; i < v.bool_array_value.size(); ++i) c.bool_array_value._buffer[i] = v.bool_array_value[i];
  copy_plain(v.integer_array_value, c.integer_array_value);
  copy_plain(v.double_array_value, c.double_array_value);
  to_c(v.string_array_value, c.string_array_value);
}

Param from_c(const rcl_interfaces_msg_dds__Parameter_& c) { return {own(c.name), from_c(c.value)}; }

void to_c(const Param& v, rcl_interfaces_msg_dds__Parameter_& c) {
  c.name = dup(v.name);
  to_c(v.value, c.value);
}

SetResult from_c(const rcl_interfaces_msg_dds__SetParametersResult_& c) { return {c.successful, own(c.reason)}; }

void to_c(const SetResult& v, rcl_interfaces_msg_dds__SetParametersResult_& c) {
  c.successful = v.successful;
  c.reason = dup(v.reason);
}

ParamDescriptor from_c(const rcl_interfaces_msg_dds__ParameterDescriptor_& c) {
  ParamDescriptor d;
  d.name = own(c.name);
  d.type = static_cast<ParamType>(c.type);
  d.description = own(c.description);
  d.additional_constraints = own(c.additional_constraints);
  d.read_only = c.read_only;
  d.dynamic_typing = c.dynamic_typing;
  if (c.floating_point_range._length > 0) {
    const auto& r = c.floating_point_range._buffer[0];
    d.floating_point_range = FloatRange{r.from_value, r.to_value, r.step};
  }
  if (c.integer_range._length > 0) {
    const auto& r = c.integer_range._buffer[0];
    d.integer_range = IntRange{r.from_value, r.to_value, r.step};
  }
  return d;
}

void to_c(const ParamDescriptor& v, rcl_interfaces_msg_dds__ParameterDescriptor_& c) {
  c.name = dup(v.name);
  c.type = static_cast<std::uint8_t>(v.type);
  c.description = dup(v.description);
  c.additional_constraints = dup(v.additional_constraints);
  c.read_only = v.read_only;
  c.dynamic_typing = v.dynamic_typing;
  alloc(c.floating_point_range, v.floating_point_range ? 1 : 0);
  if (v.floating_point_range) {
    c.floating_point_range._buffer[0] = {v.floating_point_range->from_value, v.floating_point_range->to_value,
                                         v.floating_point_range->step};
  }
  alloc(c.integer_range, v.integer_range ? 1 : 0);
  if (v.integer_range) {
    c.integer_range._buffer[0] = {v.integer_range->from_value, v.integer_range->to_value, v.integer_range->step};
  }
}

ListResult from_c(const rcl_interfaces_msg_dds__ListParametersResult_& c) {
  return {from_c(c.names), from_c(c.prefixes)};
}

void to_c(const ListResult& v, rcl_interfaces_msg_dds__ListParametersResult_& c) {
  to_c(v.names, c.names);
  to_c(v.prefixes, c.prefixes);
}

std::vector<Param> from_c(const dds_sequence_rcl_interfaces_msg_dds__Parameter_& s) { return from_seq<Param>(s); }

void to_c(const std::vector<Param>& v, dds_sequence_rcl_interfaces_msg_dds__Parameter_& c) { to_seq(v, c); }
void to_c(const std::vector<ParamValue>& v, dds_sequence_rcl_interfaces_msg_dds__ParameterValue_& c) { to_seq(v, c); }
void to_c(const std::vector<SetResult>& v, dds_sequence_rcl_interfaces_msg_dds__SetParametersResult_& c) {
  to_seq(v, c);
}
void to_c(const std::vector<ParamDescriptor>& v, dds_sequence_rcl_interfaces_msg_dds__ParameterDescriptor_& c) {
  to_seq(v, c);
}
void to_c(const std::vector<std::uint8_t>& v, dds_sequence_uint8& c) { copy_plain(v, c); }

std::string endpoint_id(const dds_guid_t& participant, std::uint32_t counter) {
  std::uint8_t id[16];
  std::memcpy(id, participant.v, 12);  // the participant's GUID prefix
  for (int i = 0; i < 4; ++i) id[12 + i] = static_cast<std::uint8_t>(counter >> (24 - 8 * i));
  std::ostringstream os;
  os << std::hex << std::setw(2) << static_cast<int>(id[0]);
  for (int i = 1; i < 16; ++i) os << '.' << static_cast<int>(id[i]);
  return os.str();
}

std::string new_endpoint_id(dds_entity_t participant) {
  static std::atomic<std::uint32_t> counter{0};  // an id source only; no behaviour depends on it
  dds_guid_t guid;
  if (dds_get_guid(participant, &guid) < 0) guid = {};
  return endpoint_id(guid, ++counter);
}

std::string user_data_value(const dds_qos_t* qos, const std::string& key) {
  void* data = nullptr;
  size_t size = 0;
  if (qos == nullptr || !dds_qget_userdata(qos, &data, &size) || data == nullptr) return {};
  const std::string ud(static_cast<const char*>(data), size);
  dds_free(data);
  std::size_t pos = 0;
  while (pos < ud.size()) {
    std::size_t end = ud.find(';', pos);
    if (end == std::string::npos) end = ud.size();
    const std::string item = ud.substr(pos, end - pos);
    const auto eq = item.find('=');
    if (eq != std::string::npos && item.compare(0, eq, key) == 0 && eq == key.size()) return item.substr(eq + 1);
    pos = end + 1;
  }
  return {};
}

}  // namespace quadcosim::dds::wire
