#include "io/output_folder.hpp"

#include <fmt/format.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace quadcosim::io {

namespace fs = std::filesystem;

namespace {

// "a, b, c" for at most `shown` names, then ", ... (N in all)".
std::string some_names(const std::vector<std::string>& names, std::size_t shown = 4) {
  std::string text;
  for (std::size_t i = 0; i < names.size() && i < shown; ++i) text += (i == 0 ? "" : ", ") + names[i];
  if (names.size() > shown) text += fmt::format(", ... ({} in all)", names.size());
  return text;
}

std::string files_word(std::size_t n) { return n == 1 ? "1 file" : fmt::format("{} files", n); }

// A manifest entry may only name a file inside its folder: relative, no "..", no empty or "." part.
bool inside_path(const std::string& rel) {
  if (rel.empty() || rel.front() == '/') return false;
  for (const auto& part : fs::path(rel)) {
    const std::string p = part.string();
    if (p.empty() || p == "." || p == "..") return false;
  }
  return true;
}

// Removes the sub-folders of `root` on the way to `file` that are empty now, deepest first.
void prune_empty_parents(const fs::path& root, const std::string& file) {
  std::error_code ec;
  for (fs::path d = fs::path(file).parent_path(); !d.empty(); d = d.parent_path()) {
    if (!fs::is_empty(root / d, ec) || ec) return;
    fs::remove(root / d, ec);
  }
}

bool has_manifest(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / kOutputManifest, ec);
}

// The sub-folders of `root` (relative) holding a manifest of their own.
std::vector<std::string> nested_outputs(const fs::path& root) {
  std::vector<std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (it->is_directory(ec) && !it->is_symlink(ec) && has_manifest(it->path())) {
      out.push_back(it->path().lexically_relative(root).generic_string() + "/");
      it.disable_recursion_pending();
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

std::set<std::string> OutputManifest::files() const {
  std::set<std::string> all;
  for (const auto& [group, files] : groups) all.insert(files.begin(), files.end());
  return all;
}

bool read_output_manifest(const fs::path& dir, OutputManifest& manifest) {
  const fs::path file = dir / kOutputManifest;
  struct stat st {};
  if (::lstat(file.c_str(), &st) != 0) {
    if (errno == ENOENT) return false;
    throw OutputFolderRefused(fmt::format("{}: cannot read ({})", file.string(), std::strerror(errno)));
  }
  if (!S_ISREG(st.st_mode)) {
    throw OutputFolderRefused(
        fmt::format("{}: not a regular file (a symbolic link or other): quadcosim reads no manifest through a link; "
                    "remove it by hand, or choose another folder",
                    file.string()));
  }
  // An older quadcosim could leave the manifest empty or cut short (interrupted, or out of disk
  // space): which files it wrote is then unknown, so nothing may be removed on its word.
  const std::string unknown =
      "which files it lists is unknown: remove that command's outputs and the manifest by hand, or choose "
      "another folder (removing only the manifest makes --force keep every file as one quadcosim did not write)";
  if (st.st_size == 0) {
    throw OutputFolderRefused(fmt::format(
        "{}: the manifest is empty (0 bytes), left by an older quadcosim that was interrupted or ran out of "
        "disk space while writing it; {}",
        file.string(), unknown));
  }
  const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) throw OutputFolderRefused(fmt::format("{}: cannot read ({})", file.string(), std::strerror(errno)));
  std::string text;
  char buf[65536];
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      throw OutputFolderRefused(fmt::format("{}: cannot read ({})", file.string(), std::strerror(err)));
    }
    text.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    OutputManifest m;
    m.command = j.at("command").get<std::string>();
    for (const auto& [group, files] : j.at("files").items()) {
      for (const auto& f : files) {
        const std::string rel = f.get<std::string>();
        if (!inside_path(rel)) throw std::invalid_argument("'" + rel + "' is not a file inside the folder");
        m.groups[group].insert(rel);
      }
    }
    manifest = std::move(m);
    return true;
  } catch (const nlohmann::json::parse_error& e) {
    throw OutputFolderRefused(
        fmt::format("{}: the manifest is not JSON (cut short? {}); {}", file.string(), e.what(), unknown));
  } catch (const std::exception& e) {
    throw OutputFolderRefused(
        fmt::format("{}: not a quadcosim output manifest ({}); remove it by hand, or choose "
                    "another folder",
                    file.string(), e.what()));
  }
}

