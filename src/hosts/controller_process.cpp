// The controller process over DDS (`quadcosim controller`, one vehicle): the flight controller node as
// a long-running process, stepping once per complete sensor sample in lockstep, or on a wall-clock
// timer in real time.
#include "hosts/controller_process.hpp"

#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "dds/dds_transport.hpp"
#include "dds/node_announcer.hpp"
#include "dds/parameter_service.hpp"
#include "dds/peer_pairing.hpp"
#include "drivers/controller_drivers.hpp"
#include "hosts/exit_code.hpp"
#include "hosts/node_common.hpp"
#include "hosts/parameter_binding.hpp"
#include "hosts/recording.hpp"
#include "hosts/signals.hpp"
#include "isolation/child.hpp"
#include "sim/controller_node.hpp"
#include "sim/topics.hpp"

namespace quadcosim::hosts {

namespace {
/// Runs a node's loop. A step given up on SIGINT or SIGTERM (an isolated Python controller's process
/// is killed on a stop request, and the steps after find it gone) ends the node as the signal does,
/// exit 0, not as a failure of the controller.
template <class Loop>
void run_until_stopped(Loop&& loop) {
  try {
    loop();
  } catch (const sim::ControllerFailure& e) {
    if (!stop_signalled()) throw;
    std::cerr << "controller: stop requested while the controller was stepping (" << e.what() << ")\n";
  } catch (const isolation::Interrupted& e) {
    if (!stop_signalled()) throw;
    std::cerr << "controller: " << e.what() << '\n';
  }
}
}  // namespace

int run_controller_process(const ControllerProcessOptions& o, io::Scenario sc,
                           sim::ControllerThread::ThreadHost thread_host) {
  const sim::TickClock clock = sc.simulation.plant.clock;
  const std::int64_t control_period_ns = clock.period_ns * sc.simulation.controller_divider;
  const double dt_s = static_cast<double>(control_period_ns) / 1e9;
  const auto wall_period_ns =
      static_cast<std::int64_t>(static_cast<double>(control_period_ns) / o.realtime.rate_factor);
  const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);

  dds::DdsTransport transport(dds::read_ros_environment(o.enclave));
  if (o.sensor_qos) use_sensor_qos(transport, topics);
  // Paired with the plant by the run's token (run --transport dds): the node's writers carry it, and
  // it takes sensor samples from the plant's writers only (dds/peer_pairing.hpp).
  const std::string pair_token = dds::pair_token_from_environment();
  dds::PeerFilter pairing(transport);
  sim::ControllerNode::SampleFilter from_plant;
  if (!pair_token.empty()) {
    transport.set_user_data_keys(std::string(dds::kPairTokenKey) + "=" + pair_token + ";");
    pairing.pair_by_token(pair_token);
    from_plant = [&pairing](const std::string& topic, sim::SenderId s) { return pairing.accepts(topic, s); };
  }
  sim::ControllerNode node(transport, topics, sc.controller, std::move(from_plant),
                           sc.simulation.plant.realism.extra_sensors);
  // A controller that asks for it (one written in Python, docs/python.md) runs on a thread of its own:
  // one that blocks holds up neither the DDS threads (discovery, parameter services) nor a stop.
  const bool on_thread = sc.controller.wants_own_thread();
  if (on_thread) {
    sim::ControllerThreading threading;
    threading.asynchronous = o.lockstep;
    threading.wait_ns = wall_period_ns * 3 / 4;
    threading.on_error = o.on_controller_error == "safety" ? sim::ControllerThreading::OnError::kSafety
                                                           : sim::ControllerThreading::OnError::kStop;
    threading.on_failure = [](const std::string&) { request_stop(); };
    threading.thread_host = std::move(thread_host);
    node.run_controller_on_thread(std::move(threading));
  }
  const dds::NodeName ros_name = dds::parse_node_name(o.one_vehicle.node_name);
  // The ROS 2 parameter services, answered in the transport's waits (both drivers below).
  dds::ParameterServer parameters(transport, ros_name, controller_parameter_callbacks(node));
  if (!o.apply_schedule) sc.schedule.clear();
  // After the node's own readers, so a plant that counts this process's readers finds the node's first.
  // --foxglove: the controller's one recorder (it has no plant ticks: only built and finished).
  RecordingOptions ro(io::RecordingOptions::for_run(sc));
  ro.foxglove = o.foxglove;
  ro.who = "controller";
  io::Recording recording = make_recording(ro, &transport);
  dds::NodeAnnouncer announcer(transport.participant().handle(), ros_name.name, ros_name.ns);
  announcer.announce();  // after every endpoint exists: `ros2 node list` shows /attitude_controller
  std::cerr << fmt::format("controller: domain {}, namespace {}, {} mode, period {} s, controller {}\n",
                           transport.participant().domain_id(), sc.simulation.ns, o.lockstep ? "lockstep" : "real-time",
                           dt_s,
                           sc.controller_fmu   ? "fmu " + sc.controller_fmu->path
                           : !o.python.empty() ? "python " + o.python
                                               : std::string(sc.controller.type()));

