// Zip extraction with minizip (Debian libminizip-dev). Files are written only below the target
// directory: entry names are checked component by component before anything is created, and only
// directories and regular files are made (never links), so no entry can reach outside.
#include "fmi/unzip.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>
#include <unzip.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "fmi/model_description.hpp"

namespace quadcosim::fmi {

TempDir::TempDir(const std::string& prefix) {
  const char* tmp = std::getenv("TMPDIR");
  std::string base = tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
  if (base.size() > 1 && base.back() == '/') base.pop_back();
  std::string templ = base + "/" + prefix + "XXXXXX";
  if (mkdtemp(templ.data()) == nullptr) {
    throw FmuError(fmt::format("cannot make a temporary directory {}: {}", templ, std::strerror(errno)));
  }
  path_ = templ;
}

TempDir::~TempDir() {
  std::error_code ignored;  // nothing sensible to do about a directory that will not go
  std::filesystem::remove_all(path_, ignored);
}

namespace {

struct ZipCloser {
  void operator()(void* z) const { unzClose(z); }
};

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

/// The entry's path components, or an empty list with `why` set when it must be refused.
std::vector<std::string> components(std::string name, std::string& why) {
  for (char& c : name) {
    if (c == '\\') c = '/';
  }
  if (name.find('\0') != std::string::npos) {
    why = "has a NUL character in its name";
    return {};
  }
  if (name.starts_with("/") || (name.size() >= 2 && name[1] == ':')) {
    why = "has an absolute path";
    return {};
  }
  std::vector<std::string> parts;
  std::size_t begin = 0;
  while (begin <= name.size()) {
    std::size_t end = name.find('/', begin);
    if (end == std::string::npos) end = name.size();
    std::string part = name.substr(begin, end - begin);
    if (part == "..") {
      why = "has a '..' component (it would be written outside the directory)";
      return {};
    }
    if (!part.empty() && part != ".") parts.push_back(std::move(part));
    begin = end + 1;
  }
  if (parts.empty()) why = "has an empty name";
  return parts;
}

void make_directory(const std::string& path, const std::string& archive, const std::string& entry) {
  if (::mkdir(path.c_str(), 0755) != 0 && errno != EEXIST) {
    throw FmuError(
        fmt::format("{}: entry '{}': cannot make directory {}: {}", archive, entry, path, std::strerror(errno)));
  }
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    throw FmuError(fmt::format("{}: entry '{}': {} is a file and a directory in this archive", archive, entry, path));
  }
}

FmuLimits& limits_in_force() {
  static FmuLimits limits;  // set once by the command line before any FMU is read
  return limits;
}

}  // namespace

const FmuLimits& fmu_limits() { return limits_in_force(); }
void set_fmu_limits(const FmuLimits& limits) { limits_in_force() = limits; }
std::string limit_hint(const std::string& name) {
  return fmt::format("limit {}; raise it with --limit {}=N, or --no-limits", name, name);
}