namespace {

std::runtime_error write_error(const fs::path& path, int err) {
  return std::runtime_error(fmt::format("{}: write failed ({})", path.string(), std::strerror(err)));
}

// Writes all of `data` to `fd`; false with errno set when it cannot.
bool write_all(int fd, std::string_view data) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      return false;
    }
    data.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

}  // namespace

void write_file_atomically(const fs::path& path, std::string_view content) {
  // A name no other writer uses (process and counter), created exclusively: a file or link planted
  // there makes the open fail instead of being written through.
  static std::atomic<unsigned> counter{0};
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const fs::path tmp = dir / fmt::format(".{}.tmp-{}-{}", path.filename().string(), ::getpid(), counter.fetch_add(1));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) throw write_error(path, errno);
  const auto fail = [&](int err) {
    ::close(fd);
    ::unlink(tmp.c_str());
    return write_error(path, err);
  };
  if (!write_all(fd, content)) throw fail(errno);
  if (::fsync(fd) != 0) throw fail(errno);
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw write_error(path, err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {  // replaces a link at `path`, never its target
    const int err = errno;
    ::unlink(tmp.c_str());
    throw write_error(path, err);
  }
  // The rename itself on disk: fsync the folder (best effort: some file systems refuse it).
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

std::FILE* open_output_file(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) {
    if (errno == ELOOP) {
      throw std::runtime_error(path.string() +
                               ": is a symbolic link; quadcosim does not write through links (remove it)");
    }
    throw std::runtime_error(fmt::format("{}: cannot open for writing ({})", path.string(), std::strerror(errno)));
  }
  std::FILE* f = ::fdopen(fd, "wb");
  if (!f) {
    const int err = errno;
    ::close(fd);
    throw std::runtime_error(fmt::format("{}: cannot open for writing ({})", path.string(), std::strerror(err)));
  }
  return f;
}

OutputFolder::OutputFolder(fs::path root, OutputManifest manifest, std::string default_group)
    : root_(std::move(root)), manifest_(std::move(manifest)), default_group_(std::move(default_group)) {}

OutputFolder::OutputFolder(OutputFolder&& o) noexcept
    : root_(std::move(o.root_)),
      manifest_(std::move(o.manifest_)),
      default_group_(std::move(o.default_group_)),
      seen_(std::move(o.seen_)),
      active_(o.active_) {
  o.active_ = false;
}

OutputFolder::~OutputFolder() {
  if (!active_) return;
  try {
    record(default_group_);
  } catch (const std::exception&) {
    // Nothing to do about it here: the command has already reported why its outputs failed.
  }
}

OutputFolder::Snapshot OutputFolder::snapshot(const fs::path& root) {
  Snapshot s;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    const fs::path& p = it->path();
    // A file that goes while the folder is read (a temporary file renamed by a writer of a running
    // command) is simply not in the snapshot.
    std::error_code entry_ec;
    const auto st = it->symlink_status(entry_ec);
    if (entry_ec) continue;
    if (fs::is_directory(st)) {
      if (has_manifest(p)) it.disable_recursion_pending();  // another command's outputs
      continue;
    }
    const std::string rel = p.lexically_relative(root).generic_string();
    if (rel == kOutputManifest) continue;
    Stamp stamp;
    stamp.regular = fs::is_regular_file(st);
    if (stamp.regular) {
      stamp.size = fs::file_size(p, entry_ec);
      if (!entry_ec) stamp.mtime = fs::last_write_time(p, entry_ec);
      if (entry_ec) continue;
    }
    s[rel] = stamp;
  }
  if (ec) throw std::runtime_error("cannot read " + root.string() + ": " + ec.message());
  return s;
}

