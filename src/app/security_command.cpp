// `quadcosim security create-keystore|create-enclave|check`: an SROS2-compatible DDS Security keystore
// (security/keystore.hpp), and the --enclave option every DDS command takes.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>

#include <iostream>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "dds/participant.hpp"
#include "security/keystore.hpp"

namespace quadcosim::app {

namespace fs = std::filesystem;

namespace {

std::string check_enclave_name(const std::string& name) { return security::enclave_name_error(name); }

// ROS_DOMAIN_ID, as the nodes read it (sros2 writes it into governance and permissions).
std::uint32_t domain_or_env(int domain_id) {
  return domain_id >= 0 ? static_cast<std::uint32_t>(domain_id) : dds::read_ros_environment().domain_id;
}

}  // namespace

void add_enclave_option(CLI::App* command, std::string& enclave) {
  command
      ->add_option("--enclave", enclave,
                   "security enclave, as `--ros-args --enclave` (default /; files from "
                   "$ROS_SECURITY_KEYSTORE/enclaves/<name> when ROS_SECURITY_ENABLE=true)")
      ->check(CLI::Validator(check_enclave_name, "ENCLAVE"));
}

CLI::App* add_security_subcommand(CLI::App& app, SecurityOptions& o) {
  auto* sec = app.add_subcommand("security", "DDS Security keystores and enclaves, as `ros2 security`");
  sec->require_subcommand(1);
  auto domain = [&o](CLI::App* verb) {
    verb->add_option("--domain-id", o.domain_id, "DDS domain the documents hold for (default: ROS_DOMAIN_ID or 0)")
        ->check(CLI::Range(0, 232));
  };

  auto* ks =
      sec->add_subcommand("create-keystore", "a new keystore: CA, governance (as `ros2 security create_keystore`)");
  ks->add_option("dir", o.dir, "keystore directory (created when missing)")->required();
  domain(ks);
  ks->callback([&o] { o.verb = "create-keystore"; });

  auto* en =
      sec->add_subcommand("create-enclave", "an enclave: identity, permissions (as `ros2 security create_enclave`)");
  en->add_option("dir", o.dir, "keystore directory")->required()->check(CLI::ExistingDirectory);
  en->add_option("name", o.name, "enclave name, e.g. /quadcosim/plant")
      ->required()
      ->check(CLI::Validator(check_enclave_name, "ENCLAVE"));
  auto* deny = en->add_option("--deny-publish", o.deny_publish,
                              "a ROS topic this enclave may not publish, e.g. /drone/motor_commands (repeatable); "
                              "it may then set no node's parameters either (it may still read both)");
  en->add_flag("--read-only", o.read_only,
               "subscribe only, e.g. for a monitoring station: read every topic, publish none, call no "
               "service (no parameter changes)")
      ->excludes(deny);
  domain(en);
  en->callback([&o] { o.verb = "create-enclave"; });

  auto* chk = sec->add_subcommand(
      "check", "can a node use this enclave? (files present, signatures verify, XML as signed, keys private)");
  chk->add_option("dir", o.dir, "keystore directory")->required()->check(CLI::ExistingDirectory);
  chk->add_option("name", o.name, "enclave name")->required()->check(CLI::Validator(check_enclave_name, "ENCLAVE"));
  chk->callback([&o] { o.verb = "check"; });
  return sec;
}

int security_command(const SecurityOptions& o) {
  if (o.verb == "create-keystore") {
    const std::uint32_t domain = domain_or_env(o.domain_id);
    security::create_keystore(o.dir, domain);
    std::cout << fmt::format("created keystore {} (CA sros2CA, governance for domain {})\n", o.dir, domain);
    return exit_code::kOk;
  }
  if (o.verb == "create-enclave") {
    security::EnclavePolicy policy;
    policy.deny_publish = o.deny_publish;
    policy.read_only = o.read_only;
    policy.domain_id = domain_or_env(o.domain_id);
    const fs::path dir = security::create_enclave(o.dir, o.name, policy);
    std::string limits;
    if (o.read_only) limits = ", read-only: subscribes to topics, publishes none, calls no service";
    if (!o.deny_publish.empty()) {
      limits = fmt::format(", may not publish {} nor set any node's parameters", fmt::join(o.deny_publish, " "));
    }
    std::cout << fmt::format("created enclave {} in {} (domain {}{})\n", o.name, dir.string(), policy.domain_id,
                             limits);
    return exit_code::kOk;
  }
  if (o.verb == "check") {
    const fs::path dir = security::enclave_dir(o.dir, o.name);
    auto problems = security::check_enclave(dir);
    for (auto& p : security::key_mode_problems(o.dir, dir)) problems.push_back(std::move(p));
    for (const auto& p : problems) std::cout << "problem: " << p << '\n';
    if (problems.empty()) std::cout << "enclave " << o.name << " in " << dir.string() << " is usable\n";
    return problems.empty() ? exit_code::kOk : exit_code::kFailed;
  }
  std::cerr << "error: security: expected create-keystore, create-enclave or check\n";
  return exit_code::kBadInput;
}

}  // namespace quadcosim::app
