// The keystore, checked by an independent verifier: the openssl command line (verify, smime -verify,
// x509, pkey), and against the layout and rules SROS2 and rcl document.
#include "security/keystore.hpp"

#include <fcntl.h>
#include <fnmatch.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <map>

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
    create_enclave(*dir_, "/monitor", {{}, 42, true});
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static const fs::path& ks() { return *dir_; }
  static fs::path plant() { return ks() / "enclaves" / "quadcosim" / "plant"; }
  static fs::path rogue() { return ks() / "enclaves" / "rogue"; }
  static fs::path monitor() { return ks() / "enclaves" / "monitor"; }

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

// The rules of a permissions document, evaluated as the DDS Security specification (9.4.1.3) and
// Cyclone DDS's access control plugin apply them: for a writer (reader), the first rule whose
// publish (subscribe) list matches the topic (fnmatch, '*' also across '/') decides; whether the
// topic may be created at all, the first rule naming it in either list; otherwise <default>.
class Grant {
 public:
  explicit Grant(const std::string& xml) {
    EXPECT_NE(xml.find("<default>DENY</default>"), std::string::npos);
    for (std::size_t at = 0;;) {
      const auto allow = xml.find("<allow_rule>", at), deny = xml.find("<deny_rule>", at);
      if (allow == std::string::npos && deny == std::string::npos) break;
      Rule r;
      r.allow = allow < deny;
      const auto begin = std::min(allow, deny);
      const auto end = xml.find(r.allow ? "</allow_rule>" : "</deny_rule>", begin);
      const std::string body = xml.substr(begin, end - begin);
      r.publish = topics(body, "publish");
      r.subscribe = topics(body, "subscribe");
      rules_.push_back(r);
      at = end;
    }
  }
  bool may_write(const std::string& topic) const { return decide(topic, true, false); }
  bool may_read(const std::string& topic) const { return decide(topic, false, true); }
  bool may_create_topic(const std::string& topic) const { return decide(topic, true, true); }

 private:
  struct Rule {
    bool allow = false;
    std::vector<std::string> publish, subscribe;
  };
  static std::vector<std::string> topics(const std::string& body, const std::string& kind) {
    std::vector<std::string> out;
    const auto begin = body.find("<" + kind + ">");
    if (begin == std::string::npos) return out;
    const auto end = body.find("</" + kind + ">", begin);
    for (auto at = body.find("<topic>", begin); at < end; at = body.find("<topic>", at + 1)) {
      const auto from = at + 7;
      out.push_back(body.substr(from, body.find("</topic>", from) - from));
    }
    return out;
  }
  static bool names(const std::vector<std::string>& patterns, const std::string& topic) {
    for (const auto& p : patterns) {
      if (fnmatch(p.c_str(), topic.c_str(), 0) == 0) return true;
    }
    return false;
  }
  bool decide(const std::string& topic, bool publish, bool subscribe) const {
    for (const Rule& r : rules_) {
      if ((publish && names(r.publish, topic)) || (subscribe && names(r.subscribe, topic))) return r.allow;
    }
    return false;  // <default>DENY</default>
  }
  std::vector<Rule> rules_;
};

