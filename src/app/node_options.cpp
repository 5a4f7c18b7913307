// The flags the node commands share (`plant`, `controller`, and --controller / --judge of run, sweep,
// margins, fmu): CLI11 options and their checks.
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "app/commands.hpp"
#include "hosts/node_common.hpp"
#include "io/scenario.hpp"
#include "sim/topics.hpp"

namespace quadcosim::app {

void check_controller_choice(CLI::Option& option) {
  option.check(CLI::Validator(
      [](std::string& value) -> std::string {
        try {
          (void)io::parse_controller_choice(value);
          return "";
        } catch (const std::invalid_argument& e) {
          return e.what();
        }
      },
      "TYPE|python:MODULE:CLASS|fmu:PATH"));
}

void add_controller_type_option(CLI::App& cmd, std::string& type) {
  check_controller_choice(*cmd.add_option(
      "--controller", type,
      "the controller to fly in place of the scenario's: a type (`quadcosim params --list`), "
      "python:MODULE:CLASS, fmu:PATH or sitl:ardupilot|px4|betaflight[:BINARY] (docs/sitl.md); the scenario's "
      "setpoints, reference and criteria stay"));
}

void add_judge_option(CLI::App& cmd, std::string& judge) {
  cmd.add_option("--judge", judge,
                 "judge the run against: spec (the scenario's specification, default), paper (the paper "
                 "controller's measured response bands), none (figures only, no verdict)")
      ->check(CLI::IsMember(io::judge_names()));
}

void add_cpus_option(CLI::App* command, std::string& cpus) {
  command
      ->add_option("--cpus", cpus,
                   "run this process on these CPUs only, e.g. 0 or 0-1 (as taskset -c; on 2 cores, plant and "
                   "controller each on its own CPU run lockstep faster)")
      ->check(CLI::Validator(
          [](const std::string& text) {
            std::vector<int> cpus;
            return hosts::parse_cpu_list(text, cpus);
          },
          "LIST"));
}

void add_node_host_options(CLI::App* command, std::string& ns, NodeSwarmOptions& swarm, bool& sensor_qos,
                           const std::string& sensor_qos_help, std::string& cpus) {
  const CLI::Validator ros_namespace(sim::validate_namespace, "NAMESPACE");
  command->add_option("--namespace", ns, "topic namespace, e.g. /uav1 (one vehicle)")->check(ros_namespace);
  command->add_option("--vehicles", swarm.vehicles, "host N vehicles, namespaces <prefix>0000.. (lockstep)")
      ->check(CLI::Range(1, 1'000'000));
  command->add_option("--ns-prefix", swarm.ns_prefix,
                      "with --vehicles: namespace prefix (default: swarm.namespace_prefix, /uav)");
  command->add_option("--threads", swarm.threads, "with --vehicles: threads, one DDS participant each")
      ->check(CLI::Range(1, 64));
  command->add_flag("--sensor-qos", sensor_qos, sensor_qos_help);
  add_cpus_option(command, cpus);
}

void refuse_idle_flags(const CLI::App& command, std::initializer_list<FlagRule> rules) {
  for (const FlagRule& r : rules) {
    if (command.count(r.flag) > 0 && !r.acts) {
      throw CLI::ValidationError(r.flag, std::string("does nothing with ") + r.mode);
    }
  }
}

}  // namespace quadcosim::app
