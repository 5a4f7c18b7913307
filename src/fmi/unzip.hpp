// Unpacking an .fmu (a zip archive, minizip) into a private temporary directory that removes itself.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace quadcosim::fmi {

/// What an FMU may hold before quadcosim refuses it (docs/scenarios.md, "Limits"). An FMU is a few
/// files and a few hundred variables; these bounds stop an archive that unpacks to gigabytes (a zip
/// bomb) or a description of a million variables before they cost the memory or the disk.
struct FmuLimits {
  std::uint64_t entries = 10'000;             ///< entries in the archive (fmu_entries)
  std::uint64_t unpacked_bytes = 1ULL << 30;  ///< bytes unpacked, all entries together (fmu_unpacked_bytes)
  std::uint64_t variables = 100'000;          ///< variables in modelDescription.xml (fmu_variables)
  bool enabled = true;                        ///< false: --no-limits
};

/// The limits in force in this process (the defaults unless the command line changed them).
const FmuLimits& fmu_limits();
/// Sets the limits for this process: once, by the command line, before any FMU is loaded.
void set_fmu_limits(const FmuLimits& limits);
/// How to raise limit `name`, for refusals: "raise it with --limit NAME=N, or --no-limits".
std::string limit_hint(const std::string& name);

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
/// Refuses an archive of more than fmu_limits().entries entries, or whose entries declare more than
/// fmu_limits().unpacked_bytes, before unpacking anything; and stops, refusing it, when the bytes
/// actually unpacked pass that bound (a declared size may lie).
void unzip(const std::string& archive, const std::string& dir);

/// `archive` unpacked into a new TempDir.
std::unique_ptr<TempDir> unpack(const std::string& archive);

}  // namespace quadcosim::fmi
