// The six ROS 2 parameter services of one node, on the DDS wire as rmw_cyclonedds serves them, so
// `ros2 param get/set/list/describe` (rmw_cyclonedds_cpp) and `quadcosim param` can reach the node:
//
//   /<node>/get_parameters  ->  reader "rq/<node>/get_parametersRequest"
//                               (rcl_interfaces::srv::dds_::GetParameters_Request_), writer
//                               "rr/<node>/get_parametersReply" (..._Response_); likewise
//   get_parameter_types, set_parameters, set_parameters_atomically, describe_parameters,
//   list_parameters.
//
// Each request starts with rmw_cyclonedds's in-band header (uint64 guid, int64 seq), which the reply
// echoes. QoS: rclcpp's parameter-service profile, KEEP_LAST 1000, RELIABLE, VOLATILE. Endpoints
// carry USER_DATA "serviceid=<id>;" (one id per service on its reader and writer), which
// rmw_cyclonedds clients use to pair them. Like an rmw_cyclonedds server, a reply to a client whose
// request writer carries "clientid=<id>;" waits until that client's reply reader is matched (here
// without blocking: it is retried on every serve() for up to reply_wait_ns).
//
// Semantics follow rclcpp's ParameterService: get / get types / describe answer nothing when one of
// the names is not declared; set_parameters applies each parameter on its own; the atomic set
// applies all or none. An INTEGER value for a DOUBLE parameter is taken as a double (`ros2 param set
// NODE z_des 10` sends an INTEGER). A successful change is published on /parameter_events
// (rcl_interfaces::msg::dds_::ParameterEvent_, KEEP_LAST 1000 RELIABLE VOLATILE).
//
// Requests are served on the thread that calls serve() (DdsTransport::spin_once when built on a
// transport), so parameters change between control steps, never during one.
#pragma once

#include <dds/dds.h>

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dds/entity.hpp"
#include "dds/parameter_types.hpp"

namespace quadcosim::dds {

class DdsTransport;

/// How the server reaches the node's parameters. All four are required.
struct ParameterCallbacks {
  /// Declared names, in a stable order.
  std::function<std::vector<std::string>()> names;
  /// The current value, or nullopt when `name` is not declared.
  std::function<std::optional<ParamValue>(const std::string& name)> get;
  /// Applies one value: "" on success, else why it was refused (and nothing changed).
  std::function<std::string(const std::string& name, const ParamValue& value)> set;
  /// The descriptor, or nullopt when `name` is not declared.
  std::function<std::optional<ParamDescriptor>(const std::string& name)> describe;
};

struct ParameterServerOptions {
  int depth = 1000;                            ///< KEEP_LAST depth (rclcpp's parameter services)
  std::int64_t reply_wait_ns = 2'000'000'000;  ///< how long a reply waits for the client's reader
  bool publish_events = true;                  ///< /parameter_events on successful sets
};

class ParameterServer {
 public:
  /// Creates the services' endpoints on `participant`; the caller calls serve() when
  /// wake_entities() trigger (or periodically).
  ParameterServer(dds_entity_t participant, NodeName node, ParameterCallbacks callbacks,
                  ParameterServerOptions options = {});
  /// As above on the transport's participant, served by the transport's spin_once (the transport
  /// must outlive the server).
  ParameterServer(DdsTransport& transport, NodeName node, ParameterCallbacks callbacks,
                  ParameterServerOptions options = {});
  ~ParameterServer();
  ParameterServer(const ParameterServer&) = delete;
  ParameterServer& operator=(const ParameterServer&) = delete;

  /// Read conditions of the request readers and the reply writers (publication-matched status):
  /// what should wake a waitset that serves this server.
  std::vector<dds_entity_t> wake_entities() const;

  /// Answers every request that has arrived and sends replies that were waiting for their client.
  /// Returns how many requests were taken.
  int serve();

  struct Stats {
    std::uint64_t requests = 0;         ///< requests taken
    std::uint64_t replies = 0;          ///< replies written
    std::uint64_t replies_dropped = 0;  ///< client gone, or its reader not matched within reply_wait_ns
    std::uint64_t events = 0;           ///< ParameterEvent messages published
  };
  const Stats& stats() const { return stats_; }
  const NodeName& node() const { return node_; }

 private:
  struct Endpoints {
    Entity request_topic, reply_topic;  // owned in creation order, so deleted children first
    Entity reader, read_condition, writer;
  };
  struct PendingReply {
    ParamService service;
    dds_instance_handle_t request_writer;  ///< as our request reader knows it
    std::int64_t deadline_ns;
    std::shared_ptr<void> sample;  ///< the reply, a generated C struct
  };

  void take_requests(ParamService service, int& taken);
  std::shared_ptr<void> answer(ParamService service, const void* request);
  /// 1: send now; 0: keep waiting; -1: drop (client gone).
  int client_ready(ParamService service, dds_instance_handle_t request_writer) const;
  void send_pending();
  SetResult set_one(const Param& p, std::vector<Param>& changed);
  void publish_event(const std::vector<Param>& changed);

  dds_entity_t participant_;
  NodeName node_;
  ParameterCallbacks cb_;
  ParameterServerOptions options_;
  std::array<Endpoints, 6> ep_{};
  Entity events_topic_;
  Entity events_writer_;
  std::deque<PendingReply> pending_;
  Stats stats_;
  DdsTransport* transport_ = nullptr;
  int transport_work_id_ = 0;
};

}  // namespace quadcosim::dds
