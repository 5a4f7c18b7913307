// security/keystore.hpp: the governance and permissions documents of a keystore, as sros2 writes them
// (the XML only; signing them is keystore.cpp's).
#include <cstdint>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "security/keystore.hpp"

namespace quadcosim::security {

namespace {

const char kGovernanceHeader[] =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
    "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd\">\n";
const char kPermissionsHeader[] =
    "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
    "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd\">\n";

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      default: o += c;
    }
  }
  return o;
}

void topics_block(std::ostringstream& x, const char* kind, const std::set<std::string>& topics) {
  x << "        <" << kind << ">\n          <topics>\n";
  for (const auto& t : topics) x << "            <topic>" << xml_escape(t) << "</topic>\n";
  x << "          </topics>\n        </" << kind << ">\n";
}

void domains_block(std::ostringstream& x, std::uint32_t domain_id) {
  x << "        <domains>\n          <id>" << domain_id << "</id>\n        </domains>\n";
}

}  // namespace

std::string governance_xml(std::uint32_t domain_id) {
  std::ostringstream x;
  x << kGovernanceHeader
    << "  <domain_access_rules>\n"
       "    <domain_rule>\n"
       "      <domains>\n"
       "        <id>"
    << domain_id
    << "</id>\n"
       "      </domains>\n"
       "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
       "      <enable_join_access_control>true</enable_join_access_control>\n"
       "      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>\n"
       "      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>\n"
       "      <rtps_protection_kind>SIGN</rtps_protection_kind>\n"
       "      <topic_access_rules>\n"
       "        <topic_rule>\n"
       "          <topic_expression>*</topic_expression>\n"
       "          <enable_discovery_protection>true</enable_discovery_protection>\n"
       "          <enable_liveliness_protection>true</enable_liveliness_protection>\n"
       "          <enable_read_access_control>true</enable_read_access_control>\n"
       "          <enable_write_access_control>true</enable_write_access_control>\n"
       "          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>\n"
       "          <data_protection_kind>ENCRYPT</data_protection_kind>\n"
       "        </topic_rule>\n"
       "      </topic_access_rules>\n"
       "    </domain_rule>\n"
       "  </domain_access_rules>\n"
       "</dds>\n";
  return x.str();
}

const std::vector<std::string>& parameter_change_requests() {
  static const std::vector<std::string> topics = {"rq/*/set_parametersRequest",
                                                  "rq/*/set_parameters_atomicallyRequest"};
  return topics;
}

std::string permissions_xml(const std::string& enclave, const EnclavePolicy& policy, const std::string& not_before,
                            const std::string& not_after) {
  if (const std::string why = enclave_name_error(enclave); !why.empty()) {
    throw KeystoreError("enclave '" + enclave + "': " + why);
  }
  if (policy.read_only && !policy.deny_publish.empty()) {
    throw KeystoreError("enclave '" + enclave +
                        "': a read-only policy denies every publication already; "
                        "it takes no topics to deny");
  }
  // SROS2's default policy (topics "/*", services "/*", actions "/*" all allowed), as its
  // permissions.xsl expands it: the same topic set is published and subscribed.
  const std::set<std::string> all = {"rq/*/_action/cancel_goalRequest",
                                     "rq/*/_action/get_resultRequest",
                                     "rq/*/_action/send_goalRequest",
                                     "rq/*Request",
                                     "rr/*/_action/cancel_goalReply",
                                     "rr/*/_action/get_resultReply",
                                     "rr/*/_action/send_goalReply",
                                     "rr/*Reply",
                                     "rt/*",
                                     "rt/*/_action/feedback",
                                     "rt/*/_action/status"};
  std::set<std::string> denied;
  for (const auto& topic : policy.deny_publish) {
    if (topic.empty() || topic[0] != '/') {
      throw KeystoreError("denied topic '" + topic + "': expected a fully qualified ROS topic name starting with '/'");
    }
    denied.insert("rt" + topic);
  }
  // Whoever may set a node's parameters decides what it publishes (a controller's z_des moves the
  // vehicle as surely as a motor command), and an enclave does not know which node publishes a topic:
  // denying any topic also denies setting any node's parameters. Getting, listing and describing stay.
  if (!denied.empty()) denied.insert(parameter_change_requests().begin(), parameter_change_requests().end());
  std::ostringstream x;
  x << kPermissionsHeader << "  <permissions>\n"
    << "    <grant name=\"" << xml_escape(enclave) << "\">\n"
    << "      <subject_name>CN=" << xml_escape(enclave) << "</subject_name>\n"
    << "      <validity>\n        <not_before>" << not_before << "</not_before>\n        <not_after>" << not_after
    << "</not_after>\n      </validity>\n";
  // Rules apply in document order. For a writer (reader) the first rule whose publish (subscribe)
  // list names the topic decides; whether the topic may be created at all, Cyclone DDS decides by the
  // first rule naming it in either list. So the denied topics are first allowed for subscribing only
  // (the enclave still reads them, and serves its own parameters), then denied for publishing, ahead
  // of the allow rules, as sros2's permissions.xsl places deny rules.
  if (policy.read_only) {
    x << "      <allow_rule>\n";
    domains_block(x, policy.domain_id);
    topics_block(x, "subscribe", {"rt/*"});
    x << "      </allow_rule>\n";
  } else {
    if (!denied.empty()) {
      x << "      <allow_rule>\n";
      domains_block(x, policy.domain_id);
      topics_block(x, "subscribe", denied);
      x << "      </allow_rule>\n      <deny_rule>\n";
      domains_block(x, policy.domain_id);
      topics_block(x, "publish", denied);
      x << "      </deny_rule>\n";
    }
    x << "      <allow_rule>\n";
    domains_block(x, policy.domain_id);
    topics_block(x, "publish", all);
    topics_block(x, "subscribe", all);
    x << "      </allow_rule>\n";
  }
  // The ROS graph topic (no rt/ prefix) every rmw with graph information uses; rmw_cyclonedds and
  // quadcosim's nodes cannot start without its writer. It carries node names, not data.
  x << "      <allow_rule>\n";
  domains_block(x, policy.domain_id);
  topics_block(x, "publish", {"ros_discovery_info"});
  topics_block(x, "subscribe", {"ros_discovery_info"});
  x << "      </allow_rule>\n"
    << "      <default>DENY</default>\n"
    << "    </grant>\n  </permissions>\n</dds>\n";
  return x.str();
}

}  // namespace quadcosim::security