void OutputFolder::refuse_links(const fs::path& dir, const Snapshot& now) {
  std::vector<std::string> links;
  for (const auto& [rel, stamp] : now) {
    if (!stamp.regular) links.push_back(rel);
  }
  if (links.empty()) return;
  throw OutputFolderRefused(fmt::format(
      "{} holds {} that {} not a regular file ({}: symbolic links or other special files); quadcosim neither "
      "writes through nor removes them, with or without --force: remove them by hand, or choose another folder",
      dir.string(), links.size() == 1 ? "an entry" : fmt::format("{} entries", links.size()),
      links.size() == 1 ? "is" : "are", some_names(links)));
}

OutputFolder OutputFolder::claim(const fs::path& dir, const std::string& command, const Options& options,
                                 std::ostream& notes) {
  std::error_code ec;
  const auto st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st)) {
    throw OutputFolderRefused(dir.string() + " exists and is not a folder; give a new or empty folder");
  }
  if (!fs::exists(st)) {
    fs::create_directories(dir, ec);
    if (ec) throw std::runtime_error("cannot create output directory " + dir.string() + ": " + ec.message());
  }
  OutputManifest old;
  const bool had_manifest = read_output_manifest(dir, old);
  const Snapshot now = snapshot(dir);
  const std::set<std::string> listed_all = old.files();
  std::vector<std::string> listed, others;
  for (const auto& [rel, stamp] : now) (listed_all.count(rel) != 0 ? listed : others).push_back(rel);
  const std::vector<std::string> nested = nested_outputs(dir);

  if (!listed.empty() || !others.empty() || !nested.empty()) {
    const bool replace = options.force || (options.replace_own && had_manifest && old.command == command &&
                                           others.empty() && nested.empty());
    if (!replace) {
      std::string what;
      if (!listed.empty()) {
        what = fmt::format("the outputs of `quadcosim {}` ({}: {})", old.command, files_word(listed.size()),
                           some_names(listed));
      }
      if (!others.empty()) {
        what += fmt::format("{}{} quadcosim did not write ({})", what.empty() ? "" : " and ", files_word(others.size()),
                            some_names(others));
      }
      if (!nested.empty()) {
        what += fmt::format("{}the outputs of other commands in {}", what.empty() ? "" : " and ", some_names(nested));
      }
      throw OutputFolderRefused(fmt::format(
          "{} is not empty: it holds {}; choose a new or empty folder, or add --force to {}", dir.string(), what,
          listed.empty() ? "write into it anyway (those files are kept)"
                         : "remove exactly those outputs first (other files are kept)"));
    }
    refuse_links(dir, now);
    // A file no manifest lists in a folder the command fills alone would pass for one of its outputs.
    for (const std::string& sub : options.exclusive) {
      std::vector<std::string> stray;
      for (const std::string& rel : others) {
        if (rel.starts_with(sub + "/")) stray.push_back(rel);
      }
      if (!stray.empty()) {
        throw OutputFolderRefused(fmt::format(
            "{}: {} holds {} that no manifest lists ({}), e.g. the runs of an earlier `quadcosim {}` whose "
            "manifest did not record them; --force keeps such files, and they would stand beside the new ones: "
            "remove {} by hand, or choose another folder",
            dir.string(), sub + "/", files_word(stray.size()), some_names(stray), command, (dir / sub).string()));
      }
    }
    for (const std::string& rel : listed) {
      if (::unlink((dir / rel).c_str()) != 0 && errno != ENOENT) {  // a regular file (refuse_links): no link
        throw std::runtime_error(fmt::format("cannot remove {}: {}", (dir / rel).string(), std::strerror(errno)));
      }
      prune_empty_parents(dir, rel);
    }
    if (!others.empty()) {
      notes << fmt::format("note: {}: kept {} quadcosim did not write: {}\n", dir.string(), files_word(others.size()),
                           some_names(others));
    }
    if (!nested.empty()) {
      notes << fmt::format("note: {}: kept the outputs of other commands in {}\n", dir.string(), some_names(nested));
    }
  }
  OutputManifest fresh;
  fresh.command = command;
  OutputFolder folder(dir, std::move(fresh), options.default_group);
  folder.seen_ = snapshot(dir);
  folder.write_manifest();
  return folder;
}

