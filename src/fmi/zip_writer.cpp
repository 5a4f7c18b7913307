#include "fmi/zip_writer.hpp"

#include <minizip/zip.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string_view>

namespace quadcosim::fmi {

namespace {

/// "" when `name` is a valid entry name, else why not.
std::string check_name(const std::string& name) {
  if (name.empty()) return "an empty name";
  if (name.front() == '/') return "an absolute path";
  if (name.back() == '/') return "a folder name (folders are made from the files' paths)";
  if (name.find('\\') != std::string::npos) return "a backslash (zip paths use '/')";
  if (name.find('\0') != std::string::npos) return "a NUL character";
  std::string_view rest = name;
  while (!rest.empty()) {
    const std::size_t slash = rest.find('/');
    const std::string_view part = rest.substr(0, slash);
    if (part.empty() || part == "." || part == "..") return "an empty, '.' or '..' part";
    rest = slash == std::string_view::npos ? std::string_view{} : rest.substr(slash + 1);
  }
  return {};
}

std::string read_file(const std::filesystem::path& file, const std::string& archive, const std::string& name) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ZipError(archive + ": cannot read " + file.string() + " (for " + name + ")");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw ZipError(archive + ": error reading " + file.string() + " (for " + name + ")");
  return std::move(bytes).str();
}

/// An open archive, closed (and, unless committed, removed) on destruction.
class Archive {
 public:
  Archive(std::filesystem::path temp, std::string archive) : temp_(std::move(temp)), archive_(std::move(archive)) {
    errno = 0;
    zip_ = zipOpen64(temp_.c_str(), APPEND_STATUS_CREATE);
    if (zip_ == nullptr)
      throw ZipError(archive_ + ": cannot create " + temp_.string() +
                     (errno != 0 ? ": " + std::string(std::strerror(errno)) : ""));
  }
  ~Archive() {
    if (zip_ != nullptr) zipClose(zip_, nullptr);
    if (!committed_) {
      std::error_code ignored;
      std::filesystem::remove(temp_, ignored);
    }
  }
  Archive(const Archive&) = delete;
  Archive& operator=(const Archive&) = delete;

  void add(const std::string& name, std::string_view bytes, unsigned mode) {
    zip_fileinfo info{};
    info.tmz_date.tm_year = 1980;  // the earliest date a zip can hold: the same bytes for the same content
    info.tmz_date.tm_mday = 1;
    info.external_fa = static_cast<uLong>(mode) << 16;  // Unix mode, read as such with version made by 3
    const bool folder = !name.empty() && name.back() == '/';
    if (folder) info.external_fa |= 0x10;  // MS-DOS directory bit
    constexpr uLong kMadeByUnix = (3u << 8) | 20u;
    int rc = zipOpenNewFileInZip4_64(zip_, name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr,
                                     folder ? 0 : Z_DEFLATED, folder ? 0 : Z_BEST_COMPRESSION, 0, -MAX_WBITS,
                                     DEF_MEM_LEVEL, Z_DEFAULT_STRATEGY, nullptr, 0, kMadeByUnix, 0, 0);
    if (rc == ZIP_OK && !bytes.empty())
      rc = zipWriteInFileInZip(zip_, bytes.data(), static_cast<unsigned>(bytes.size()));
    if (rc == ZIP_OK) rc = zipCloseFileInZip(zip_);
    if (rc != ZIP_OK)
      throw ZipError(archive_ + ": cannot write entry " + name + " (minizip error " + std::to_string(rc) + ")");
  }

  void commit(const std::filesystem::path& archive) {
    const int rc = zipClose(zip_, nullptr);
    zip_ = nullptr;
    if (rc != ZIP_OK)
      throw ZipError(archive_ + ": cannot finish the archive (minizip error " + std::to_string(rc) + ")");
    std::error_code ec;
    std::filesystem::rename(temp_, archive, ec);
    if (ec) throw ZipError(archive_ + ": cannot move it into place: " + ec.message());
    committed_ = true;
  }

 private:
  std::filesystem::path temp_;
  std::string archive_;
  zipFile zip_ = nullptr;
  bool committed_ = false;
};

}  // namespace

void write_zip(const std::filesystem::path& archive, const std::vector<ZipEntry>& entries) {
  const std::string where = archive.string();
  std::set<std::string> names, folders;
  std::vector<std::string> folder_order;
  for (const ZipEntry& e : entries) {
    if (const std::string why = check_name(e.name); !why.empty())
      throw ZipError(where + ": entry '" + e.name + "' has " + why);
    if (!names.insert(e.name).second) throw ZipError(where + ": entry '" + e.name + "' is given twice");
    for (std::size_t slash = e.name.find('/'); slash != std::string::npos; slash = e.name.find('/', slash + 1)) {
      const std::string folder = e.name.substr(0, slash + 1);
      if (folders.insert(folder).second) folder_order.push_back(folder);
    }
  }
  for (const std::string& folder : folder_order) {
    if (names.contains(folder.substr(0, folder.size() - 1)))
      throw ZipError(where + ": entry '" + folder.substr(0, folder.size() - 1) + "' is both a file and a folder");
  }

  std::filesystem::path temp = archive;
  temp += ".partial-" + std::to_string(::getpid());
  Archive zip(temp, where);
  for (const std::string& folder : folder_order) zip.add(folder, {}, 040755);
  for (const ZipEntry& e : entries) {
    const std::string bytes = e.file.empty() ? std::string{} : read_file(e.file, where, e.name);
    zip.add(e.name, e.file.empty() ? std::string_view(e.bytes) : std::string_view(bytes),
            e.executable ? 0100755 : 0100644);
  }
  zip.commit(archive);
}

}  // namespace quadcosim::fmi