TEST_F(KeystoreTest, WhatEachPolicyGrants) {
  const Grant all(slurp(plant() / "permissions.xml"));
  const Grant deny(slurp(rogue() / "permissions.xml"));  // --deny-publish /drone/motor_commands
  const Grant ro(slurp(monitor() / "permissions.xml"));  // --read-only
  struct Row {
    std::string topic;
    bool deny_write, deny_read, ro_write, ro_read;
  };
  // DDS topic names as ROS 2 puts them on the wire.
  const std::vector<Row> rows = {
      {"rt/drone/motor_commands", false, true, false, true},
      {"rt/drone/Pose", true, true, false, true},
      {"rt/drone/Imu", true, true, false, true},
      {"rt/uav1/drone/Imu", true, true, false, true},
      {"rt/clock", true, true, false, true},
      {"rt/parameter_events", true, true, false, true},
      {"rq/attitude_controller/set_parametersRequest", false, true, false, false},
      {"rq/uav1/attitude_controller/set_parameters_atomicallyRequest", false, true, false, false},
      {"rq/attitude_controller/get_parametersRequest", true, true, false, false},
      {"rq/attitude_controller/list_parametersRequest", true, true, false, false},
      {"rr/attitude_controller/set_parametersReply", true, true, false, false},
      {"rq/nav/_action/send_goalRequest", true, true, false, false},
      {"ros_discovery_info", true, true, true, true},
  };
  for (const Row& r : rows) {
    EXPECT_TRUE(all.may_write(r.topic) && all.may_read(r.topic)) << r.topic;
    EXPECT_EQ(deny.may_write(r.topic), r.deny_write) << "--deny-publish, write " << r.topic;
    EXPECT_EQ(deny.may_read(r.topic), r.deny_read) << "--deny-publish, read " << r.topic;
    EXPECT_EQ(ro.may_write(r.topic), r.ro_write) << "--read-only, write " << r.topic;
    EXPECT_EQ(ro.may_read(r.topic), r.ro_read) << "--read-only, read " << r.topic;
    // Cyclone refuses a reader or writer whose topic it may not create: every topic read is creatable.
    if (r.deny_read) EXPECT_TRUE(deny.may_create_topic(r.topic)) << r.topic;
    if (r.ro_read) EXPECT_TRUE(ro.may_create_topic(r.topic)) << r.topic;
  }
  // Only the denied topics are named ahead of the sros2 default rule; no subscribe is denied.
  const std::string p = slurp(rogue() / "permissions.xml");
  const std::string rule = p.substr(p.find("<deny_rule>"), p.find("</deny_rule>") - p.find("<deny_rule>"));
  EXPECT_EQ(rule.find("<subscribe>"), std::string::npos);
  EXPECT_EQ(count(rule, "<topic>"), 3u) << rule;
  EXPECT_THROW(
      permissions_xml("/m", {{"/drone/motor_commands"}, 0, true}, "2026-01-01T00:00:00", "2036-01-01T00:00:00"),
      KeystoreError);
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

// ---- keys are never readable by others ------------------------------------------------------------

// Sets the process's umask for one scope.
class ScopedUmask {
 public:
  explicit ScopedUmask(mode_t mask) : old_(umask(mask)) {}
  ~ScopedUmask() { umask(old_); }
  ScopedUmask(const ScopedUmask&) = delete;
  ScopedUmask& operator=(const ScopedUmask&) = delete;

 private:
  mode_t old_;
};

unsigned mode_of(const fs::path& p) {
  struct stat st {};
  EXPECT_EQ(stat(p.c_str(), &st), 0) << p;
  return st.st_mode & 07777;
}

// What inotify saw happen to each name in the watched directories: created, attributes changed.
struct Seen {
  int created = 0;
  int attrib = 0;
};

std::map<std::string, Seen> drain(int fd, const std::map<int, std::string>& dirs) {
  std::map<std::string, Seen> seen;
  alignas(inotify_event) char buf[65536];
  for (ssize_t n; (n = read(fd, buf, sizeof buf)) > 0;) {
    for (char* at = buf; at < buf + n;) {
      const auto* ev = reinterpret_cast<const inotify_event*>(at);
      if (ev->len > 0) {
        Seen& s = seen[dirs.at(ev->wd) + "/" + ev->name];
        if (ev->mask & IN_CREATE) ++s.created;
        if (ev->mask & IN_ATTRIB) ++s.attrib;
      }
      at += sizeof(inotify_event) + ev->len;
    }
  }
  return seen;
}

// A private key's mode can only come from its creation or a later chmod, and inotify reports every
// chmod (IN_ATTRIB). A key that ends at 0600 without any IN_ATTRIB since its IN_CREATE was created
// 0600: never, not for a microsecond, readable by others. Under umask 022, as most users have it.
TEST(KeyFiles, CreatedWithMode0600UnderUmask022) {
  ScopedUmask mask(022);
  const fs::path ks = fs::temp_directory_path() / ("quadcosim_keymodes_" + std::to_string(getpid()));
  fs::remove_all(ks);
  // The directories exist before (as an attacker or an earlier run may have left them, 0755), so
  // that inotify watches them from before the first key.
  fs::create_directories(ks / "private");
  fs::create_directories(ks / "enclaves" / "monitor");
  ASSERT_EQ(mode_of(ks / "private"), 0755u);
  const int fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  ASSERT_GE(fd, 0);
  std::map<int, std::string> dirs;
  for (const char* d : {"private", "enclaves/monitor"}) {
    const int wd = inotify_add_watch(fd, (ks / d).c_str(), IN_CREATE | IN_ATTRIB);
    ASSERT_GE(wd, 0) << d;
    dirs[wd] = d;
  }
  create_keystore(ks, 7);
  create_enclave(ks, "/monitor", {{}, 7});
  const auto seen = drain(fd, dirs);
  close(fd);
  for (const char* key : {"private/ca.key.pem", "enclaves/monitor/key.pem"}) {
    ASSERT_TRUE(seen.count(key)) << key << " was not created in the watched directory";
    EXPECT_EQ(seen.at(key).created, 1) << key;
    EXPECT_EQ(seen.at(key).attrib, 0) << key << ": its mode or owner changed after creation (created readable?)";
    EXPECT_EQ(mode_of(ks / key), 0600u) << key;
  }
  // The folders that hold keys: the owner's only, also when they existed with a looser mode.
  EXPECT_EQ(mode_of(ks / "private"), 0700u);
  EXPECT_EQ(mode_of(ks / "enclaves" / "monitor"), 0700u);
  fs::remove_all(ks);
}

// An attacker's view: another local user (nobody) opens the key files as fast as it can while
// keystores and enclaves are made under umask 022; any descriptor it gets is a copied key. Needs
// root (to become nobody).
TEST(KeyFiles, AnotherUserNeverOpensAKey) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to run the reader as the user nobody";
  ScopedUmask mask(022);
  constexpr int kRounds = 40;
  const fs::path base = fs::temp_directory_path() / ("quadcosim_keyrace_" + std::to_string(getpid()));
  fs::remove_all(base);
  fs::create_directories(base);
  fs::permissions(base, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec | fs::perms::others_read |
                            fs::perms::others_exec);
  // Shared with the reader: the round being made (-1: stop) and the keys it opened.
  struct Shared {
    std::atomic<int> round;
    std::atomic<int> opened;
    std::atomic<int> nonempty;
  };
  void* mem = mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(mem, MAP_FAILED);
  auto* shared = new (mem) Shared{{0}, {0}, {0}};
  auto paths = [&](int round) {
    const fs::path ks = base / ("ks" + std::to_string(round));
    return std::array<std::string, 2>{(ks / "private" / "ca.key.pem").string(),
                                      (ks / "enclaves" / "monitor" / "key.pem").string()};
  };
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    if (setgroups(0, nullptr) != 0 || setgid(65534) != 0 || setuid(65534) != 0) _exit(3);
    std::map<std::string, int> fds;  // one descriptor per key file opened
    for (int r; (r = shared->round.load()) >= 0;) {
      for (const auto& p : paths(r)) {
        if (fds.count(p)) continue;
        const int f = open(p.c_str(), O_RDONLY | O_CLOEXEC);
        if (f >= 0) fds[p] = f;
      }
    }
    // Read what the descriptors hold now that the writer has finished.
    for (const auto& [path, f] : fds) {
      char c;
      shared->opened.fetch_add(1);
      if (pread(f, &c, 1, 0) == 1) shared->nonempty.fetch_add(1);
    }
    _exit(0);
  }
  for (int r = 0; r < kRounds; ++r) {
    shared->round.store(r);
    const fs::path ks = base / ("ks" + std::to_string(r));
    create_keystore(ks, 7);
    create_enclave(ks, "/monitor", {{}, 7});
  }
  shared->round.store(-1);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << status;
  ASSERT_EQ(WEXITSTATUS(status), 0) << "the reader could not become nobody";
  EXPECT_EQ(shared->opened.load(), 0) << "nobody opened " << shared->opened.load() << " key files ("
                                      << shared->nonempty.load() << " with the key in them) of " << 2 * kRounds;
  shared->~Shared();
  munmap(mem, sizeof(Shared));
  fs::remove_all(base);
}