OutputFolder OutputFolder::resume(const fs::path& dir, const std::string& command) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw OutputFolderRefused(dir.string() + ": no such folder: nothing to resume");
  }
  OutputManifest manifest;
  if (!read_output_manifest(dir, manifest)) {
    throw OutputFolderRefused(
        fmt::format("{}: no {} here, so no `quadcosim {}` to resume", dir.string(), kOutputManifest, command));
  }
  if (manifest.command != command) {
    throw OutputFolderRefused(
        fmt::format("{} holds the outputs of `quadcosim {}`, not of `quadcosim {}`: nothing to "
                    "resume",
                    dir.string(), manifest.command, command));
  }
  const Snapshot now = snapshot(dir);
  refuse_links(dir, now);
  OutputFolder folder(dir, std::move(manifest), "outputs");
  folder.seen_ = now;
  return folder;
}

OutputFolder OutputFolder::reopen(const fs::path& dir, const std::string& command, const std::string& group) {
  fs::path root = dir;
  std::string prefix;  // of dir's files, relative to root
  OutputManifest manifest;
  if (!read_output_manifest(dir, manifest)) {
    manifest = OutputManifest{command, {}};
    const fs::path abs = fs::absolute(dir).lexically_normal();
    for (fs::path up = abs.parent_path(); !up.empty(); up = up.parent_path()) {
      OutputManifest enclosing;
      if (read_output_manifest(up, enclosing)) {
        const std::string rel = abs.lexically_relative(up).generic_string() + "/";
        bool lists = false;
        for (const std::string& f : enclosing.files()) lists = lists || f.starts_with(rel);
        if (lists) {
          root = up;
          prefix = rel;
          manifest = std::move(enclosing);
        }
        break;  // the nearest manifest decides: an unrelated one is not ours to change
      }
      if (up == up.parent_path()) break;
    }
  }
  const Snapshot now = snapshot(root);
  refuse_links(root, now);  // before the folder exists: a refusal writes no manifest
  OutputFolder folder(root, std::move(manifest), group);
  auto& files = folder.manifest_.groups[group];
  for (auto it = files.begin(); it != files.end();) {
    if (!it->starts_with(prefix)) {
      ++it;
      continue;
    }
    if (now.count(*it) != 0 && ::unlink((root / *it).c_str()) != 0 && errno != ENOENT) {
      throw std::runtime_error(fmt::format("cannot remove {}: {}", (root / *it).string(), std::strerror(errno)));
    }
    it = files.erase(it);
  }
  folder.seen_ = snapshot(root);
  folder.write_manifest();
  return folder;
}

void OutputFolder::record(const std::string& group) {
  const Snapshot now = snapshot(root_);
  for (auto& [g, files] : manifest_.groups) std::erase_if(files, [&](const std::string& f) { return !now.count(f); });
  const std::set<std::string> listed = manifest_.files();
  for (const auto& [rel, stamp] : now) {
    if (listed.count(rel) != 0) continue;
    const auto it = seen_.find(rel);
    if (it == seen_.end() || !(it->second == stamp)) manifest_.groups[group].insert(rel);
  }
  std::erase_if(manifest_.groups, [](const auto& g) { return g.second.empty(); });
  seen_ = now;
  write_manifest();
}

void OutputFolder::write_manifest() const {
  nlohmann::json files = nlohmann::json::object();
  for (const auto& [group, list] : manifest_.groups) files[group] = list;
  const nlohmann::json j = {{"command", manifest_.command}, {"files", files}};
  write_file_atomically(root_ / kOutputManifest, j.dump(2) + "\n");
}

}  // namespace quadcosim::io
