// DDS Security from the ROS 2 environment: how the variables are read, which enclave directory is
// used, what Enforce and Permissive do with missing files, and a secured participant's USER_DATA.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>

#include "dds/dds_test_support.hpp"
#include "dds/participant.hpp"
#include "security/keystore.hpp"

namespace quadcosim::dds {
namespace {

namespace fs = std::filesystem;

// Sets the four ROS_SECURITY_* variables for one test and restores "unset" afterwards.
class SecurityEnvTest : public ::testing::Test {
 protected:
  void TearDown() override {
    for (const char* v :
         {"ROS_SECURITY_ENABLE", "ROS_SECURITY_STRATEGY", "ROS_SECURITY_KEYSTORE", "ROS_SECURITY_ENCLAVE_OVERRIDE"}) {
      unsetenv(v);
    }
  }
};

TEST_F(SecurityEnvTest, ReadAsRclReadsIt) {
  TearDown();
  EXPECT_FALSE(read_security_environment().enabled);
  setenv("ROS_SECURITY_ENABLE", "true", 1);
  setenv("ROS_SECURITY_STRATEGY", "Enforce", 1);
  setenv("ROS_SECURITY_KEYSTORE", "/k", 1);
  setenv("ROS_SECURITY_ENCLAVE_OVERRIDE", "/o", 1);
  SecurityEnvironment e = read_security_environment();
  EXPECT_TRUE(e.enabled);
  EXPECT_EQ(e.strategy, SecurityStrategy::kEnforce);
  EXPECT_EQ(e.keystore, "/k");
  EXPECT_EQ(e.enclave_override, "/o");
  EXPECT_EQ(e.warning, "");
  // Only the exact words count, as in rcl; other spellings are read the same way but noted.
  setenv("ROS_SECURITY_STRATEGY", "enforce", 1);
  e = read_security_environment();
  EXPECT_EQ(e.strategy, SecurityStrategy::kPermissive);
  EXPECT_NE(e.warning.find("ROS_SECURITY_STRATEGY='enforce'"), std::string::npos);
  setenv("ROS_SECURITY_ENABLE", "1", 1);
  e = read_security_environment();
  EXPECT_FALSE(e.enabled);
  EXPECT_NE(e.warning.find("ROS_SECURITY_ENABLE='1'"), std::string::npos);
}

TEST(SecurityPlanTest, DisabledDoesNothing) {
  const SecurityPlan p = plan_security(SecurityEnvironment{}, "/anything");
  EXPECT_FALSE(p.secured);
  EXPECT_EQ(p.note, "");
}

TEST(SecurityPlanTest, EnforceNamesWhatIsMissing) {
  SecurityEnvironment e;
  e.enabled = true;
  e.strategy = SecurityStrategy::kEnforce;
  try {
    plan_security(e, "/a");
    FAIL() << "no keystore accepted under Enforce";
  } catch (const DdsError& x) {
    EXPECT_NE(std::string(x.what()).find("ROS_SECURITY_KEYSTORE is not set"), std::string::npos) << x.what();
  }
  e.keystore = "/nonexistent/ks";
  try {
    plan_security(e, "/a/b");
    FAIL() << "a missing enclave accepted under Enforce";
  } catch (const DdsError& x) {
    EXPECT_NE(std::string(x.what()).find("/nonexistent/ks/enclaves/a/b: no such directory"), std::string::npos)
        << x.what();
  }
  e.strategy = SecurityStrategy::kPermissive;
  const SecurityPlan p = plan_security(e, "/a/b");
  EXPECT_FALSE(p.secured);
  EXPECT_NE(p.note.find("running WITHOUT security"), std::string::npos) << p.note;
}

TEST(SecurityPlanTest, PluginsFromDebiansDirectoryWhenPresent) {
  const std::string auth = security_plugin("dds_security_auth");
  // Either the full path of an existing file, or the bare name for Cyclone's own search.
  if (auth != "dds_security_auth") {
    EXPECT_TRUE(fs::is_regular_file(auth)) << auth;
    EXPECT_EQ(fs::path(auth).filename(), "libdds_security_auth.so");
  }
}

// A secured participant: the override selects the files, USER_DATA keeps the enclave the node was
// given (as rmw_cyclonedds writes options->enclave).
TEST(SecurityPlanTest, SecuredParticipantWithOverride) {
  RosEnvironment env = test::private_env();
  const fs::path ks = fs::temp_directory_path() / ("quadcosim_dds_ks_" + std::to_string(getpid()));
  fs::remove_all(ks);
  security::create_keystore(ks, env.domain_id);
  security::create_enclave(ks, "/files", {{}, env.domain_id});
  env.enclave = "/given";
  env.security.enabled = true;
  env.security.strategy = SecurityStrategy::kEnforce;
  env.security.keystore = ks.string();
  env.security.enclave_override = "/files";
  const SecurityPlan plan = plan_security(env.security, env.enclave);
  EXPECT_TRUE(plan.secured);
  EXPECT_EQ(plan.root, ks / "enclaves" / "files");
  {
    Participant p(env);
    EXPECT_TRUE(p.secured());
    dds_qos_t* qos = dds_create_qos();
    ASSERT_EQ(dds_get_qos(p.handle(), qos), DDS_RETCODE_OK);
    void* data = nullptr;
    size_t size = 0;
    ASSERT_TRUE(dds_qget_userdata(qos, &data, &size));
    EXPECT_EQ(std::string(static_cast<char*>(data), size), "enclave=/given;");
    char* value = nullptr;
    ASSERT_TRUE(dds_qget_prop(qos, "dds.sec.auth.identity_certificate", &value));
    EXPECT_EQ(std::string(value), "file:" + (ks / "enclaves/files/cert.pem").string());
    dds_free(value);
    dds_free(data);
    dds_delete_qos(qos);
  }
  fs::remove_all(ks);
}

TEST(SecurityPlanTest, EnclaveNameIsChecked) {
  EXPECT_THROW(read_ros_environment("no_slash"), DdsError);
  EXPECT_EQ(read_ros_environment("/quadcosim/plant").enclave, "/quadcosim/plant");
}

}  // namespace
}  // namespace quadcosim::dds
