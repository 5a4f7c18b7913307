// hosts/dds_run.hpp: `run --transport dds`, its two child processes and their keystore.
#include "hosts/dds_run.hpp"

#include <fmt/format.h>
#include <stdlib.h>

#include <cstdint>
#include <filesystem>
#include <iostream>
#include <system_error>
#include <vector>

#include "dds/participant.hpp"
#include "dds/peer_pairing.hpp"
#include "hosts/child_process.hpp"
#include "hosts/exit_code.hpp"
#include "hosts/node_common.hpp"
#include "hosts/signals.hpp"
#include "io/scenario_limits.hpp"
#include "security/keystore.hpp"

namespace quadcosim::hosts {

namespace fs = std::filesystem;

namespace {

// Makes the SROS2 keystore at `keystore` (for the ROS domain of the environment) and the `enclaves`
// in it when they are missing, saying on stderr what it created; what exists is kept as it is.
// Returns 0, or exit_code::kBadInput with the reason on stderr.
int prepare_keystore_for_run(const std::string& keystore, const std::vector<std::string>& enclaves) {
  try {
    if (!security::is_keystore(keystore)) {
      const std::uint32_t domain = dds::read_ros_environment().domain_id;
      security::create_keystore(keystore, domain);
      std::cerr << fmt::format("run: created keystore {} for domain {}\n", keystore, domain);
    }
    for (const auto& name : enclaves) {
      std::error_code ec;
      if (fs::exists(security::enclave_dir(keystore, name) / "cert.pem", ec)) continue;  // kept as it is
      security::EnclavePolicy policy;
      policy.domain_id = dds::read_ros_environment().domain_id;
      security::create_enclave(keystore, name, policy);
      std::cerr << fmt::format("run: created enclave {} in {}\n", name, keystore);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: run --keystore " << keystore << ": " << e.what() << '\n';
    return exit_code::kBadInput;
  }
}

}  // namespace

int run_over_dds(const DdsRunOptions& opt, const std::string& csv_path) {
  install_stop_handlers();
  const std::string self = self_executable();
  const std::string timeout = fmt::format("{}", opt.timeout_s);
  // The plant owns simulated time, so in lockstep it applies the schedule through the controller's
  // parameter services, each change before its tick; in real time the controller applies it itself.
  std::vector<std::string> controller_args = {self, "controller", "--scenario", opt.scenario};
  if (!opt.controller.empty()) {
    controller_args.push_back("--controller");
    controller_args.push_back(opt.controller);
  }
  const std::string mcap_path = (std::filesystem::path(csv_path).parent_path() / "run.mcap").string();
  // A fresh pairing token for this run's two children: each takes the other's writers only
  // (dds/peer_pairing.hpp), so a stranger's message or a controller left from another run bends nothing.
  setenv(dds::kPairTokenEnv, dds::new_pair_token().c_str(), 1);
  std::vector<std::string> plant_args = {self,     "plant",  "--scenario", opt.scenario, "--record",
                                         csv_path, "--mcap", mcap_path,    "--timeout",  timeout};
  if (!opt.realtime) {
    controller_args.push_back("--no-schedule");
    for (std::string a : {"--schedule-via", "/attitude_controller"}) plant_args.push_back(a);
  }
  if (!opt.keystore.empty()) {
    // Secured: each node in its own enclave of the keystore, strategy Enforce (the children inherit
    // the environment; an enclave override would put both in one enclave, so it is dropped).
    const std::string keystore = fs::absolute(opt.keystore).string();
    const std::string plant_enclave = "/quadcosim/plant", controller_enclave = "/quadcosim/controller";
    if (int rc = prepare_keystore_for_run(keystore, {plant_enclave, controller_enclave}); rc != 0) return rc;
    setenv("ROS_SECURITY_ENABLE", "true", 1);
    setenv("ROS_SECURITY_STRATEGY", "Enforce", 1);
    setenv("ROS_SECURITY_KEYSTORE", keystore.c_str(), 1);
    unsetenv("ROS_SECURITY_ENCLAVE_OVERRIDE");
    controller_args.insert(controller_args.end(), {"--enclave", controller_enclave});
    plant_args.insert(plant_args.end(), {"--enclave", plant_enclave});
  }
  if (opt.realtime) {
    for (std::string a : {"--realtime", "--rate-factor"}) controller_args.push_back(a);
    controller_args.push_back(fmt::format("{}", opt.rate_factor));
    for (std::string a : {"--realtime", "--wait-for-controller", "--rate-factor"}) plant_args.push_back(a);
    plant_args.push_back(fmt::format("{}", opt.rate_factor));
  }
  if (opt.pin) pin_apart(plant_args, controller_args);
  for (const std::string& a : io::limit_arguments(io::limits())) {  // the child processes read the same files
    plant_args.push_back(a);
    controller_args.push_back(a);
  }
  if (!opt.foxglove.listen.empty()) {  // the plant serves: it has every topic, and the simulated time
    plant_args.insert(plant_args.end(), {"--foxglove", opt.foxglove.listen, "--foxglove-queue-kib",
                                         fmt::format("{}", opt.foxglove.queue_kib)});
    for (const std::string& origin : opt.foxglove.allow_origins)
      plant_args.insert(plant_args.end(), {"--foxglove-allow-origin", origin});
    if (opt.foxglove.linger_s > 0)
      plant_args.insert(plant_args.end(), {"--foxglove-linger", fmt::format("{}", opt.foxglove.linger_s)});
  }
  return run_plant_and_controller(plant_args, controller_args);
}

}  // namespace quadcosim::hosts
