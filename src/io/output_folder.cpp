#include "io/output_folder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

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
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(file, ec))) return false;
  std::ifstream in(file);
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
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
  } catch (const std::exception& e) {
    throw OutputFolderRefused(
        fmt::format("{}: not a quadcosim output manifest ({}); remove it by hand, or choose "
                    "another folder",
                    file.string(), e.what()));
  }
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
    const auto st = it->symlink_status(ec);
    if (fs::is_directory(st)) {
      if (has_manifest(p)) it.disable_recursion_pending();  // another command's outputs
      continue;
    }
    const std::string rel = p.lexically_relative(root).generic_string();
    if (rel == kOutputManifest || rel == std::string(kOutputManifest) + ".tmp") continue;
    Stamp stamp;
    if (fs::is_regular_file(st)) {
      stamp.size = it->file_size(ec);
      stamp.mtime = it->last_write_time(ec);
    }
    s[rel] = stamp;
  }
  if (ec) throw std::runtime_error("cannot read " + root.string() + ": " + ec.message());
  return s;
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
    for (const std::string& rel : listed) {
      fs::remove(dir / rel, ec);
      if (ec) throw std::runtime_error("cannot remove " + (dir / rel).string() + ": " + ec.message());
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
  OutputFolder folder(root, std::move(manifest), group);
  const Snapshot now = snapshot(root);
  auto& files = folder.manifest_.groups[group];
  std::error_code ec;
  for (auto it = files.begin(); it != files.end();) {
    if (!it->starts_with(prefix)) {
      ++it;
      continue;
    }
    if (now.count(*it) != 0) {
      fs::remove(root / *it, ec);
      if (ec) throw std::runtime_error("cannot remove " + (root / *it).string() + ": " + ec.message());
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
  const fs::path file = root_ / kOutputManifest, tmp = root_ / (std::string(kOutputManifest) + ".tmp");
  {
    std::ofstream out(tmp);
    out << j.dump(2) << '\n';
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) throw std::runtime_error("cannot write " + file.string() + ": " + ec.message());
}

}  // namespace quadcosim::io
