// The plain option structs the DDS process hosts take (plant_process.hpp, controller_process.hpp,
// swarm_nodes.hpp, foxglove_serving.hpp): what `quadcosim plant` and `quadcosim controller` parse their
// flags into (app/), and what any other front end fills in to start the same processes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace quadcosim::hosts {

/// `--foxglove [ADDR:]PORT` and its companions (run, plant, controller): serve the node's topics live
/// over the Foxglove WebSocket protocol (hosts/foxglove_serving.hpp, docs/foxglove.md).
struct FoxgloveOptions {
  std::string listen;            ///< "PORT" (on 127.0.0.1) or "ADDR:PORT"; "" for no server
  double linger_s = 0.0;         ///< keep serving the last state this long after the run [s]
  double wait_s = 0.0;           ///< in-process run: wait this long for a client to subscribe first [s]
  double pace = 0.0;             ///< in-process run: run at this many times real time (0: unpaced)
  std::size_t queue_kib = 1024;  ///< per-client queue above which messages are dropped [KiB]
  /// --foxglove-allow-origin: browser Origins admitted besides the local ones ("*": any)
  std::vector<std::string> allow_origins;
};

/// --vehicles N: how `plant` and `controller` host a swarm (lockstep only).
struct NodeSwarmOptions {
  int vehicles = 0;       ///< > 0: host this many vehicles (namespaces <ns-prefix>0000, ...)
  std::string ns_prefix;  ///< overrides the scenario's swarm.namespace_prefix
  int threads = 2;        ///< threads (one DDS participant each)
};

/// `quadcosim plant`: what every mode takes, then what one mode alone takes (its own struct).
struct PlantProcessOptions {
  /// Lockstep only (one vehicle or --vehicles N).
  struct Lockstep {
    std::string on_timeout = "abort";  ///< "abort" (exit 4) or "hold" (last commands, go on unpaced)
    /// How the controller steps (one vehicle): "samples" (on each control tick's samples, answering
    /// tick 0), "clock" (from a timer on ROS time: samples, a parameter round trip to its node, then
    /// /clock; first answer one period in), "auto" (clock when the node has use_sim_time true).
    std::string sync = "auto";
    std::string controller_node;  ///< the node --sync talks to ("" = found from the command publisher)
  };
  /// Real time only (--realtime).
  struct Realtime {
    double rate_factor = 1.0;          ///< run k times faster than the wall clock
    bool wait_for_controller = false;  ///< start the clock only once a controller is matched
  };
  /// One vehicle only (lockstep or real time).
  struct OneVehicle {
    std::string record;  ///< trajectory CSV to write ("" for none)
    std::string mcap;    ///< MCAP file to record the topics into, metadata.yaml beside it ("" for none)
    /// Apply the scenario's schedule through this node's ROS 2 parameter services, each change
    /// before the tick it is due at ("" = the plant leaves the schedule to the controller).
    std::string schedule_node;
  };
  /// --vehicles N (lockstep).
  struct Swarm : NodeSwarmOptions {
    std::string out;  ///< directory for summary.json, vehicles.csv, recorded vehicles
  };

  // Every mode.
  std::string scenario;         ///< vehicle, rates, duration, initial state ("" for defaults)
  std::string vehicle;          ///< vehicle file, replaces the scenario's vehicle when set
  std::string fmu;              ///< --fmu: a co-simulation FMU flown as the plant (default variable names)
  std::string ns;               ///< overrides the scenario's namespace when set
  bool sensor_qos = false;      ///< publish Pose/Velocity/Imu with the ROS sensor-data QoS (best effort)
  std::string cpus;             ///< run on these CPUs only ("0", "0-1"; "" for any)
  bool lockstep = true;         ///< false: real time
  double duration_s = -1.0;     ///< overrides the scenario's duration when >= 0
  double timeout_s = 10.0;      ///< how long to wait for a controller (and, in lockstep, for one command)
  double watchdog_s = -1.0;     ///< overrides simulation.watchdog_s when >= 0 (0: off)
  std::string watchdog_policy;  ///< overrides simulation.watchdog_policy when set: "hold" or "stop"
  std::string stats;            ///< write run figures (real-time factor, round trip) as JSON here ("" none)
  std::string enclave = "/";    ///< DDS Security enclave (rcl --enclave)
  /// Publish /clock after each tick's Pose, Velocity and Imu (a peer stepping on /clock).
  bool clock_after_sensors = false;

  FoxgloveOptions foxglove;  ///< one vehicle

  Lockstep lockstep_only;
  Realtime realtime;
  OneVehicle one_vehicle;
  Swarm swarm;
};

/// `quadcosim controller`: what every mode takes, then what one mode alone takes (its own struct).
struct ControllerProcessOptions {
  /// Real time only (--realtime).
  struct Realtime {
    double rate_factor = 1.0;  ///< the timer runs k times faster (to match a faster plant)
    std::string stats;         ///< write the control period jitter as JSON here on exit
    int rt_priority = 0;       ///< run the control loop under SCHED_FIFO at this priority (0 off)
  };
  /// One vehicle only.
  struct OneVehicle {
    std::string node_name = "attitude_controller";  ///< ROS node name (parameter services, node list)
  };
  /// --vehicles N (lockstep): this many vehicles' controllers.
  using Swarm = NodeSwarmOptions;

  // Every mode.
  std::string scenario;    ///< controller parameters, rates, schedule ("" for defaults)
  std::string controller;  ///< --controller: replaces the scenario's controller.type ("" keeps it)
  std::string params;      ///< controller parameter file, applied over the scenario's
  std::string vehicle;     ///< vehicle file (the controller's model of the vehicle)
  std::string fmu;         ///< --fmu: a co-simulation FMU flown as the controller (default variable names)
  std::string python;      ///< --python module:Class: a controller written in Python
  std::string on_controller_error = "stop";  ///< a failed step: "stop" the node or send the "safety" command
  std::string ns;
  bool sensor_qos = false;  ///< subscribe Pose/Velocity/Imu with the sensor-data QoS (best effort)
  std::string cpus;         ///< run on these CPUs only ("1", "0-1"; "" for any)
  bool lockstep = true;
  bool apply_schedule = true;  ///< apply the scenario's schedule itself (off when the plant does it)
  std::string enclave = "/";   ///< DDS Security enclave (rcl --enclave)
  FoxgloveOptions foxglove;    ///< one vehicle

  Realtime realtime;
  OneVehicle one_vehicle;
  Swarm swarm;
};

}  // namespace quadcosim::hosts
