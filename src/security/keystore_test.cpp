// The keystore, checked by an independent verifier: the openssl command line (verify, smime -verify,
// x509, pkey), and against the layout and rules SROS2 and rcl document.
#include "security/keystore.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace quadcosim::security {
namespace {

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string out;
};

// Runs `args` through the shell (stderr joined to stdout); each argument is single-quoted.
Result run(const std::vector<std::string>& args) {
  std::string cmd;
  for (const auto& a : args) cmd += "'" + a + "' ";
  cmd += "2>&1";
  Result r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  for (std::size_t n; (n = fread(buf.data(), 1, buf.size(), p)) > 0;) r.out.append(buf.data(), n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

Result openssl(std::vector<std::string> args) {
  args.insert(args.begin(), QUADCOSIM_OPENSSL);
  return run(args);
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// "notBefore=Nov 21 07:02:14 2026 GMT" -> seconds since the epoch (UTC).
std::time_t openssl_date(const std::string& text, const std::string& key) {
  const auto at = text.find(key + "=");
  EXPECT_NE(at, std::string::npos) << text;
  std::tm tm{};
  std::istringstream in(text.substr(at + key.size() + 1));
  in >> std::get_time(&tm, "%b %d %H:%M:%S %Y");
  return timegm(&tm);
}

std::string iso(std::time_t t) {
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

class KeystoreTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("quadcosim_keystore_" + std::to_string(getpid())));
    fs::remove_all(*dir_);
    create_keystore(*dir_, 42);
    create_enclave(*dir_, "/quadcosim/plant", {{}, 42});
    create_enclave(*dir_, "/rogue", {{"/drone/motor_commands"}, 42});
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static const fs::path& ks() { return *dir_; }
  static fs::path plant() { return ks() / "enclaves" / "quadcosim" / "plant"; }
  static fs::path rogue() { return ks() / "enclaves" / "rogue"; }

 private:
  static fs::path* dir_;
};
fs::path* KeystoreTest::dir_ = nullptr;

TEST(EnclaveName, RclRules) {
  for (const char* ok : {"/", "/foo", "/foo/bar", "/foo/bar123/_/baz_", "/quadcosim/plant"}) {
    EXPECT_EQ(enclave_name_error(ok), "") << ok;
  }
  for (const char* bad : {"", " ", "//", "foo", "foo/bar", "/42foo", "/foo/42bar", "/foo/", "/a b", "/a-b"}) {
    EXPECT_NE(enclave_name_error(bad), "") << bad;
  }
  EXPECT_NE(enclave_name_error("/" + std::string(300, 'a')), "");
}

TEST(EnclaveName, DirectoryAsRclResolvesIt) {
  EXPECT_EQ(enclave_dir("/k", "/"), fs::path("/k/enclaves"));
  EXPECT_EQ(enclave_dir("/k", "/quadcosim/plant"), fs::path("/k/enclaves/quadcosim/plant"));
}

TEST_F(KeystoreTest, LayoutAsSros2) {
  EXPECT_TRUE(is_keystore(ks()));
  for (const char* f :
       {"public/ca.cert.pem", "private/ca.key.pem", "enclaves/governance.xml", "enclaves/governance.p7s"}) {
    EXPECT_TRUE(fs::is_regular_file(ks() / f)) << f;
  }
  // One CA serves identity and permissions: links to ca.*.pem.
  for (const char* f : {"public/identity_ca.cert.pem", "public/permissions_ca.cert.pem"}) {
    ASSERT_TRUE(fs::is_symlink(ks() / f)) << f;
    EXPECT_EQ(fs::read_symlink(ks() / f), fs::path("ca.cert.pem"));
  }
  for (const char* f : {"private/identity_ca.key.pem", "private/permissions_ca.key.pem"}) {
    ASSERT_TRUE(fs::is_symlink(ks() / f)) << f;
    EXPECT_EQ(fs::read_symlink(ks() / f), fs::path("ca.key.pem"));
  }
  for (const auto& f : enclave_files()) EXPECT_TRUE(fs::is_regular_file(plant() / f)) << f;
  EXPECT_TRUE(fs::is_regular_file(plant() / "permissions.xml"));
  // Relative links, so the keystore can be moved.
  EXPECT_EQ(fs::read_symlink(plant() / "identity_ca.cert.pem"), fs::path("../../../public/identity_ca.cert.pem"));
  EXPECT_EQ(fs::read_symlink(plant() / "governance.p7s"), fs::path("../../governance.p7s"));
  EXPECT_EQ(fs::status(plant() / "key.pem").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_TRUE(check_enclave(plant()).empty());
}

TEST_F(KeystoreTest, CreatingAgainIsRefused) {
  EXPECT_THROW(create_keystore(ks(), 0), KeystoreError);
  EXPECT_THROW(create_enclave(ks() / "public", "/x", {}), KeystoreError);  // not a keystore
  EXPECT_THROW(create_enclave(ks(), "/4x", {}), KeystoreError);
  EXPECT_THROW(create_enclave(ks(), "/x", {{"drone/relative"}, 0}), KeystoreError);
}

TEST_F(KeystoreTest, CertificatesVerifyWithOpenssl) {
  const auto ca = (ks() / "public" / "ca.cert.pem").string();
  const Result r = openssl({"verify", "-CAfile", ca, (plant() / "cert.pem").string()});
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find(": OK"), std::string::npos) << r.out;
  // A certificate from another keystore does not verify against this CA.
  const fs::path other = ks().parent_path() / (ks().filename().string() + "_other");
  fs::remove_all(other);
  create_keystore(other, 42);
  create_enclave(other, "/quadcosim/plant", {{}, 42});
  EXPECT_NE(openssl({"verify", "-CAfile", ca, (other / "enclaves/quadcosim/plant/cert.pem").string()}).status, 0);
  fs::remove_all(other);
}

TEST_F(KeystoreTest, KeysAndNames) {
  for (const fs::path& key : {ks() / "private" / "ca.key.pem", plant() / "key.pem"}) {
    EXPECT_EQ(slurp(key).rfind("-----BEGIN PRIVATE KEY-----", 0), 0u) << key;  // PKCS#8
    const Result r = openssl({"pkey", "-in", key.string(), "-noout", "-text"});
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("ASN1 OID: prime256v1"), std::string::npos) << r.out;
  }
  const Result ca =
      openssl({"x509", "-in", (ks() / "public/ca.cert.pem").string(), "-noout", "-text", "-nameopt", "RFC2253"});
  EXPECT_NE(ca.out.find("Subject: CN=sros2CA"), std::string::npos) << ca.out;
  EXPECT_NE(ca.out.find("Issuer: CN=sros2CA"), std::string::npos) << ca.out;
  EXPECT_NE(ca.out.find("X509v3 Basic Constraints: critical"), std::string::npos) << ca.out;
  EXPECT_NE(ca.out.find("CA:TRUE, pathlen:1"), std::string::npos) << ca.out;
  EXPECT_NE(ca.out.find("ecdsa-with-SHA256"), std::string::npos) << ca.out;
  const Result id = openssl({"x509", "-in", (plant() / "cert.pem").string(), "-noout", "-text", "-nameopt", "RFC2253"});
  EXPECT_NE(id.out.find("Subject: CN=/quadcosim/plant"), std::string::npos) << id.out;
  EXPECT_NE(id.out.find("Issuer: CN=sros2CA"), std::string::npos) << id.out;
  EXPECT_NE(id.out.find("CA:FALSE"), std::string::npos) << id.out;
  EXPECT_NE(id.out.find("prime256v1"), std::string::npos) << id.out;
}

TEST_F(KeystoreTest, ValidityIsTenYearsFromYesterday) {
  for (const fs::path& cert : {ks() / "public/ca.cert.pem", plant() / "cert.pem"}) {
    const Result r = openssl({"x509", "-in", cert.string(), "-noout", "-dates"});
    const std::time_t now = std::time(nullptr);
    const std::time_t before = openssl_date(r.out, "notBefore"), after = openssl_date(r.out, "notAfter");
    EXPECT_NEAR(static_cast<double>(now - before), 86400.0, 600.0) << r.out;
    EXPECT_EQ(after - before, (3650L + 1L) * 86400L) << r.out;
    EXPECT_EQ(openssl({"x509", "-in", cert.string(), "-noout", "-checkend", "0"}).status, 0);
  }
}

TEST_F(KeystoreTest, SignedDocumentsVerifyWithOpensslSmime) {
  const auto perm_ca = (ks() / "public" / "permissions_ca.cert.pem").string();
  const fs::path out = ks() / "verified.txt";
  for (const auto& [p7s, xml] : {std::pair{ks() / "enclaves/governance.p7s", ks() / "enclaves/governance.xml"},
                                 std::pair{plant() / "permissions.p7s", plant() / "permissions.xml"},
                                 std::pair{rogue() / "permissions.p7s", rogue() / "permissions.xml"}}) {
    const Result r =
        openssl({"smime", "-verify", "-in", p7s.string(), "-CAfile", perm_ca, "-text", "-out", out.string()});
    EXPECT_EQ(r.status, 0) << p7s << ": " << r.out;
    // The signed text is the XML beside it (S/MIME text mode carries it with CRLF line ends).
    std::string signed_text = slurp(out);
    std::erase(signed_text, '\r');
    EXPECT_EQ(signed_text, slurp(xml)) << p7s;
    const std::string mime = slurp(p7s);
    EXPECT_NE(mime.find("multipart/signed"), std::string::npos);  // detached S/MIME
    EXPECT_NE(mime.find("micalg=\"sha-256\""), std::string::npos);
  }
  fs::remove(out);
}

TEST_F(KeystoreTest, GovernanceAsSros2Default) {
  const std::string g = slurp(ks() / "enclaves/governance.xml");
  for (const char* s : {"<id>42</id>", "<allow_unauthenticated_participants>false</allow_unauthenticated_participants>",
                        "<enable_join_access_control>true</enable_join_access_control>",
                        "<discovery_protection_kind>ENCRYPT</discovery_protection_kind>",
                        "<liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>",
                        "<rtps_protection_kind>SIGN</rtps_protection_kind>", "<topic_expression>*</topic_expression>",
                        "<enable_read_access_control>true</enable_read_access_control>",
                        "<enable_write_access_control>true</enable_write_access_control>",
                        "<metadata_protection_kind>ENCRYPT</metadata_protection_kind>",
                        "<data_protection_kind>ENCRYPT</data_protection_kind>"}) {
    EXPECT_NE(g.find(s), std::string::npos) << s;
  }
}

// Count of `what` in `text`.
std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST_F(KeystoreTest, PermissionsForTheEnclave) {
  const std::string p = slurp(plant() / "permissions.xml");
  EXPECT_NE(p.find("<grant name=\"/quadcosim/plant\">"), std::string::npos);
  EXPECT_NE(p.find("<subject_name>CN=/quadcosim/plant</subject_name>"), std::string::npos);
  EXPECT_EQ(count(p, "<id>42</id>"), 2u);  // both allow rules, for the domain given
  // ROS 2 names on the wire: topics rt/..., services rq/...Request and rr/...Reply, the graph topic;
  // each allowed both ways.
  for (const char* t : {"rt/*", "rq/*Request", "rr/*Reply", "rt/*/_action/feedback", "ros_discovery_info"}) {
    EXPECT_EQ(count(p, std::string("<topic>") + t + "</topic>"), 2u) << t;
  }
  EXPECT_EQ(p.find("deny_rule"), std::string::npos);
  EXPECT_NE(p.find("<default>DENY</default>"), std::string::npos);
  // The grant is valid exactly as long as the certificate (as sros2 writes it).
  const Result d = openssl({"x509", "-in", (plant() / "cert.pem").string(), "-noout", "-dates"});
  EXPECT_NE(p.find("<not_before>" + iso(openssl_date(d.out, "notBefore")) + "</not_before>"), std::string::npos) << p;
  EXPECT_NE(p.find("<not_after>" + iso(openssl_date(d.out, "notAfter")) + "</not_after>"), std::string::npos) << p;
}

TEST_F(KeystoreTest, DenyPublishComesFirst) {
  const std::string p = slurp(rogue() / "permissions.xml");
  const auto deny = p.find("<deny_rule>"), allow = p.find("<allow_rule>");
  ASSERT_NE(deny, std::string::npos);
  ASSERT_NE(allow, std::string::npos);
  EXPECT_LT(deny, allow);  // rules apply in order: the first naming a topic decides
  const std::string rule = p.substr(deny, p.find("</deny_rule>") - deny);
  EXPECT_NE(rule.find("<publish>"), std::string::npos);
  EXPECT_EQ(rule.find("<subscribe>"), std::string::npos);
  EXPECT_NE(rule.find("<topic>rt/drone/motor_commands</topic>"), std::string::npos);
}

TEST_F(KeystoreTest, CreatingAnEnclaveAgainKeepsItsIdentity) {
  const std::string cert = slurp(rogue() / "cert.pem"), key = slurp(rogue() / "key.pem");
  create_enclave(ks(), "/rogue", {{"/drone/motor_commands", "/drone/Pose"}, 42});
  EXPECT_EQ(slurp(rogue() / "cert.pem"), cert);
  EXPECT_EQ(slurp(rogue() / "key.pem"), key);
  EXPECT_NE(slurp(rogue() / "permissions.xml").find("<topic>rt/drone/Pose</topic>"), std::string::npos);
  create_enclave(ks(), "/rogue", {{"/drone/motor_commands"}, 42});
}

TEST_F(KeystoreTest, CheckNamesWhatIsWrong) {
  const fs::path bad = ks() / "enclaves" / "broken";
  fs::remove_all(bad);
  fs::create_directories(bad);
  for (const auto& f : enclave_files()) fs::copy(plant() / f, bad / f);
  EXPECT_TRUE(check_enclave(bad).empty());
  auto joined = [&] {
    std::string s;
    for (const auto& p : check_enclave(bad)) s += p + "\n";
    return s;
  };
  // A key that is not the certificate's.
  fs::copy(rogue() / "key.pem", bad / "key.pem", fs::copy_options::overwrite_existing);
  EXPECT_NE(joined().find("key.pem: does not belong to cert.pem"), std::string::npos) << joined();
  fs::copy(plant() / "key.pem", bad / "key.pem", fs::copy_options::overwrite_existing);
  // Permissions for another subject.
  fs::copy(rogue() / "permissions.p7s", bad / "permissions.p7s", fs::copy_options::overwrite_existing);
  EXPECT_NE(joined().find("no grant for the identity's subject CN=/quadcosim/plant"), std::string::npos) << joined();
  // A signed document altered after signing: openssl and the check both refuse it.
  std::string p7s = slurp(plant() / "permissions.p7s");
  p7s.replace(p7s.find("<default>DENY</default>"), 23, "<default>ALLOW</default>");
  std::ofstream(bad / "permissions.p7s", std::ios::trunc) << p7s;
  EXPECT_NE(openssl({"smime", "-verify", "-in", (bad / "permissions.p7s").string(), "-CAfile",
                     (ks() / "public/ca.cert.pem").string(), "-out", "/dev/null"})
                .status,
            0);
  EXPECT_NE(joined().find("permissions.p7s: signature does not verify"), std::string::npos) << joined();
  // A missing file is named.
  fs::remove(bad / "governance.p7s");
  EXPECT_NE(joined().find("governance.p7s: missing"), std::string::npos) << joined();
  fs::remove_all(bad);
  EXPECT_NE(check_enclave(bad).at(0).find("no such directory"), std::string::npos);
}

}  // namespace
}  // namespace quadcosim::security
