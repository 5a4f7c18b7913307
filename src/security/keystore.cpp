#include "security/keystore.hpp"

#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

namespace quadcosim::security {

namespace fs = std::filesystem;

namespace {

// ---- OpenSSL ownership ---------------------------------------------------------------------------
struct Free {
  void operator()(BIO* p) const { BIO_free_all(p); }
  void operator()(EVP_PKEY* p) const { EVP_PKEY_free(p); }
  void operator()(X509* p) const { X509_free(p); }
  void operator()(X509_STORE* p) const { X509_STORE_free(p); }
  void operator()(X509_STORE_CTX* p) const { X509_STORE_CTX_free(p); }
  void operator()(PKCS7* p) const { PKCS7_free(p); }
  void operator()(BIGNUM* p) const { BN_free(p); }
  void operator()(X509_EXTENSION* p) const { X509_EXTENSION_free(p); }
};
template <class T>
using Own = std::unique_ptr<T, Free>;

// The newest OpenSSL error as text (empties the queue).
std::string openssl_error() {
  std::string text;
  while (const unsigned long e = ERR_get_error()) {
    char buf[256];
    ERR_error_string_n(e, buf, sizeof buf);
    text = buf;
  }
  return text.empty() ? "unknown OpenSSL error" : text;
}

[[noreturn]] void fail(const std::string& what) { throw KeystoreError(what + ": " + openssl_error()); }

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) throw KeystoreError(p.string() + ": cannot read");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  if (!f || !(f << text) || !f.flush()) throw KeystoreError(p.string() + ": cannot write");
}

std::string errno_text(int e) { return std::strerror(e); }

// The process's umask for one scope.
class ScopedUmask {
 public:
  explicit ScopedUmask(mode_t mask) : old_(::umask(mask)) {}
  ~ScopedUmask() { ::umask(old_); }
  ScopedUmask(const ScopedUmask&) = delete;
  ScopedUmask& operator=(const ScopedUmask&) = delete;

 private:
  mode_t old_;
};

// Writes private key material to the new file `p`, created 0600 in the same call that creates it
// (O_CREAT|O_EXCL, umask 077 meanwhile), so that no other user can open it at any moment; never
// follows a link and never overwrites: an existing `p` is an error. A partly written file is removed.
// (OpenSSL writes no file here: keys are encoded into memory and written by this function only.)
void write_secret(const fs::path& p, const std::string& text) {
  const ScopedUmask mask(077);
  const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) {
    const int e = errno;
    throw KeystoreError(p.string() + ": cannot create the key file (" + errno_text(e) +
                        (e == EEXIST ? "; a key file is never overwritten: remove it first" : "") + ")");
  }
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  const int write_errno = errno;
  if (::close(fd) != 0 || done != text.size()) {
    ::unlink(p.c_str());
    throw KeystoreError(p.string() + ": cannot write the key file (" + errno_text(write_errno) + ")");
  }
}

std::string bio_text(BIO* b) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(b, &data);
  return std::string(data, static_cast<std::size_t>(n));
}