void unzip(const std::string& archive, const std::string& dir) {
  std::unique_ptr<void, ZipCloser> zip(unzOpen64(archive.c_str()));
  if (!zip) throw FmuError(fmt::format("{}: cannot open as a zip archive (missing, unreadable or not a zip)", archive));
  const FmuLimits& limits = fmu_limits();
  if (limits.enabled) {  // from the central directory, before anything is unpacked
    unz_global_info64 global{};
    if (unzGetGlobalInfo64(zip.get(), &global) != UNZ_OK) {
      throw FmuError(fmt::format("{}: cannot read the zip directory", archive));
    }
    if (global.number_entry > limits.entries) {
      throw FmuError(fmt::format("{}: the archive has {} entries, more than the {} an FMU may have ({})", archive,
                                 global.number_entry, limits.entries, limit_hint("fmu_entries")));
    }
    std::uint64_t declared = 0;
    for (int r = unzGoToFirstFile(zip.get()); r == UNZ_OK; r = unzGoToNextFile(zip.get())) {
      unz_file_info64 info{};
      if (unzGetCurrentFileInfo64(zip.get(), &info, nullptr, 0, nullptr, 0, nullptr, 0) != UNZ_OK) break;
      declared += info.uncompressed_size;
      if (declared > limits.unpacked_bytes) {
        throw FmuError(fmt::format("{}: the archive's entries unpack to more than {} bytes, the most an FMU may ({})",
                                   archive, limits.unpacked_bytes, limit_hint("fmu_unpacked_bytes")));
      }
    }
  }
  int rc = unzGoToFirstFile(zip.get());
  if (rc == UNZ_END_OF_LIST_OF_FILE) throw FmuError(fmt::format("{}: the zip archive is empty", archive));
  std::vector<char> buffer(1 << 16);
  std::uint64_t unpacked = 0;
  for (; rc == UNZ_OK; rc = unzGoToNextFile(zip.get())) {
    unz_file_info64 info{};
    if (unzGetCurrentFileInfo64(zip.get(), &info, nullptr, 0, nullptr, 0, nullptr, 0) != UNZ_OK) {
      throw FmuError(fmt::format("{}: cannot read the zip directory", archive));
    }
    std::string entry(info.size_filename, '\0');
    if (unzGetCurrentFileInfo64(zip.get(), &info, entry.data(), entry.size(), nullptr, 0, nullptr, 0) != UNZ_OK) {
      throw FmuError(fmt::format("{}: cannot read the zip directory", archive));
    }
    std::string why;
    const std::vector<std::string> parts = components(entry, why);
    if (!why.empty()) throw FmuError(fmt::format("{}: refused entry '{}': it {}", archive, entry, why));
    if ((info.flag & 1U) != 0) throw FmuError(fmt::format("{}: refused entry '{}': it is encrypted", archive, entry));
    const bool is_directory = entry.back() == '/' || entry.back() == '\\';

    std::string path = dir;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      path += "/" + parts[i];
      make_directory(path, archive, entry);
    }
    path += "/" + parts.back();
    if (is_directory) {
      make_directory(path, archive, entry);
      continue;
    }
    if (unzOpenCurrentFile(zip.get()) != UNZ_OK) {
      throw FmuError(fmt::format("{}: entry '{}': cannot read it (unsupported compression?)", archive, entry));
    }
    Fd out{::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644)};
    if (out.fd < 0) {
      const int err = errno;
      unzCloseCurrentFile(zip.get());
      throw FmuError(fmt::format("{}: entry '{}': cannot create {}: {}", archive, entry, path,
                                 err == EEXIST ? "it appears twice in the archive" : std::strerror(err)));
    }
    for (;;) {
      const int n = unzReadCurrentFile(zip.get(), buffer.data(), static_cast<unsigned>(buffer.size()));
      if (n < 0) {
        unzCloseCurrentFile(zip.get());
        throw FmuError(fmt::format("{}: entry '{}': corrupt data (minizip error {})", archive, entry, n));
      }
      if (n == 0) break;
      unpacked += static_cast<std::uint64_t>(n);
      if (limits.enabled && unpacked > limits.unpacked_bytes) {  // a declared size may lie
        unzCloseCurrentFile(zip.get());
        throw FmuError(
            fmt::format("{}: entry '{}': the archive unpacks to more than {} bytes, the most an FMU may ({})", archive,
                        entry, limits.unpacked_bytes, limit_hint("fmu_unpacked_bytes")));
      }
      for (int written = 0; written < n;) {
        const ssize_t w = ::write(out.fd, buffer.data() + written, static_cast<std::size_t>(n - written));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
          const int err = errno;
          unzCloseCurrentFile(zip.get());
          throw FmuError(fmt::format("{}: entry '{}': cannot write {}: {}", archive, entry, path, std::strerror(err)));
        }
        written += static_cast<int>(w);
      }
    }
    if (unzCloseCurrentFile(zip.get()) != UNZ_OK) {
      throw FmuError(fmt::format("{}: entry '{}': CRC mismatch (the archive is corrupt)", archive, entry));
    }
  }
  if (rc != UNZ_END_OF_LIST_OF_FILE) throw FmuError(fmt::format("{}: corrupt zip directory", archive));
}

std::unique_ptr<TempDir> unpack(const std::string& archive) {
  auto dir = std::make_unique<TempDir>();
  unzip(archive, dir->path());
  return dir;
}

}  // namespace quadcosim::fmi
