// libFuzzer target: raw CDR bytes as ROS 2 parameter service requests to the controller.
//
// Input: records [service: 1 byte][length: 2 bytes LE][serialized request: encapsulation header +
// CDR]; service % 6 picks get_parameters, get_parameter_types, set_parameters,
// set_parameters_atomically, describe_parameters, list_parameters (rcl_interfaces, with
// rmw_cyclonedds's request header). Each request goes the whole way a request from `ros2 param`
// goes, minus the network: Cyclone DDS reads the bytes with the request topic's sertype (refusing what
// does not fit the type), a local writer delivers the sample to the controller node's
// dds::ParameterServer, whose serve() takes it, answers through the parameter binding of `quadcosim
// controller` and writes the reply. Between requests a closed loop (plant + controller, in-process)
// advances two plant ticks. Checked: the plant state stays finite and every controller command is
// four finite speeds, whatever parameters were accepted.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>

#include "closed_loop.hpp"
#include "cyclone_bytes.hpp"
#include "dds/parameter_service.hpp"
#include "dds/parameter_wire.hpp"
#include "hosts/parameter_binding.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"

namespace {

using namespace quadcosim;

sim::ControllerNode* g_node = nullptr;  // the current input's controller, seen by the server's callbacks

struct Setup {
  std::unique_ptr<dds::Participant> participant = fuzz::isolated_participant();
  std::unique_ptr<dds::ParameterServer> server;
  std::vector<fuzz::LocalTopic> requests;

  Setup() {
    dds::ParameterCallbacks cb;
    cb.names = [] { return hosts::controller_parameter_callbacks(*g_node).names(); };
    cb.get = [](const std::string& n) { return hosts::controller_parameter_callbacks(*g_node).get(n); };
    cb.set = [](const std::string& n, const dds::ParamValue& v) {
      return hosts::controller_parameter_callbacks(*g_node).set(n, v);
    };
    cb.describe = [](const std::string& n) { return hosts::controller_parameter_callbacks(*g_node).describe(n); };
    dds::ParameterServerOptions options;
    options.reply_wait_ns = 0;
    const dds::NodeName node{"/", "attitude_controller"};
    server = std::make_unique<dds::ParameterServer>(participant->handle(), node, cb, options);
    for (dds::ParamService service : dds::kParamServices) {
      const std::string name =
          "rq" + node.fully_qualified() + "/" + std::string(dds::service_suffix(service)) + "Request";
      requests.emplace_back(*participant, dds::wire::service_types(service).request, name);
    }
    g_node = &setup_node;
    server->serve();  // the zero sample each LocalTopic wrote to learn its sertype reached the server too
    g_node = nullptr;
  }
  sim::InProcessTransport setup_bus;
  sim::ControllerNode setup_node{setup_bus, sim::Topics::for_namespace("/drone"),
                                 controllers::make_config("paper", model::VehicleParams{})};
};

Setup& setup() {
  static Setup s;  // process-wide, made on the first input
  return s;
}

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_parameters: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Setup& s = setup();
  fuzz::ClosedLoop loop("fuzz_parameters", 0.0);  // rotors stopped: the controller must lift it
  g_node = &loop.controller();

  sim::Tick k = 0;
  fuzz::for_each_record(data, size, 64, [&](int kind, const std::uint8_t* bytes, std::size_t len) {
    const fuzz::LocalTopic& t = s.requests[static_cast<std::size_t>(kind % 6)];
    if (ddsi_serdata* sd = t.from_bytes(bytes, len)) {
      if (dds_writecdr(t.writer, sd) < 0) fail("dds_writecdr refused a sample Cyclone had read");
      if (s.server->serve() != 1) fail("a request Cyclone had read did not reach the server");
    }
    for (int i = 0; i < 2; ++i, ++k) {
      loop.begin(k);
      loop.end(k);
    }
  });
  g_node = nullptr;
  return 0;
}