// ---- the XML beside a signature is what is signed ------------------------------------------------

TEST_F(KeystoreTest, CheckRefusesAnXmlThatDiffersFromItsSignature) {
  const fs::path bad = ks() / "enclaves" / "quadcosim" / "edited";  // beside plant: its relative links hold
  fs::remove_all(bad);
  fs::create_directories(bad);
  for (const auto& f : enclave_files()) fs::copy(plant() / f, bad / f, fs::copy_options::copy_symlinks);
  fs::copy(plant() / "permissions.xml", bad / "permissions.xml");
  auto joined = [&] {
    std::string s;
    for (const auto& p : check_enclave(bad)) s += p + "\n";
    return s;
  };
  ASSERT_EQ(joined(), "");
  // A user edits permissions.xml (here: allows everything by default) and does not sign it again.
  std::string xml = slurp(bad / "permissions.xml");
  xml.replace(xml.find("<default>DENY</default>"), 23, "<default>ALLOW</default>");
  std::ofstream(bad / "permissions.xml", std::ios::trunc) << xml;
  EXPECT_NE(joined().find((bad / "permissions.xml").string() + ": differs from what permissions.p7s signs"),
            std::string::npos)
      << joined();
  fs::copy(plant() / "permissions.xml", bad / "permissions.xml", fs::copy_options::overwrite_existing);
  EXPECT_EQ(joined(), "");
  // The governance: the enclave's governance.p7s links to enclaves/governance.p7s, beside which
  // governance.xml lies.
  const fs::path gov = ks() / "enclaves" / "governance.xml";
  const std::string original = slurp(gov);
  std::string edited = original;
  edited.replace(edited.find("<rtps_protection_kind>SIGN"), 26, "<rtps_protection_kind>NONE");
  std::ofstream(gov, std::ios::trunc) << edited;
  EXPECT_NE(joined().find(gov.string() + ": differs from what governance.p7s signs"), std::string::npos) << joined();
  std::ofstream(gov, std::ios::trunc) << original;
  EXPECT_EQ(joined(), "");
  fs::remove_all(bad);
}

}  // namespace
}  // namespace quadcosim::security
