// Unpacking an .fmu (a zip archive, minizip) into a private temporary directory that removes itself.
#pragma once

#include <memory>
#include <string>

namespace quadcosim::fmi {

/// A fresh directory only its owner can enter (mode 0700, mkdtemp under $TMPDIR or /tmp), removed
/// with all it holds when this is destroyed.
class TempDir {
 public:
  /// `prefix` begins the directory's name ("quadcosim-fmu-" + six random characters). Throws FmuError.
  explicit TempDir(const std::string& prefix = "quadcosim-fmu-");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// Extracts every entry of the zip archive `archive` below the existing directory `dir`. Refuses
/// (FmuError naming the archive and the entry) an entry with an absolute path or a `..` component
/// (zip slip), an encrypted entry, and any read, CRC or write error. Backslashes count as separators.
void unzip(const std::string& archive, const std::string& dir);

/// `archive` unpacked into a new TempDir.
std::unique_ptr<TempDir> unpack(const std::string& archive);

}  // namespace quadcosim::fmi
