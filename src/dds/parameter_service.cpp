#include "dds/parameter_service.hpp"

#include <chrono>
#include <cstring>

#include "dds/dds_transport.hpp"
#include "dds/parameter_wire.hpp"
#include "dds/participant.hpp"
#include "dds/steady_clock.hpp"
#include "dds/type_hash.hpp"

namespace quadcosim::dds {

namespace {

std::vector<dds_instance_handle_t> matched_subscriptions(dds_entity_t writer) {
  std::vector<dds_instance_handle_t> h(8);
  for (;;) {
    const dds_return_t n = dds_get_matched_subscriptions(writer, h.data(), h.size());
    if (n < 0) return {};
    if (static_cast<std::size_t>(n) <= h.size()) {
      h.resize(static_cast<std::size_t>(n));
      return h;
    }
    h.resize(static_cast<std::size_t>(n));
  }
}

}  // namespace

ParameterServer::ParameterServer(dds_entity_t participant, NodeName node, ParameterCallbacks callbacks,
                                 ParameterServerOptions options)
    : participant_(participant), node_(std::move(node)), cb_(std::move(callbacks)), options_(options) {
  if (!cb_.names || !cb_.get || !cb_.set || !cb_.describe) {
    throw DdsError("ParameterServer: every parameter callback (names, get, set, describe) is required");
  }
  for (ParamService s : kParamServices) {
    const wire::ServiceTypes types = wire::service_types(s);
    const std::string rq = request_topic(node_, s), rr = reply_topic(node_, s);
    Endpoints& e = ep_[index(s)];
    e.request_topic = Entity(check(dds_create_topic(participant_, types.request, rq.c_str(), nullptr, nullptr),
                                   ("dds_create_topic " + rq).c_str()));
    e.reply_topic = Entity(check(dds_create_topic(participant_, types.response, rr.c_str(), nullptr, nullptr),
                                 ("dds_create_topic " + rr).c_str()));
    // One service id on both endpoints, each followed by the hash of its own message type (rmw_cyclonedds).
    const Qos qos(ros_qos(options_.depth, true));
    const std::string service_id = "serviceid=" + wire::new_endpoint_id(participant_) + ";";
    set_endpoint_user_data(qos.get(), types.request->m_typename, service_id);
    e.reader = Entity(check(dds_create_reader(participant_, e.request_topic, qos.get(), nullptr),
                            ("dds_create_reader " + rq).c_str()));
    set_endpoint_user_data(qos.get(), types.response->m_typename, service_id);
    e.writer = Entity(
        check(dds_create_writer(participant_, e.reply_topic, qos.get(), nullptr), ("dds_create_writer " + rr).c_str()));
    e.read_condition = Entity(check(dds_create_readcondition(e.reader, DDS_ANY_STATE), "dds_create_readcondition"));
    // A client's reply reader being matched wakes the server, so a waiting reply goes out at once.
    check(dds_set_status_mask(e.writer, DDS_PUBLICATION_MATCHED_STATUS), "dds_set_status_mask");
  }
  if (options_.publish_events) {
    events_topic_ = Entity(check(dds_create_topic(participant_, &rcl_interfaces_msg_dds__ParameterEvent__desc,
                                                  "rt/parameter_events", nullptr, nullptr),
                                 "dds_create_topic rt/parameter_events"));
    const Qos qos(ros_qos(1000, true));
    set_endpoint_user_data(qos.get(), rcl_interfaces_msg_dds__ParameterEvent__desc.m_typename);
    events_writer_ = Entity(check(dds_create_writer(participant_, events_topic_, qos.get(), nullptr),
                                  "dds_create_writer rt/parameter_events"));
  }
}

ParameterServer::ParameterServer(DdsTransport& transport, NodeName node, ParameterCallbacks callbacks,
                                 ParameterServerOptions options)
    : ParameterServer(transport.participant().handle(), std::move(node), std::move(callbacks), options) {
  transport_ = &transport;
  transport_work_id_ = transport.add_extra_work(wake_entities(), [this] { serve(); });
}

ParameterServer::~ParameterServer() {
  if (transport_) transport_->remove_extra_work(transport_work_id_);
  pending_.clear();
  // Then the endpoints and their topics go with the members (dds/entity.hpp).
}

std::vector<dds_entity_t> ParameterServer::wake_entities() const {
  std::vector<dds_entity_t> v;
  for (const Endpoints& e : ep_) {
    v.push_back(e.read_condition);
    v.push_back(e.writer);
  }
  return v;
}

int ParameterServer::serve() {
  int taken = 0;
  std::uint32_t status = 0;
  for (ParamService s : kParamServices) {
    dds_take_status(ep_[index(s)].writer, &status, DDS_PUBLICATION_MATCHED_STATUS);
    take_requests(s, taken);
  }
  send_pending();
  return taken;
}

void ParameterServer::take_requests(ParamService service, int& taken) {
  constexpr int kBatch = 8;
  const Endpoints& e = ep_[index(service)];
  for (;;) {
    void* samples[kBatch] = {nullptr};
    dds_sample_info_t infos[kBatch];
    const dds_return_t n = check(dds_take(e.reader, samples, infos, kBatch, kBatch), "dds_take (parameter request)");
    if (n == 0) break;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      ++taken;
      ++stats_.requests;
      pending_.push_back(
          {service, infos[i].publication_handle, steady_ns() + options_.reply_wait_ns, answer(service, samples[i])});
    }
    dds_return_loan(e.reader, samples, n);
    if (n < kBatch) break;
  }
}

