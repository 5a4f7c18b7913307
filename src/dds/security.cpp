#include "dds/security.hpp"

#include <cstdlib>

#include "dds/participant.hpp"
#include "security/keystore.hpp"

namespace quadcosim::dds {

namespace fs = std::filesystem;

namespace {
std::string env_or_empty(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}
}  // namespace

SecurityEnvironment read_security_environment() {
  SecurityEnvironment e;
  const std::string enable = env_or_empty("ROS_SECURITY_ENABLE");
  const std::string strategy = env_or_empty("ROS_SECURITY_STRATEGY");
  e.enabled = enable == "true";
  e.strategy = strategy == "Enforce" ? SecurityStrategy::kEnforce : SecurityStrategy::kPermissive;
  e.keystore = env_or_empty("ROS_SECURITY_KEYSTORE");
  e.enclave_override = env_or_empty("ROS_SECURITY_ENCLAVE_OVERRIDE");
  if (!enable.empty() && enable != "true" && enable != "false") {
    e.warning = "ROS_SECURITY_ENABLE='" + enable + "' is not \"true\": security is off (as in ROS 2)";
  } else if (e.enabled && !strategy.empty() && strategy != "Enforce" && strategy != "Permissive") {
    e.warning = "ROS_SECURITY_STRATEGY='" + strategy + "' is not \"Enforce\": read as Permissive (as in ROS 2)";
  }
  return e;
}

SecurityPlan plan_security(const SecurityEnvironment& e, const std::string& enclave) {
  SecurityPlan plan;
  if (!e.enabled) {
    plan.note = e.warning;
    return plan;
  }
  const bool enforce = e.strategy == SecurityStrategy::kEnforce;
  const std::string mode = enforce ? "Enforce" : "Permissive";
  plan.enclave_used = e.enclave_override.empty() ? enclave : e.enclave_override;
  std::string problem;
  if (e.keystore.empty()) {
    problem = "ROS_SECURITY_KEYSTORE is not set";
  } else if (const std::string why = security::enclave_name_error(plan.enclave_used); !why.empty()) {
    problem = std::string(e.enclave_override.empty() ? "enclave" : "ROS_SECURITY_ENCLAVE_OVERRIDE") + " '" +
              plan.enclave_used + "': " + why;
  } else {
    plan.root = security::enclave_dir(e.keystore, plan.enclave_used);
    const auto problems = security::check_enclave(plan.root);
    for (const auto& p : problems) problem += (problem.empty() ? "" : "; ") + p;
    if (!problem.empty()) problem = "enclave " + plan.enclave_used + " unusable: " + problem;
  }
  const std::string prefix = e.warning.empty() ? "" : e.warning + "; ";
  if (!problem.empty()) {
    if (enforce) throw DdsError("security (ROS_SECURITY_STRATEGY=Enforce): " + prefix + problem);
    plan.root.clear();
    plan.note = "security (Permissive): " + prefix + problem + "; running WITHOUT security";
    return plan;
  }
  plan.secured = true;
  plan.note = "security (" + mode + "): " + prefix + "enclave " + plan.enclave_used + " from " + plan.root.string();
  return plan;
}

std::string security_plugin(const std::string& name) {
#ifdef QUADCOSIM_DDS_SECURITY_PLUGIN_DIR
  const fs::path p = fs::path(QUADCOSIM_DDS_SECURITY_PLUGIN_DIR) / ("lib" + name + ".so");
  std::error_code ec;
  if (fs::is_regular_file(p, ec)) return p.string();
#endif
  return name;
}

void set_security_qos(dds_qos_t* q, const fs::path& root) {
  // The document properties as rmw_cyclonedds sets them: file: URIs with absolute paths.
  const fs::path abs = fs::absolute(root);
  auto file = [&](const char* f) { return "file:" + (abs / f).generic_string(); };
  dds_qset_prop(q, "dds.sec.auth.identity_ca", file("identity_ca.cert.pem").c_str());
  dds_qset_prop(q, "dds.sec.auth.identity_certificate", file("cert.pem").c_str());
  dds_qset_prop(q, "dds.sec.auth.private_key", file("key.pem").c_str());
  dds_qset_prop(q, "dds.sec.access.permissions_ca", file("permissions_ca.cert.pem").c_str());
  dds_qset_prop(q, "dds.sec.access.governance", file("governance.p7s").c_str());
  dds_qset_prop(q, "dds.sec.access.permissions", file("permissions.p7s").c_str());
  std::error_code ec;
  if (fs::is_regular_file(abs / "crl.pem", ec)) {
    dds_qset_prop(q, "org.eclipse.cyclonedds.sec.auth.crl", file("crl.pem").c_str());
  }
  struct Plugin {
    const char* kind;
    const char* library;
    const char* init;
    const char* finalize;
  };
  for (const Plugin& p : {Plugin{"auth", "dds_security_auth", "init_authentication", "finalize_authentication"},
                          Plugin{"crypto", "dds_security_crypto", "init_crypto", "finalize_crypto"},
                          Plugin{"access", "dds_security_ac", "init_access_control", "finalize_access_control"}}) {
    const std::string base = std::string("dds.sec.") + p.kind + ".library.";
    dds_qset_prop(q, (base + "path").c_str(), security_plugin(p.library).c_str());
    dds_qset_prop(q, (base + "init").c_str(), p.init);
    dds_qset_prop(q, (base + "finalize").c_str(), p.finalize);
  }
}

}  // namespace quadcosim::dds
