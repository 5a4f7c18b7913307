// Writing a zip archive (minizip): what `quadcosim fmu export` packs an FMU with. Entries are
// deflated and stamped with a fixed date (1980-01-01), so the same contents give the same bytes;
// the parent folders of every entry are written as folder entries first, as FMU tools expect.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace quadcosim::fmi {

/// A zip that cannot be written: what() names the archive, and the entry or file when one is at fault.
class ZipError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One file of the archive: its path inside ("resources/quadcosim.json"; relative, "/"-separated,
/// no "." or ".." parts) and its content, given as bytes or read from a file.
struct ZipEntry {
  std::string name;
  std::string bytes;           ///< the content, when `file` is empty
  std::filesystem::path file;  ///< read the content from this file instead
  bool executable = false;     ///< Unix mode 0755 instead of 0644 (a shared library)

  static ZipEntry from_bytes(std::string name, std::string bytes) { return {std::move(name), std::move(bytes), {}}; }
  static ZipEntry from_file(std::string name, std::filesystem::path file, bool executable = false) {
    return {std::move(name), {}, std::move(file), executable};
  }
};

/// Writes `entries` into the zip `archive`, replacing it. The archive is written beside itself under a
/// temporary name and renamed at the end, so a failure leaves no partial archive (and an existing one
/// untouched). Throws ZipError: a bad or repeated entry name, an unreadable file, an unwritable archive.
void write_zip(const std::filesystem::path& archive, const std::vector<ZipEntry>& entries);

}  // namespace quadcosim::fmi
