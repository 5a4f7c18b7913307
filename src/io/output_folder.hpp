// The folders quadcosim commands write (run, plot, compare, sweep, margins): each gets a manifest,
// .quadcosim-outputs.json, naming the command that wrote it and, by group, exactly the files it
// wrote, so that a later command never mixes its outputs with an earlier one's (docs/outputs.md,
// "Output folders").
//
// The rules, the same for every command:
//   - A folder that is new or empty is used as it is (created when missing).
//   - A folder that holds anything else (a previous command's outputs, or files quadcosim did not
//     write) is refused: OutputFolderRefused, naming the folder and what it holds.
//   - With `force`, exactly the files the previous manifest lists are removed (and the sub-folders
//     they leave empty); every other file is kept (the caller is told which), and is never listed
//     in the new manifest unless the command rewrites it.
// Sub-folders with a manifest of their own (a `compare` folder inside a run) are other outputs:
// listed in the refusal, kept by `force`.
//
// Links and writes: a symbolic link (or any entry that is not a regular file or a folder) inside the
// folder is refused, with or without `force`: quadcosim neither writes through it nor removes it.
// `force` removes only regular files (checked with lstat). The manifest, and the files written with
// write_file_atomically(), go to a new temporary file in the same folder (O_EXCL | O_NOFOLLOW),
// fsync'd, then renamed over the old one: never a part of a file, never 0 bytes, never through a link
// planted at the path; files written as they grow are opened with open_output_file() (O_NOFOLLOW).
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <ostream>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace quadcosim::io {

/// The manifest's file name in an output folder.
inline constexpr const char* kOutputManifest = ".quadcosim-outputs.json";

/// The folder cannot be used as asked (bad input, exit 2): what() names the folder and says what it
/// holds and what to do.
class OutputFolderRefused : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A folder's manifest: the command that wrote it and, per group ("outputs", "figures", ...), the
/// files it wrote, as paths relative to the folder ('/'-separated, sorted).
struct OutputManifest {
  std::string command;
  std::map<std::string, std::set<std::string>> groups;
  /// Every file of every group.
  std::set<std::string> files() const;
};

/// Reads `dir`/.quadcosim-outputs.json: false when there is none; throws OutputFolderRefused naming
/// the file when it is not a manifest (empty, cut short, not JSON, a link), saying what to do.
bool read_output_manifest(const std::filesystem::path& dir, OutputManifest& manifest);

/// Writes `content` to `path` atomically: into a new temporary file beside it (created with O_EXCL |
/// O_NOFOLLOW), fsync'd, renamed over `path`, and the folder fsync'd. Readers see the old file or the
/// new one, never a part; a symbolic link at `path` is replaced by the file, never written through.
/// Throws std::runtime_error "PATH: write failed (why)" (e.g. "No space left on device"), having
/// removed the temporary file and left `path` as it was.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

/// Opens `path` for writing ("wb": created, or truncated) without following a symbolic link there
/// (O_NOFOLLOW): a link at `path` is a std::runtime_error naming it. For files written as they grow
/// (trajectory.csv, run.mcap). The caller fcloses the stream.
std::FILE* open_output_file(const std::filesystem::path& path);

/// An output folder claimed by one command. Files the command writes are recorded with record(group)
/// (every file new, or rewritten, since the previous record or the claim); the destructor records
/// what is left under the default group, so an interrupted or failed command still leaves a manifest
/// that lists all it wrote. The manifest is rewritten by every record.
class OutputFolder {
 public:
  struct Options {
    bool force = false;  ///< replace a previous command's outputs (its listed files only)
    /// Replace the outputs of a previous run of the same command without `force` (outputs derived
    /// from other folders, e.g. `compare`'s, cheap to make again).
    bool replace_own = false;
    std::string default_group = "outputs";
    /// Sub-folders (relative, e.g. "runs") the command fills alone: with `force`, a file in them
    /// that the manifest does not list is refused instead of kept (it would sit beside the new
    /// outputs as if it were one of them: a run of another sweep).
    std::vector<std::string> exclusive = {};
  };

  /// Claims `dir` for `command` (e.g. "run", "sweep merge") under the rules above. Creates `dir` when
  /// missing (std::runtime_error "cannot create output directory DIR: why" when that fails). Notes
  /// about files kept with force go to `notes` (one line each).
  static OutputFolder claim(const std::filesystem::path& dir, const std::string& command, const Options& options,
                            std::ostream& notes);

  /// Takes `dir` back for `command` to continue what it wrote (`sweep --resume`): its manifest must
  /// be `command`'s (else OutputFolderRefused saying what the folder holds); the files it lists are
  /// kept and stay listed, files written from now on are added. Links are refused as by claim().
  static OutputFolder resume(const std::filesystem::path& dir, const std::string& command);

  /// Reopens the output folder of `dir` to write `group` of it again (`plot` regenerating a run's
  /// figures): the files of that group under `dir` that its manifest lists are removed, the others
  /// kept. The manifest is `dir`'s, or that of the nearest enclosing folder whose manifest lists files
  /// under `dir` (a swarm's recorded vehicle); with none, a new manifest in `dir` for `command`.
  static OutputFolder reopen(const std::filesystem::path& dir, const std::string& command, const std::string& group);

  OutputFolder(OutputFolder&& other) noexcept;
  OutputFolder& operator=(OutputFolder&&) = delete;
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  ~OutputFolder();

  /// Files new or rewritten since the previous record() (or the claim) that no group lists yet are
  /// listed under `group`; writes the manifest. Throws std::runtime_error when it cannot.
  void record(const std::string& group);

  /// The folder the manifest is in.
  const std::filesystem::path& root() const { return root_; }
  const OutputManifest& manifest() const { return manifest_; }

 private:
  struct Stamp {
    std::uintmax_t size = 0;
    std::filesystem::file_time_type mtime;
    bool regular = true;  ///< false: a symbolic link, a fifo, a socket, ... (never written or removed)
    bool operator==(const Stamp&) const = default;
  };
  using Snapshot = std::map<std::string, Stamp>;

  OutputFolder(std::filesystem::path root, OutputManifest manifest, std::string default_group);
  static Snapshot snapshot(const std::filesystem::path& root);
  /// Throws OutputFolderRefused naming the entries of `now` that are not regular files.
  static void refuse_links(const std::filesystem::path& dir, const Snapshot& now);
  void write_manifest() const;

  std::filesystem::path root_;
  OutputManifest manifest_;
  std::string default_group_;
  Snapshot seen_;  ///< files and their stamps at the claim or the last record
  bool active_ = true;
};

}  // namespace quadcosim::io