SetResult ParameterServer::set_one(const Param& p, std::vector<Param>& changed) {
  ParamValue v = p.value;
  const std::optional<ParamValue> current = cb_.get(p.name);
  if (current && current->type == ParamType::kDouble && v.type == ParamType::kInteger) {
    v = ParamValue::of_double(static_cast<double>(v.integer_value));  // `ros2 param set NODE z_des 10`
  }
  if (current && v.type == ParamType::kNotSet) {
    return {false, "parameter '" + p.name + "' cannot be undeclared"};
  }
  if (std::string err = cb_.set(p.name, v); !err.empty()) return {false, err};
  changed.push_back({p.name, cb_.get(p.name).value_or(v)});
  return {true, ""};
}

void ParameterServer::publish_event(const std::vector<Param>& changed) {
  if (!events_writer_ || changed.empty()) return;
  auto sample = wire::new_sample(&rcl_interfaces_msg_dds__ParameterEvent__desc);
  auto& ev = *static_cast<rcl_interfaces_msg_dds__ParameterEvent_*>(sample.get());
  // rclcpp stamps events with the node's clock: system time unless use_sim_time.
  const auto now =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  ev.stamp.sec = static_cast<std::int32_t>(now / 1'000'000'000);
  ev.stamp.nanosec = static_cast<std::uint32_t>(now % 1'000'000'000);
  ev.node = dds_string_dup(node_.fully_qualified().c_str());
  wire::to_c(std::vector<Param>{}, ev.new_parameters);
  wire::to_c(changed, ev.changed_parameters);
  wire::to_c(std::vector<Param>{}, ev.deleted_parameters);
  write_now(events_writer_, sample.get(), "dds_write rt/parameter_events");
  ++stats_.events;
}

std::shared_ptr<void> ParameterServer::answer(ParamService service, const void* request) {
  auto reply = wire::new_sample(wire::service_types(service).response);
  // Every request and response type starts with the in-band header; the reply echoes it.
  auto echo = [&](const auto& rq, auto& rp) {
    rp.guid = rq.guid;
    rp.seq = rq.seq;
  };
  // rclcpp answers get / types / describe with nothing when a name is not declared.
  auto all_declared = [&](const std::vector<std::string>& names) {
    for (const auto& n : names) {
      if (!cb_.get(n)) return false;
    }
    return true;
  };
  switch (service) {
    case ParamService::kGet: {
      const auto& rq = *static_cast<const rcl_interfaces_srv_dds__GetParameters_Request_*>(request);
      auto& rp = *static_cast<rcl_interfaces_srv_dds__GetParameters_Response_*>(reply.get());
      echo(rq, rp);
      const auto names = wire::from_c(rq.names);
      std::vector<ParamValue> values;
      if (all_declared(names)) {
        for (const auto& n : names) values.push_back(*cb_.get(n));
      }
      wire::to_c(values, rp.values);
      break;
    }
    case ParamService::kGetTypes: {
      const auto& rq = *static_cast<const rcl_interfaces_srv_dds__GetParameterTypes_Request_*>(request);
      auto& rp = *static_cast<rcl_interfaces_srv_dds__GetParameterTypes_Response_*>(reply.get());
      echo(rq, rp);
      const auto names = wire::from_c(rq.names);
      std::vector<std::uint8_t> types;
      if (all_declared(names)) {
        for (const auto& n : names) types.push_back(static_cast<std::uint8_t>(cb_.get(n)->type));
      }
      wire::to_c(types, rp.types);
      break;
    }
    case ParamService::kSet: {
      const auto& rq = *static_cast<const rcl_interfaces_srv_dds__SetParameters_Request_*>(request);
      auto& rp = *static_cast<rcl_interfaces_srv_dds__SetParameters_Response_*>(reply.get());
      echo(rq, rp);
      std::vector<SetResult> results;
      std::vector<Param> changed;
      for (const Param& p : wire::from_c(rq.parameters)) results.push_back(set_one(p, changed));
      wire::to_c(results, rp.results);
      publish_event(changed);
      break;
    }
    case ParamService::kSetAtomically: {
      const auto& rq = *static_cast<const rcl_interfaces_srv_dds__SetParametersAtomically_Request_*>(request);
      auto& rp = *static_cast<rcl_interfaces_srv_dds__SetParametersAtomically_Response_*>(reply.get());
      echo(rq, rp);
      // Apply in order; on a refusal undo in reverse order, which passes back through states that
      // were already accepted.
      std::vector<Param> before, changed;
      SetResult result{true, ""};
      for (const Param& p : wire::from_c(rq.parameters)) {
        const std::optional<ParamValue> old = cb_.get(p.name);
        result = set_one(p, changed);
        if (!result.successful) break;
        if (old) before.push_back({p.name, *old});
      }
      if (!result.successful) {
        for (auto it = before.rbegin(); it != before.rend(); ++it) cb_.set(it->name, it->value);
        changed.clear();
      }
      wire::to_c(result, rp.result);
      publish_event(changed);
      break;
    }
    case ParamService::kDescribe: {
      const auto& rq = *static_cast<const rcl_interfaces_srv_dds__DescribeParameters_Request_*>(request);
      auto& rp = *static_cast<rcl_interfaces_srv_dds__DescribeParameters_Response_*>(reply.get());
      echo(rq, rp);
      std::vector<ParamDescriptor> descriptors;
      for (const auto& n : wire::from_c(rq.names)) {
        std::optional<ParamDescriptor> d = cb_.describe(n);
        if (!d) {
          descriptors.clear();
          break;
        }
        descriptors.push_back(std::move(*d));
      }
      wire::to_c(descriptors, rp.descriptors);
      break;
    }
    case ParamService::kList: {
      const auto& rq = *static_cast<const rcl_interfaces_srv_dds__ListParameters_Request_*>(request);
      auto& rp = *static_cast<rcl_interfaces_srv_dds__ListParameters_Response_*>(reply.get());
      echo(rq, rp);
      wire::to_c(list_parameters(cb_.names(), wire::from_c(rq.prefixes), rq.depth), rp.result);
      break;
    }
  }
  return reply;
}

int ParameterServer::client_ready(ParamService service, dds_instance_handle_t request_writer) const {
  const Endpoints& e = ep_[index(service)];
  dds_builtintopic_endpoint_t* wr = dds_get_matched_publication_data(e.reader, request_writer);
  if (wr == nullptr) return -1;  // the client's request writer is gone
  const std::string clientid = wire::user_data_value(wr->qos, "clientid");
  const dds_guid_t client_participant = wr->participant_key;
  dds_builtintopic_free_endpoint(wr);
  // rmw_cyclonedds clients name their reply reader with the same "clientid" as their request
  // writer; for a client without one, any reply reader of the same participant will do.
  for (dds_instance_handle_t ih : matched_subscriptions(e.writer)) {
    dds_builtintopic_endpoint_t* rd = dds_get_matched_subscription_data(e.writer, ih);
    if (rd == nullptr) continue;
    const bool match = clientid.empty()
                           ? std::memcmp(rd->participant_key.v, client_participant.v, sizeof client_participant.v) == 0
                           : wire::user_data_value(rd->qos, "clientid") == clientid;
    dds_builtintopic_free_endpoint(rd);
    if (match) return 1;
  }
  return 0;
}

void ParameterServer::send_pending() {
  const std::int64_t now = steady_ns();
  for (auto it = pending_.begin(); it != pending_.end();) {
    const int ready = client_ready(it->service, it->request_writer);
    if (ready > 0) {
      write_now(ep_[index(it->service)].writer, it->sample.get(), "dds_write (parameter reply)");
      ++stats_.replies;
    } else if (ready == 0 && now < it->deadline_ns) {
      ++it;
      continue;
    } else {
      ++stats_.replies_dropped;
    }
    it = pending_.erase(it);
  }
}

}  // namespace quadcosim::dds
