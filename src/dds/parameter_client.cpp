#include "dds/parameter_client.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "dds/parameter_wire.hpp"
#include "dds/steady_clock.hpp"
#include "dds/type_hash.hpp"

namespace quadcosim::dds {

namespace {

std::string seconds(std::int64_t ns) {
  std::ostringstream os;
  os << static_cast<double>(ns) / 1e9 << " s";
  return os.str();
}

}  // namespace

ParameterClient::ParameterClient(const RosEnvironment& env, NodeName node)
    : own_participant_(std::make_unique<Participant>(env)),
      participant_(own_participant_->handle()),
      node_(std::move(node)) {
  waitset_ = Entity(check(dds_create_waitset(participant_), "dds_create_waitset"));
}

ParameterClient::ParameterClient(dds_entity_t participant, NodeName node)
    : participant_(participant), node_(std::move(node)) {
  waitset_ = Entity(check(dds_create_waitset(participant_), "dds_create_waitset"));
}

// The endpoints, then the waitset, then an own participant go with the members (in that order).
ParameterClient::~ParameterClient() = default;

ParameterClient::Endpoints& ParameterClient::endpoints(ParamService service) {
  Endpoints& kept = ep_[index(service)];
  if (kept.writer > 0) return kept;
  // Built in a local set, kept only once complete: a failure part way deletes what was created and
  // leaves the service's slot empty (the next call tries again).
  Endpoints e;
  const wire::ServiceTypes types = wire::service_types(service);
  const std::string rq = request_topic(node_, service), rr = reply_topic(node_, service);
  e.request_topic = Entity(check(dds_create_topic(participant_, types.request, rq.c_str(), nullptr, nullptr),
                                 ("dds_create_topic " + rq).c_str()));
  e.reply_topic = Entity(check(dds_create_topic(participant_, types.response, rr.c_str(), nullptr, nullptr),
                               ("dds_create_topic " + rr).c_str()));
  // rclpy's parameter client uses the parameter-service profile: KEEP_LAST 1000, RELIABLE, VOLATILE.
  // One client id on both endpoints, each followed by the hash of its own message type (rmw_cyclonedds).
  const Qos qos(ros_qos(1000, true));
  const std::string client_id = "clientid=" + wire::new_endpoint_id(participant_) + ";";
  set_endpoint_user_data(qos.get(), types.request->m_typename, client_id);
  e.writer = Entity(
      check(dds_create_writer(participant_, e.request_topic, qos.get(), nullptr), ("dds_create_writer " + rq).c_str()));
  set_endpoint_user_data(qos.get(), types.response->m_typename, client_id);
  e.reader = Entity(
      check(dds_create_reader(participant_, e.reply_topic, qos.get(), nullptr), ("dds_create_reader " + rr).c_str()));
  check(dds_get_instance_handle(e.writer, &e.writer_handle), "dds_get_instance_handle");
  e.read_condition = Entity(check(dds_create_readcondition(e.reader, DDS_ANY_STATE), "dds_create_readcondition"));
  // Matching wakes the waitset, so waiting for the service needs no polling.
  check(dds_set_status_mask(e.writer, DDS_PUBLICATION_MATCHED_STATUS), "dds_set_status_mask");
  check(dds_set_status_mask(e.reader, DDS_SUBSCRIPTION_MATCHED_STATUS), "dds_set_status_mask");
  check(dds_waitset_attach(waitset_, e.writer, 0), "dds_waitset_attach");
  check(dds_waitset_attach(waitset_, e.reader, 0), "dds_waitset_attach");
  check(dds_waitset_attach(waitset_, e.read_condition, 0), "dds_waitset_attach");
  kept = std::move(e);
  return kept;
}

namespace {
/// True when one of the endpoints matched by `entity` (a writer's subscriptions, a reader's
/// publications) belongs to `participant`.
bool matches_participant(dds_entity_t entity, bool writer, const std::array<std::uint8_t, 16>& participant) {
  dds_instance_handle_t handles[64];
  const dds_return_t n =
      writer ? dds_get_matched_subscriptions(entity, handles, 64) : dds_get_matched_publications(entity, handles, 64);
  for (dds_return_t i = 0; i < std::min<dds_return_t>(n, 64); ++i) {
    dds_builtintopic_endpoint_t* e = writer ? dds_get_matched_subscription_data(entity, handles[i])
                                            : dds_get_matched_publication_data(entity, handles[i]);
    if (e == nullptr) continue;
    const bool same = std::equal(std::begin(e->participant_key.v), std::end(e->participant_key.v), participant.begin());
    dds_builtintopic_free_endpoint(e);
    if (same) return true;
  }
  return false;
}
}  // namespace

bool ParameterClient::matched(const Endpoints& e) const {
  dds_publication_matched_status_t pub;
  dds_subscription_matched_status_t sub;
  const bool any = dds_get_publication_matched_status(e.writer, &pub) >= 0 && pub.current_count > 0 &&
                   dds_get_subscription_matched_status(e.reader, &sub) >= 0 && sub.current_count > 0;
  if (!any || !peer_) return any;
  // With only_from(): the peer's own request reader and reply writer (a namesake's do not answer).
  // Once found they stay matched for the peer's life: looked up once per service.
  if (e.peer_matched) return true;
  e.peer_matched = matches_participant(e.writer, true, *peer_) && matches_participant(e.reader, false, *peer_);
  return e.peer_matched;
}

void ParameterClient::wait(std::int64_t deadline_ns, const Endpoints* active) {
  const std::int64_t left = deadline_ns - steady_ns();
  if (left > 0) check(dds_waitset_wait(waitset_, nullptr, 0, left), "dds_waitset_wait");
  std::uint32_t status = 0;
  for (const Endpoints& e : ep_) {
    if (e.writer <= 0) continue;
    dds_take_status(e.writer, &status, DDS_PUBLICATION_MATCHED_STATUS);
    dds_take_status(e.reader, &status, DDS_SUBSCRIPTION_MATCHED_STATUS);
    if (&e == active) continue;
    // Calls are one at a time, so anything in another service's reader is a stale reply (to a call
    // that timed out, or to another client): drop it, or its read condition keeps the waitset awake.
    for (;;) {
      void* samples[8] = {nullptr};
      dds_sample_info_t infos[8];
      const dds_return_t n = dds_take(e.reader, samples, infos, 8, 8);
      if (n <= 0) break;
      dds_return_loan(e.reader, samples, n);
    }
  }
}

bool ParameterClient::wait_for_service(ParamService service, std::int64_t timeout_ns) {
  const std::int64_t deadline = steady_ns() + timeout_ns;
  const Endpoints& e = endpoints(service);
  while (!matched(e)) {
    if (steady_ns() >= deadline) return false;
    wait(deadline, &e);
  }
  return true;
}

std::string ParameterClient::describe_matches(ParamService service) const {
  const Endpoints& e = ep_[index(service)];
  dds_publication_matched_status_t pub{};
  dds_subscription_matched_status_t sub{};
  dds_get_publication_matched_status(e.writer, &pub);
  dds_get_subscription_matched_status(e.reader, &sub);
  dds_domainid_t domain = 0;
  dds_get_domainid(participant_, &domain);
  std::ostringstream os;
  os << request_topic(node_, service) << " matched by " << pub.current_count << " reader(s), "
     << reply_topic(node_, service) << " by " << sub.current_count << " writer(s), on ROS_DOMAIN_ID " << domain;
  return os.str();
}

namespace {
// Every request and reply type starts with the in-band header {uint64 guid; int64 seq}.
struct InBandHeader {
  std::uint64_t guid;
  std::int64_t seq;
};
}  // namespace

void ParameterClient::send(ParamService service, void* request) {
  Endpoints& e = endpoints(service);
  auto* header = static_cast<InBandHeader*>(request);
  header->guid = e.writer_handle;
  header->seq = ++next_seq_;
  last_ = {header->guid, header->seq};
  write_now(e.writer, request, ("dds_write " + request_topic(node_, service)).c_str());
}

ParameterClient::Header ParameterClient::send_get(const std::vector<std::string>& names) {
  if (!matched(endpoints(ParamService::kGet))) {
    throw ParameterCallError("node " + node_.fully_qualified() + ": no " +
                             std::string(service_suffix(ParamService::kGet)) + " service matched (" +
                             describe_matches(ParamService::kGet) + ")");
  }
  auto rq = wire::new_sample(wire::service_types(ParamService::kGet).request);
  wire::to_c(names, static_cast<rcl_interfaces_srv_dds__GetParameters_Request_*>(rq.get())->names);
  send(ParamService::kGet, rq.get());
  return last_;
}

void ParameterClient::only_from(const std::array<std::uint8_t, 16>& participant) {
  peer_ = participant;
  peer_writers_.clear();
  for (Endpoints& e : ep_) e.peer_matched = false;
}

bool ParameterClient::from_peer(dds_entity_t reader, dds_instance_handle_t writer) {
  if (!peer_) return true;
  if (std::find(peer_writers_.begin(), peer_writers_.end(), writer) != peer_writers_.end()) return true;
  dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(reader, writer);
  if (e == nullptr) return false;  // gone, or not described yet: not known to be the peer's
  const bool ok = std::equal(std::begin(e->participant_key.v), std::end(e->participant_key.v), peer_->begin());
  dds_builtintopic_free_endpoint(e);
  if (ok) peer_writers_.push_back(writer);
  return ok;
}

bool ParameterClient::is_reply_to(const void* reply, Header request) {
  const auto* h = static_cast<const InBandHeader*>(reply);
  return h->guid == request.guid && h->seq == request.seq;
}

void ParameterClient::call(ParamService service, void* request, std::int64_t timeout_ns,
                           const std::function<void(const void* reply)>& on_reply) {
  const std::int64_t start = steady_ns(), deadline = start + timeout_ns;
  Endpoints& e = endpoints(service);
  if (!wait_for_service(service, deadline - start)) {
    throw ParameterCallError("node " + node_.fully_qualified() + " not found: no " +
                             std::string(service_suffix(service)) + " service within " + seconds(timeout_ns) + " (" +
                             describe_matches(service) + "); is the node running on this domain?");
  }
  send(service, request);

  for (;;) {
    constexpr int kBatch = 8;
    void* samples[kBatch] = {nullptr};
    dds_sample_info_t infos[kBatch];
    const dds_return_t n = check(dds_take(e.reader, samples, infos, kBatch, kBatch), "dds_take (parameter reply)");
    bool done = false;
    for (int i = 0; i < n && !done; ++i) {
      if (!infos[i].valid_data || !is_reply_to(samples[i], last_)) continue;  // another client's
      if (!from_peer(e.reader, infos[i].publication_handle)) continue;        // a namesake's
      on_reply(samples[i]);
      done = true;
    }
    if (n > 0) dds_return_loan(e.reader, samples, n);
    if (done) return;
    if (n == kBatch) continue;
    if (steady_ns() >= deadline) {
      throw ParameterCallError("node " + node_.fully_qualified() + " did not answer " +
                               std::string(service_suffix(service)) + " (seq " + std::to_string(last_.seq) +
                               ") within " + seconds(timeout_ns) + " (" + describe_matches(service) + ")");
    }
    wait(deadline, &e);
  }
}

std::vector<ParamValue> ParameterClient::get(const std::vector<std::string>& names, std::int64_t timeout_ns) {
  auto rq = wire::new_sample(wire::service_types(ParamService::kGet).request);
  wire::to_c(names, static_cast<rcl_interfaces_srv_dds__GetParameters_Request_*>(rq.get())->names);
  std::vector<ParamValue> out;
  call(ParamService::kGet, rq.get(), timeout_ns, [&](const void* reply) {
    const auto& rp = *static_cast<const rcl_interfaces_srv_dds__GetParameters_Response_*>(reply);
    for (std::uint32_t i = 0; i < rp.values._length; ++i) out.push_back(wire::from_c(rp.values._buffer[i]));
  });
  return out;
}

std::vector<ParamType> ParameterClient::get_types(const std::vector<std::string>& names, std::int64_t timeout_ns) {
  auto rq = wire::new_sample(wire::service_types(ParamService::kGetTypes).request);
  wire::to_c(names, static_cast<rcl_interfaces_srv_dds__GetParameterTypes_Request_*>(rq.get())->names);
  std::vector<ParamType> out;
  call(ParamService::kGetTypes, rq.get(), timeout_ns, [&](const void* reply) {
    const auto& rp = *static_cast<const rcl_interfaces_srv_dds__GetParameterTypes_Response_*>(reply);
    for (std::uint32_t i = 0; i < rp.types._length; ++i) out.push_back(static_cast<ParamType>(rp.types._buffer[i]));
  });
  return out;
}

std::vector<SetResult> ParameterClient::set(const std::vector<Param>& parameters, std::int64_t timeout_ns) {
  auto rq = wire::new_sample(wire::service_types(ParamService::kSet).request);
  wire::to_c(parameters, static_cast<rcl_interfaces_srv_dds__SetParameters_Request_*>(rq.get())->parameters);
  std::vector<SetResult> out;
  call(ParamService::kSet, rq.get(), timeout_ns, [&](const void* reply) {
    const auto& rp = *static_cast<const rcl_interfaces_srv_dds__SetParameters_Response_*>(reply);
    for (std::uint32_t i = 0; i < rp.results._length; ++i) out.push_back(wire::from_c(rp.results._buffer[i]));
  });
  return out;
}

SetResult ParameterClient::set_atomically(const std::vector<Param>& parameters, std::int64_t timeout_ns) {
  auto rq = wire::new_sample(wire::service_types(ParamService::kSetAtomically).request);
  wire::to_c(parameters, static_cast<rcl_interfaces_srv_dds__SetParametersAtomically_Request_*>(rq.get())->parameters);
  SetResult out;
  call(ParamService::kSetAtomically, rq.get(), timeout_ns, [&](const void* reply) {
    out = wire::from_c(static_cast<const rcl_interfaces_srv_dds__SetParametersAtomically_Response_*>(reply)->result);
  });
  return out;
}

std::vector<ParamDescriptor> ParameterClient::describe(const std::vector<std::string>& names, std::int64_t timeout_ns) {
  auto rq = wire::new_sample(wire::service_types(ParamService::kDescribe).request);
  wire::to_c(names, static_cast<rcl_interfaces_srv_dds__DescribeParameters_Request_*>(rq.get())->names);
  std::vector<ParamDescriptor> out;
  call(ParamService::kDescribe, rq.get(), timeout_ns, [&](const void* reply) {
    const auto& rp = *static_cast<const rcl_interfaces_srv_dds__DescribeParameters_Response_*>(reply);
    for (std::uint32_t i = 0; i < rp.descriptors._length; ++i) out.push_back(wire::from_c(rp.descriptors._buffer[i]));
  });
  return out;
}

ListResult ParameterClient::list(const std::vector<std::string>& prefixes, std::uint64_t depth,
                                 std::int64_t timeout_ns) {
  auto rq = wire::new_sample(wire::service_types(ParamService::kList).request);
  auto& r = *static_cast<rcl_interfaces_srv_dds__ListParameters_Request_*>(rq.get());
  wire::to_c(prefixes, r.prefixes);
  r.depth = depth;
  ListResult out;
  call(ParamService::kList, rq.get(), timeout_ns, [&](const void* reply) {
    out = wire::from_c(static_cast<const rcl_interfaces_srv_dds__ListParameters_Response_*>(reply)->result);
  });
  return out;
}

}  // namespace quadcosim::dds