Own<BIO> mem_bio(const std::string& text) {
  Own<BIO> b(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
  if (!b) fail("BIO_new_mem_buf");
  return b;
}

Own<X509> load_cert(const fs::path& p) {
  const std::string pem = read_file(p);
  Own<X509> c(PEM_read_bio_X509(mem_bio(pem).get(), nullptr, nullptr, nullptr));
  if (!c) throw KeystoreError(p.string() + ": not a PEM X.509 certificate (" + openssl_error() + ")");
  return c;
}

Own<EVP_PKEY> load_key(const fs::path& p) {
  const std::string pem = read_file(p);
  Own<EVP_PKEY> k(PEM_read_bio_PrivateKey(mem_bio(pem).get(), nullptr, nullptr, nullptr));
  if (!k) throw KeystoreError(p.string() + ": not an unencrypted PEM private key (" + openssl_error() + ")");
  return k;
}

// ---- making keys, certificates, signatures ---------------------------------------------------------
// DDS Security 9.3.1 / sros2: ECDSA on prime256v1 (secp256r1).
Own<EVP_PKEY> new_ec_key() {
  Own<EVP_PKEY> k(EVP_EC_gen("prime256v1"));
  if (!k) fail("EC key generation (prime256v1)");
  return k;
}

std::string key_pem(EVP_PKEY* k) {  // PKCS#8, unencrypted, as sros2 writes it
  Own<BIO> b(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_PrivateKey(b.get(), k, nullptr, nullptr, 0, nullptr, nullptr)) fail("writing a key");
  return bio_text(b.get());
}

std::string cert_pem(X509* c) {
  Own<BIO> b(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_X509(b.get(), c)) fail("writing a certificate");
  return bio_text(b.get());
}

constexpr long kDaySeconds = 24L * 3600L;
constexpr long kValidityDays = 3650;  // sros2: 10 years

// A certificate for `subject_cn` with `key`'s public half, signed by `issuer_key` (issuer name from
// `issuer`, or self-signed when null). Valid from one day ago (sros2 does so that peers with a clock a
// little behind accept it) for kValidityDays.
Own<X509> make_cert(const std::string& subject_cn, EVP_PKEY* key, bool ca, X509* issuer, EVP_PKEY* issuer_key) {
  Own<X509> c(X509_new());
  if (!c || !X509_set_version(c.get(), 2)) fail("X509_new");
  unsigned char serial[20];
  if (RAND_bytes(serial, sizeof serial) != 1) fail("RAND_bytes");
  serial[0] &= 0x7f;  // positive, at most 159 bits, as RFC 5280 and sros2's random serials
  Own<BIGNUM> bn(BN_bin2bn(serial, sizeof serial, nullptr));
  if (!bn || !BN_to_ASN1_INTEGER(bn.get(), X509_get_serialNumber(c.get()))) fail("serial number");
  if (!X509_gmtime_adj(X509_getm_notBefore(c.get()), -kDaySeconds) ||
      !X509_gmtime_adj(X509_getm_notAfter(c.get()), kValidityDays * kDaySeconds)) {
    fail("validity");
  }
  X509_NAME* name = X509_get_subject_name(c.get());
  if (!X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(subject_cn.c_str()),
                                  -1, -1, 0)) {
    fail("subject name '" + subject_cn + "'");
  }
  if (!X509_set_issuer_name(c.get(), issuer ? X509_get_subject_name(issuer) : name)) fail("issuer name");
  if (!X509_set_pubkey(c.get(), key)) fail("public key");
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer ? issuer : c.get(), c.get(), nullptr, nullptr, 0);
  Own<X509_EXTENSION> bc(
      X509V3_EXT_conf_nid(nullptr, &ctx, NID_basic_constraints, ca ? "critical,CA:TRUE,pathlen:1" : "CA:FALSE"));
  if (!bc || !X509_add_ext(c.get(), bc.get(), -1)) fail("basicConstraints");
  if (!X509_sign(c.get(), issuer_key, EVP_sha256())) fail("signing the certificate for '" + subject_cn + "'");
  return c;
}

// S/MIME, detached, text (what `openssl smime -sign -text` and sros2 write).
std::string smime_sign(const std::string& document, X509* signer, EVP_PKEY* key) {
  const int flags = PKCS7_DETACHED | PKCS7_TEXT;
  Own<PKCS7> p7(PKCS7_sign(signer, key, nullptr, mem_bio(document).get(), flags));
  if (!p7) fail("S/MIME signing");
  Own<BIO> out(BIO_new(BIO_s_mem()));
  if (!SMIME_write_PKCS7(out.get(), p7.get(), mem_bio(document).get(), flags)) fail("S/MIME writing");
  return bio_text(out.get());
}

// The certificate's validity as sros2 writes it into permissions ("YYYY-MM-DDTHH:MM:SS", UTC).
std::string iso_time(const ASN1_TIME* t) {
  std::tm tm{};
  if (!ASN1_TIME_to_tm(t, &tm)) fail("certificate time");
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

void symlink_to(const fs::path& target, const fs::path& link) {
  std::error_code ec;
  if (fs::is_symlink(link, ec) || fs::exists(link, ec)) fs::remove(link, ec);
  fs::create_symlink(target.lexically_relative(link.parent_path()), link, ec);
  if (ec) throw KeystoreError(link.string() + ": cannot create link to " + target.string() + ": " + ec.message());
}

void make_dir(const fs::path& p) {
  std::error_code ec;
  fs::create_directories(p, ec);
  if (ec) throw KeystoreError(p.string() + ": cannot create directory: " + ec.message());
}

// `p` as a folder for keys: created 0700 (its parents as make_dir makes them), or an existing folder
// of this user set to 0700; one owned by another user is refused (its owner could read our keys).
void make_private_dir(const fs::path& p) {
  make_dir(p.parent_path());
  {
    const ScopedUmask mask(077);
    if (::mkdir(p.c_str(), 0700) != 0 && errno != EEXIST) {
      throw KeystoreError(p.string() + ": cannot create directory: " + errno_text(errno));
    }
  }
  struct stat st {};
  if (::stat(p.c_str(), &st) != 0) throw KeystoreError(p.string() + ": " + errno_text(errno));
  if (!S_ISDIR(st.st_mode)) throw KeystoreError(p.string() + ": not a directory");
  if (st.st_uid != ::geteuid()) {
    throw KeystoreError(p.string() + ": owned by user id " + std::to_string(st.st_uid) +
                        ", not by this user; keys are not written into another user's folder");
  }
  if ((st.st_mode & 07777) != 0700 && ::chmod(p.c_str(), 0700) != 0) {
    throw KeystoreError(p.string() + ": cannot set mode 0700: " + errno_text(errno));
  }
}

}  // namespace