  if (o.lockstep) {
    // Steps where the samples are delivered: on Cyclone's receive thread with delivery on
    // arrival, so answering a tick wakes no other thread; the host's waits serve the parameter
    // services.
    DdsDriverHost host(transport);
    drivers::LockstepControllerDriver driver({{&node, std::move(sc.schedule)}}, clock, sc.simulation.controller_divider,
                                             host);
    run_until_stopped([&] { driver.run(); });
  } else {
    // Real time: a 50 Hz (or configured) timer; data age is measured on the receiving clock.
    node.use_receipt_clock(steady_ns);
    if (std::string err = use_realtime_priority(o.realtime.rt_priority); !err.empty()) {
      std::cerr << "controller: warning: " << err << "; running with normal scheduling\n";
    }
    PeriodJitter jitter(wall_period_ns);
    drivers::RealtimeControllerHooks h;
    h.on_wake = [&](std::int64_t now) { jitter.add(now); };
    h.on_first_sample = [](std::size_t, std::int64_t stamp_ns) {
      std::cerr << fmt::format("controller: first complete sensor sample (t = {:g} s); controlling\n",
                               static_cast<double>(stamp_ns) / 1e9);
    };
    h.on_safety = [&](std::size_t, bool safety, std::int64_t now) {
      // On a thread, the safety command also stands in for a late or failed step (counted and logged).
      const bool stale = node.observation().age_s > node.settings().stale_limit_s;
      std::cerr << fmt::format("controller: {} (sensor data age {:.3f} s, limit {:g} s; monotonic {:.6f} s)\n",
                               safety                ? (stale || !on_thread ? "stale sensor data: safety command"
                                                                            : "no answer from the controller: safety command")
                               : stale || !on_thread ? "sensor data fresh again: normal control"
                                                     : "the controller answers again: normal control",
                               node.observation().age_s, node.settings().stale_limit_s, static_cast<double>(now) / 1e9);
    };
    DdsDriverHost host(transport, /*precise_deadlines=*/true);
    drivers::RealtimeControllerDriver driver({{&node, std::move(sc.schedule)}}, clock, sc.simulation.controller_divider,
                                             o.realtime.rate_factor, std::move(h), host);
    run_until_stopped([&] { driver.run(); });
    if (!o.realtime.stats.empty()) write_stats(o.realtime.stats, jitter.figures());
  }
  if (std::optional<std::string> failure = node.controller_failure(); failure && !stop_signalled()) {
    throw sim::ControllerFailure(*failure);
  }
  if (on_thread && (node.controller_failures() > 0 || node.late_steps() > 0)) {
    std::cerr << fmt::format(
        "controller: {} failed steps (safety command sent instead), {} {}\n", node.controller_failures(),
        node.late_steps(), o.lockstep ? "ticks not answered (controller busy)" : "late periods (safety command sent)");
  }
  if (node.foreign_samples() > 0) {
    std::cerr << fmt::format("controller: {} sensor samples from writers other than the plant's ignored\n",
                             node.foreign_samples());
  }
  std::cerr << "controller: stopped\n";
  recording.finish(true);
  return exit_code::kOk;
}

}  // namespace quadcosim::hosts
