// A client of one ROS 2 node's parameter services on the DDS wire, as an rmw_cyclonedds client
// calls them (see parameter_service.hpp for the names, types and QoS): each request carries the
// in-band header {guid = this client's request-writer instance handle, seq = a fresh number}, and
// only the reply echoing both is taken. The request writer and reply reader of a service carry
// USER_DATA "clientid=<id>;" so an rmw_cyclonedds server holds its reply until it has matched our
// reader. Works with quadcosim's ParameterServer and with nodes on rmw_cyclonedds_cpp, not with
// rmw_fastrtps_cpp nodes (they correlate replies differently; ros2/rmw_cyclonedds#184).
#pragma once

#include <dds/dds.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dds/parameter_types.hpp"
#include "dds/participant.hpp"

namespace quadcosim::dds {

/// A call that could not be made or was not answered in time; what() names the node, the service
/// and what was matched.
class ParameterCallError : public DdsError {
 public:
  using DdsError::DdsError;
};

class ParameterClient {
 public:
  /// A client on its own participant (domain and discovery from `env`).
  ParameterClient(const RosEnvironment& env, NodeName node);
  /// A client on an existing participant (not owned).
  ParameterClient(dds_entity_t participant, NodeName node);
  ~ParameterClient();
  ParameterClient(const ParameterClient&) = delete;
  ParameterClient& operator=(const ParameterClient&) = delete;

  // Each call waits up to `timeout_ns` in all: first for the service (a matched request reader and
  // reply writer), then for the reply. Throws ParameterCallError on timeout.

  /// Values in the order of `names`; empty when the node has not declared one of them.
  std::vector<ParamValue> get(const std::vector<std::string>& names, std::int64_t timeout_ns);
  /// Types in the order of `names`; empty when one is not declared.
  std::vector<ParamType> get_types(const std::vector<std::string>& names, std::int64_t timeout_ns);
  /// One result per parameter, each applied on its own.
  std::vector<SetResult> set(const std::vector<Param>& parameters, std::int64_t timeout_ns);
  /// All or none.
  SetResult set_atomically(const std::vector<Param>& parameters, std::int64_t timeout_ns);
  /// Descriptors in the order of `names`; empty when one is not declared.
  std::vector<ParamDescriptor> describe(const std::vector<std::string>& names, std::int64_t timeout_ns);
  ListResult list(const std::vector<std::string>& prefixes, std::uint64_t depth, std::int64_t timeout_ns);

  /// Takes replies only from writers of the participant with this GUID (the paired controller's): a
  /// node of the same name elsewhere on the domain (a controller left over from another run, a
  /// stranger) answers nothing of this client's. Until called, any writer's reply to its request is.
  void only_from(const std::array<std::uint8_t, 16>& participant);
  /// True when a reply that arrived on `reader` (one of this client's reply readers) from `writer` (its
  /// publication handle) may be taken: always without only_from().
  bool from_peer(dds_entity_t reader, dds_instance_handle_t writer);

  /// Waits up to `timeout_ns` until `service` is matched; false on timeout.
  bool wait_for_service(ParamService service, std::int64_t timeout_ns);

  /// The in-band header of the last request sent.
  struct Header {
    std::uint64_t guid = 0;
    std::int64_t seq = 0;
  };

  // Asynchronous get_parameters (a lockstep barrier): send_get() sends and returns at once; the
  // replies arrive on get_reply_reader(), which the caller takes from (e.g. through
  // DdsTransport::subscribe_raw), matching each with is_reply_to(). Once its reader is handed over,
  // the client's blocking get() must not be used.

  /// Sends get_parameters(names) and returns its header; throws ParameterCallError when the service
  /// is not matched.
  Header send_get(const std::vector<std::string>& names);
  /// The get_parameters reply reader (made on first use).
  dds_entity_t get_reply_reader() { return endpoints(ParamService::kGet).reader; }
  /// True when `reply` (a GetParameters_Response sample from get_reply_reader()) answers `request`.
  static bool is_reply_to(const void* reply, Header request);
  Header last_request() const { return last_; }
  const NodeName& node() const { return node_; }

 private:
  // Owned in creation order, so deleted children first (dds/entity.hpp).
  struct Endpoints {
    Entity request_topic, reply_topic;
    Entity writer, reader, read_condition;
    dds_instance_handle_t writer_handle = 0;
    mutable bool peer_matched = false;  ///< only_from(): the peer's service found matched
  };
  Endpoints& endpoints(ParamService service);
  std::optional<std::array<std::uint8_t, 16>> peer_;  ///< only_from()
  std::vector<dds_instance_handle_t> peer_writers_;   ///< writers found to be the peer's
  bool matched(const Endpoints& e) const;
  /// Waits for the waitset (at most until `deadline_ns`, steady clock), clears the match triggers
  /// and drops stale replies in every reader but `active`'s.
  void wait(std::int64_t deadline_ns, const Endpoints* active);
  /// Fills in `request`'s in-band header (a generated request sample) and writes it.
  void send(ParamService service, void* request);
  /// Sends `request` (a generated request sample; its header is filled in here) and passes the
  /// matching reply sample to `on_reply` before returning.
  void call(ParamService service, void* request, std::int64_t timeout_ns,
            const std::function<void(const void* reply)>& on_reply);
  std::string describe_matches(ParamService service) const;

  std::unique_ptr<Participant> own_participant_;
  dds_entity_t participant_;
  NodeName node_;
  Entity waitset_;
  std::array<Endpoints, 6> ep_{};
  std::int64_t next_seq_ = 0;
  Header last_;
};

}  // namespace quadcosim::dds