std::string enclave_name_error(const std::string& name) {
  if (name.empty()) return "an enclave name must not be empty";
  if (name.size() > 255) return "an enclave name has at most 255 characters";
  if (name[0] != '/') return "an enclave name must start with '/'";
  if (name == "/") return "";
  if (name.back() == '/') return "an enclave name must not end with '/'";
  bool token_start = true;
  for (std::size_t i = 1; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '/') {
      if (token_start) return "an enclave name must not contain '//'";
      token_start = true;
      continue;
    }
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) {
      return std::string("character '") + c + "' at index " + std::to_string(i) +
             " is not allowed (only letters, digits, '_' and '/')";
    }
    if (token_start && std::isdigit(static_cast<unsigned char>(c))) {
      return "a name token must not start with a digit (index " + std::to_string(i) + ")";
    }
    token_start = false;
  }
  return "";
}

fs::path enclave_dir(const fs::path& keystore, const std::string& enclave) {
  const fs::path enclaves = keystore / "enclaves";
  return enclave == "/" ? enclaves : enclaves / enclave.substr(1);
}

const std::vector<std::string>& enclave_files() {
  static const std::vector<std::string> files = {"identity_ca.cert.pem",    "cert.pem",       "key.pem",
                                                 "permissions_ca.cert.pem", "governance.p7s", "permissions.p7s"};
  return files;
}

bool is_keystore(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / "public" / "permissions_ca.cert.pem", ec) &&
         fs::is_regular_file(dir / "public" / "identity_ca.cert.pem", ec) &&
         fs::is_regular_file(dir / "private" / "permissions_ca.key.pem", ec) &&
         fs::is_regular_file(dir / "private" / "identity_ca.key.pem", ec) &&
         fs::is_regular_file(dir / "enclaves" / "governance.p7s", ec);
}

void create_keystore(const fs::path& dir, std::uint32_t domain_id) {
  if (is_keystore(dir)) throw KeystoreError(dir.string() + ": a keystore exists there already");
  for (const char* sub : {"public", "enclaves"}) make_dir(dir / sub);
  const fs::path pub = dir / "public", priv = dir / "private";
  make_private_dir(priv);
  Own<EVP_PKEY> key = new_ec_key();
  Own<X509> ca = make_cert("sros2CA", key.get(), true, nullptr, key.get());
  write_secret(priv / "ca.key.pem", key_pem(key.get()));
  write_file(pub / "ca.cert.pem", cert_pem(ca.get()));
  for (const char* role : {"identity_ca", "permissions_ca"}) {
    symlink_to(pub / "ca.cert.pem", pub / (std::string(role) + ".cert.pem"));
    symlink_to(priv / "ca.key.pem", priv / (std::string(role) + ".key.pem"));
  }
  const std::string gov = governance_xml(domain_id);
  write_file(dir / "enclaves" / "governance.xml", gov);
  write_file(dir / "enclaves" / "governance.p7s", smime_sign(gov, ca.get(), key.get()));
}

fs::path create_enclave(const fs::path& dir, const std::string& name, const EnclavePolicy& policy) {
  if (const std::string why = enclave_name_error(name); !why.empty()) {
    throw KeystoreError("enclave '" + name + "': " + why);
  }
  if (name == "/") throw KeystoreError("enclave '/': its directory is the keystore's enclaves/ itself; choose a name");
  if (!is_keystore(dir)) {
    throw KeystoreError(dir.string() +
                        ": not a keystore (expected public/{identity,permissions}_ca.cert.pem, "
                        "private/{identity,permissions}_ca.key.pem and enclaves/governance.p7s)");
  }
  const fs::path pub = dir / "public", priv = dir / "private";
  const fs::path edir = enclave_dir(dir, name);
  make_private_dir(edir);
  symlink_to(pub / "identity_ca.cert.pem", edir / "identity_ca.cert.pem");
  symlink_to(pub / "permissions_ca.cert.pem", edir / "permissions_ca.cert.pem");
  symlink_to(dir / "enclaves" / "governance.p7s", edir / "governance.p7s");

  std::error_code ec;
  if (!fs::is_regular_file(edir / "cert.pem", ec) || !fs::is_regular_file(edir / "key.pem", ec)) {
    Own<X509> id_ca = load_cert(pub / "identity_ca.cert.pem");
    Own<EVP_PKEY> id_ca_key = load_key(priv / "identity_ca.key.pem");
    Own<EVP_PKEY> key = new_ec_key();
    Own<X509> cert = make_cert(name, key.get(), false, id_ca.get(), id_ca_key.get());
    fs::remove(edir / "key.pem", ec);  // a key without its certificate is replaced
    write_secret(edir / "key.pem", key_pem(key.get()));
    write_file(edir / "cert.pem", cert_pem(cert.get()));
  }
  Own<X509> cert = load_cert(edir / "cert.pem");
  const std::string perms = permissions_xml(name, policy, iso_time(X509_get0_notBefore(cert.get())),
                                            iso_time(X509_get0_notAfter(cert.get())));
  Own<X509> perm_ca = load_cert(pub / "permissions_ca.cert.pem");
  Own<EVP_PKEY> perm_ca_key = load_key(priv / "permissions_ca.key.pem");
  write_file(edir / "permissions.xml", perms);
  write_file(edir / "permissions.p7s", smime_sign(perms, perm_ca.get(), perm_ca_key.get()));
  return edir;
}

namespace {

// The text signed in an S/MIME document, verified against `ca`; throws naming `file` otherwise.
std::string verified_smime_content(const fs::path& file, X509* ca) {
  const std::string text = read_file(file);
  BIO* content_raw = nullptr;
  Own<PKCS7> p7(SMIME_read_PKCS7(mem_bio(text).get(), &content_raw));
  Own<BIO> content(content_raw);
  if (!p7) throw KeystoreError(file.string() + ": not an S/MIME (PKCS#7) signed document (" + openssl_error() + ")");
  Own<X509_STORE> store(X509_STORE_new());
  if (!store || !X509_STORE_add_cert(store.get(), ca)) fail("X509_STORE");
  Own<BIO> out(BIO_new(BIO_s_mem()));
  if (PKCS7_verify(p7.get(), nullptr, store.get(), content.get(), out.get(), PKCS7_TEXT) != 1) {
    throw KeystoreError(file.string() + ": signature does not verify against permissions_ca.cert.pem (" +
                        openssl_error() + ")");
  }
  return bio_text(out.get());
}

// Where a link chain ends, keeping the caller's spelling of the path (no canonicalisation).
fs::path resolve_links(fs::path p) {
  std::error_code ec;
  for (int hops = 0; hops < 40 && fs::is_symlink(p, ec); ++hops) {
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) break;
    p = (target.is_absolute() ? target : p.parent_path() / target).lexically_normal();
  }
  return p;
}

// The XML a signed document `p7s` was made from lies beside it (sros2 and `create-*` keep both; for
// an enclave's governance.p7s, a link, beside the file it links to). Cyclone enforces the signed
// text, so an XML that says something else misleads whoever reads it: a problem when it differs.
void check_xml_beside(const fs::path& p7s, std::string signed_text) {
  const fs::path xml = resolve_links(p7s).replace_extension(".xml");
  std::error_code ec;
  if (!fs::is_regular_file(xml, ec)) return;  // rmw does not read it; sros2 writes it
  std::string text = read_file(xml);
  // S/MIME text mode signs CRLF line ends; the file may have either.
  std::erase(signed_text, '\r');
  std::erase(text, '\r');
  if (text != signed_text) {
    throw KeystoreError(xml.string() + ": differs from what " + p7s.filename().string() +
                        " signs (nodes enforce the signed text: sign this XML again, or restore it)");
  }
}

std::string common_name(X509* c) {
  char buf[512];
  const int n = X509_NAME_get_text_by_NID(X509_get_subject_name(c), NID_commonName, buf, sizeof buf);
  return n < 0 ? std::string() : std::string(buf, static_cast<std::size_t>(n));
}

}  // namespace

std::vector<std::string> check_enclave(const fs::path& dir) {
  std::vector<std::string> problems;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return {dir.string() + ": no such directory"};
  for (const auto& f : enclave_files()) {
    if (!fs::is_regular_file(dir / f, ec)) problems.push_back((dir / f).string() + ": missing");
  }
  if (!problems.empty()) return problems;
  auto attempt = [&](auto&& check) {
    try {
      check();
    } catch (const KeystoreError& e) {
      problems.emplace_back(e.what());
    }
  };
  Own<X509> id_ca, perm_ca, cert;
  attempt([&] { id_ca = load_cert(dir / "identity_ca.cert.pem"); });
  attempt([&] { perm_ca = load_cert(dir / "permissions_ca.cert.pem"); });
  attempt([&] { cert = load_cert(dir / "cert.pem"); });
  attempt([&] {
    Own<EVP_PKEY> key = load_key(dir / "key.pem");
    if (cert && X509_check_private_key(cert.get(), key.get()) != 1) {
      ERR_clear_error();
      throw KeystoreError((dir / "key.pem").string() + ": does not belong to cert.pem");
    }
  });
  if (cert && id_ca) {
    Own<X509_STORE> store(X509_STORE_new());
    Own<X509_STORE_CTX> ctx(X509_STORE_CTX_new());
    if (store && ctx && X509_STORE_add_cert(store.get(), id_ca.get()) &&
        X509_STORE_CTX_init(ctx.get(), store.get(), cert.get(), nullptr)) {
      if (X509_verify_cert(ctx.get()) != 1) {
        problems.push_back((dir / "cert.pem").string() + ": does not verify against identity_ca.cert.pem (" +
                           X509_verify_cert_error_string(X509_STORE_CTX_get_error(ctx.get())) + ")");
      }
    }
  }
  if (perm_ca) {
    attempt([&] {
      check_xml_beside(dir / "governance.p7s", verified_smime_content(dir / "governance.p7s", perm_ca.get()));
    });
    attempt([&] {
      const std::string perms = verified_smime_content(dir / "permissions.p7s", perm_ca.get());
      check_xml_beside(dir / "permissions.p7s", perms);
      const std::string cn = cert ? common_name(cert.get()) : std::string();
      if (!cn.empty() && perms.find("CN=" + cn) == std::string::npos) {
        throw KeystoreError((dir / "permissions.p7s").string() + ": no grant for the identity's subject CN=" + cn);
      }
    });
  }
  ERR_clear_error();
  return problems;
}

std::vector<std::string> key_mode_problems(const fs::path& keystore, const fs::path& enclave) {
  std::vector<std::string> problems;
  std::set<std::string> seen;
  // `p`, when it exists, must give group and others none of the access bits in `loose`.
  auto check = [&](const fs::path& p, mode_t loose, bool folder) {
    struct stat st {};
    if (::stat(p.c_str(), &st) != 0) return;  // absent: check_enclave names a missing enclave file
    const fs::path real = resolve_links(p);
    if (!seen.insert(real.string()).second) return;
    const unsigned mode = st.st_mode & 07777;
    if ((mode & loose) == 0) return;
    char octal[8];
    std::snprintf(octal, sizeof octal, "%04o", mode);
    problems.push_back(real.string() + ": mode " + octal + " lets group or others " +
                       (folder ? "into a folder of private keys" : "at a private key") + " (want " +
                       (folder ? "0700: chmod 700 " : "0600: chmod 600 ") + real.string() + ")");
  };
  const mode_t kFolderLoose = S_IRGRP | S_IWGRP | S_IROTH | S_IWOTH;  // listing or changing it
  const mode_t kKeyLoose = S_IRWXG | S_IRWXO;
  check(enclave, kFolderLoose, true);
  check(enclave / "key.pem", kKeyLoose, false);
  check(keystore / "private", kFolderLoose, true);
  for (const char* key : {"ca.key.pem", "identity_ca.key.pem", "permissions_ca.key.pem"}) {
    check(keystore / "private" / key, kKeyLoose, false);
  }
  return problems;
}

}  // namespace quadcosim::security
