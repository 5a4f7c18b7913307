// Output folders: a manifest lists exactly what a command wrote; a used folder is refused unless
// --force, which removes exactly the listed files; plot-style reopening replaces one group.
#include "io/output_folder.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace quadcosim::io {
namespace {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "quadcosim_outdir_test_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void write(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

/// What `quadcosim run` leaves in `dir`: `outputs` written and recorded as the group "outputs", then
/// `figures` as the group "figures" (paths relative to dir).
void write_run(const fs::path& dir, const std::vector<std::string>& outputs, const std::vector<std::string>& figures) {
  std::ostringstream notes;
  OutputFolder f = OutputFolder::claim(dir, "run", {}, notes);
  for (const std::string& p : outputs) write(dir / p);
  f.record("outputs");
  for (const std::string& p : figures) write(dir / p);
  f.record("figures");
}

nlohmann::json manifest_json(const fs::path& dir) {
  std::ifstream in(dir / kOutputManifest);
  return nlohmann::json::parse(in);
}

std::string refusal(const fs::path& dir, const std::string& command, OutputFolder::Options o = {}) {
  std::ostringstream notes;
  try {
    OutputFolder f = OutputFolder::claim(dir, command, o, notes);
  } catch (const OutputFolderRefused& e) {
    return e.what();
  }
  return "";
}

TEST(OutputFolder, NewFolderIsCreatedAndItsManifestListsExactlyWhatWasWritten) {
  TempDir t;
  const fs::path dir = t.path() / "a" / "b";
  std::ostringstream notes;
  {
    OutputFolder f = OutputFolder::claim(dir, "run", {}, notes);
    write(dir / "trajectory.csv");
    write(dir / "sub" / "metrics.json");
    f.record("outputs");
    write(dir / "step_z.png");
  }  // the destructor records the rest under the default group
  const nlohmann::json j = manifest_json(dir);
  EXPECT_EQ(j["command"], "run");
  EXPECT_EQ(j["files"]["outputs"], nlohmann::json({"step_z.png", "sub/metrics.json", "trajectory.csv"}));
  EXPECT_EQ(j["files"].size(), 1u);
  EXPECT_TRUE(notes.str().empty());
}

TEST(OutputFolder, GroupsSplitTheFilesByWhenTheyWereWritten) {
  TempDir t;
  write_run(t.path(), {"trajectory.csv"}, {"overview.png"});
  const nlohmann::json j = manifest_json(t.path());
  EXPECT_EQ(j["files"]["outputs"], nlohmann::json({"trajectory.csv"}));
  EXPECT_EQ(j["files"]["figures"], nlohmann::json({"overview.png"}));
}

TEST(OutputFolder, UsedFolderIsRefusedNamingItAndWhatItHolds) {
  TempDir t;
  std::ostringstream notes;
  {
    OutputFolder f = OutputFolder::claim(t.path(), "run", {}, notes);
    write(t.path() / "step_x.png");
  }
  write(t.path() / "notes.txt");
  const std::string why = refusal(t.path(), "sweep");
  EXPECT_NE(why.find(t.path().string() + " is not empty"), std::string::npos) << why;
  EXPECT_NE(why.find("`quadcosim run` (1 file: step_x.png)"), std::string::npos) << why;
  EXPECT_NE(why.find("1 file quadcosim did not write (notes.txt)"), std::string::npos) << why;
  EXPECT_NE(why.find("--force"), std::string::npos) << why;
  EXPECT_TRUE(fs::exists(t.path() / "step_x.png"));  // a refusal changes nothing
}

TEST(OutputFolder, ForeignFilesAloneAreRefusedToo) {
  TempDir t;
  write(t.path() / "mine.txt");
  const std::string why = refusal(t.path(), "run");
  EXPECT_NE(why.find("1 file quadcosim did not write (mine.txt)"), std::string::npos) << why;
  EXPECT_EQ(why.find("outputs of"), std::string::npos) << why;
}

TEST(OutputFolder, ForceRemovesExactlyTheListedFilesAndKeepsTheRest) {
  TempDir t;
  std::ostringstream notes;
  {
    OutputFolder f = OutputFolder::claim(t.path(), "sweep", {}, notes);
    for (int i = 0; i < 4; ++i) write(t.path() / "runs" / ("000" + std::to_string(i)) / "metrics.json");
    write(t.path() / "summary.json");
  }
  write(t.path() / "notes.txt", "mine");
  write(t.path() / "runs" / "0003" / "keep.me");
  OutputFolder::Options force;
  force.force = true;
  {
    OutputFolder f = OutputFolder::claim(t.path(), "sweep", force, notes);
    EXPECT_FALSE(fs::exists(t.path() / "summary.json"));
    EXPECT_FALSE(fs::exists(t.path() / "runs" / "0001"));  // emptied run folders go too
    EXPECT_TRUE(fs::exists(t.path() / "runs" / "0003" / "keep.me"));
    for (int i = 0; i < 2; ++i) write(t.path() / "runs" / ("000" + std::to_string(i)) / "metrics.json");
  }
  EXPECT_NE(notes.str().find("kept 2 files quadcosim did not write: notes.txt, runs/0003/keep.me"), std::string::npos)
      << notes.str();
  EXPECT_EQ(manifest_json(t.path())["files"]["outputs"],
            nlohmann::json({"runs/0000/metrics.json", "runs/0001/metrics.json"}));
  std::ifstream in(t.path() / "notes.txt");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "mine");
}

TEST(OutputFolder, ReplaceOwnReplacesTheSameCommandsOutputsOnly) {
  TempDir t;
  std::ostringstream notes;
  OutputFolder::Options own;
  own.replace_own = true;
  {
    OutputFolder f = OutputFolder::claim(t.path(), "compare", own, notes);
    write(t.path() / "compare_x.png");
  }
  {
    OutputFolder f = OutputFolder::claim(t.path(), "compare", own, notes);
    EXPECT_FALSE(fs::exists(t.path() / "compare_x.png"));
    write(t.path() / "compare_z.png");
  }
  EXPECT_NE(refusal(t.path(), "margins", own).find("`quadcosim compare`"), std::string::npos);
  write(t.path() / "mine.txt");
  EXPECT_NE(refusal(t.path(), "compare", own).find("mine.txt"), std::string::npos);
}

TEST(OutputFolder, ReopenReplacesOneGroupOfTheFolder) {
  TempDir t;
  write_run(t.path(), {"trajectory.csv"}, {"step_x.png", "overview.png"});
  {
    OutputFolder f = OutputFolder::reopen(t.path(), "plot", "figures");
    EXPECT_FALSE(fs::exists(t.path() / "step_x.png"));
    EXPECT_TRUE(fs::exists(t.path() / "trajectory.csv"));
    write(t.path() / "step_z.png");
    write(t.path() / "overview.png");
  }
  const nlohmann::json j = manifest_json(t.path());
  EXPECT_EQ(j["command"], "run");
  EXPECT_EQ(j["files"]["figures"], nlohmann::json({"overview.png", "step_z.png"}));
  EXPECT_EQ(j["files"]["outputs"], nlohmann::json({"trajectory.csv"}));
}

TEST(OutputFolder, ReopenOfASubFolderUsesTheEnclosingManifest) {
  TempDir t;
  write_run(t.path(), {"uav0000/trajectory.csv", "uav0001/trajectory.csv"},
            {"uav0000/step_x.png", "uav0001/step_x.png"});
  {
    OutputFolder f = OutputFolder::reopen(t.path() / "uav0000", "plot", "figures");
    EXPECT_FALSE(fs::exists(t.path() / "uav0000" / "step_x.png"));
    EXPECT_TRUE(fs::exists(t.path() / "uav0001" / "step_x.png"));  // another vehicle's: not this plot's
    write(t.path() / "uav0000" / "step_z.png");
  }
  EXPECT_FALSE(fs::exists(t.path() / "uav0000" / kOutputManifest));
  EXPECT_EQ(manifest_json(t.path())["files"]["figures"], nlohmann::json({"uav0000/step_z.png", "uav0001/step_x.png"}));
}

TEST(OutputFolder, NestedOutputFoldersAreKeptAndNamed) {
  TempDir t;
  std::ostringstream notes;
  {
    OutputFolder f = OutputFolder::claim(t.path() / "cmp", "compare", {}, notes);
    write(t.path() / "cmp" / "c.md");
  }
  EXPECT_NE(refusal(t.path(), "run").find("the outputs of other commands in cmp/"), std::string::npos);
  OutputFolder::Options force;
  force.force = true;
  { OutputFolder f = OutputFolder::claim(t.path(), "run", force, notes); }
  EXPECT_TRUE(fs::exists(t.path() / "cmp" / "c.md"));
}

TEST(OutputFolder, AManifestNamingFilesOutsideItsFolderIsRefused) {
  TempDir t;
  write(t.path() / "out" / kOutputManifest, R"({"command": "run", "files": {"outputs": ["../victim"]}})");
  write(t.path() / "victim");
  OutputFolder::Options force;
  force.force = true;
  EXPECT_NE(refusal(t.path() / "out", "run", force).find("not a quadcosim output manifest"), std::string::npos);
  EXPECT_TRUE(fs::exists(t.path() / "victim"));
}

TEST(OutputFolder, AFileInPlaceOfTheFolderIsRefused) {
  TempDir t;
  write(t.path() / "f");
  EXPECT_NE(refusal(t.path() / "f", "run").find("exists and is not a folder"), std::string::npos);
}

}  // namespace
}  // namespace quadcosim::io

namespace quadcosim::io {
namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A folder a command wrote (summary.json, runs/0000/metrics.json), with its manifest.
void used_folder(const fs::path& dir) {
  std::ostringstream notes;
  OutputFolder f = OutputFolder::claim(dir, "sweep", {}, notes);
  write(dir / "summary.json");
  write(dir / "runs" / "0000" / "metrics.json");
}

TEST(OutputFolder, AnEmptyManifestLeftByAnOlderVersionIsRefusedWithAWayForward) {
  TempDir t;
  write(t.path() / "trajectory.csv");
  write(t.path() / kOutputManifest, "");
  const std::string why = refusal(t.path(), "run", {.force = true});
  EXPECT_NE(why.find(kOutputManifest), std::string::npos) << why;
  EXPECT_NE(why.find("empty (0 bytes)"), std::string::npos) << why;
  EXPECT_NE(why.find("by hand"), std::string::npos) << why;
  EXPECT_TRUE(fs::exists(t.path() / "trajectory.csv"));  // nothing removed on its word
  write(t.path() / kOutputManifest, R"({"command": "run", "files": {"outputs": ["trajectory.csv",)");
  const std::string cut = refusal(t.path(), "run", {.force = true});
  EXPECT_NE(cut.find("not JSON (cut short?"), std::string::npos) << cut;
}

TEST(OutputFolder, TheManifestIsNeverLeftEmptyOrPartWritten) {
  TempDir t;
  std::ostringstream notes;
  OutputFolder f = OutputFolder::claim(t.path(), "run", {}, notes);
  write(t.path() / "a.csv");
  f.record("outputs");
  // Every record leaves a whole manifest (written beside it and renamed over it) and no temporary
  // file; a write that fails is in WriteFileAtomically..., a full disk in cli.output_folder_disk_full.
  for (int i = 0; i < 5; ++i) {
    write(t.path() / fmt::format("f{}.csv", i));
    f.record("outputs");
    EXPECT_EQ(manifest_json(t.path())["files"]["outputs"].size(), static_cast<std::size_t>(i + 2));
  }
  for (const auto& e : fs::directory_iterator(t.path())) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
}

TEST(OutputFolder, WriteFileAtomicallyReplacesALinkAndNeverWritesThroughIt) {
  TempDir t;
  write(t.path() / "outside.txt", "precious");
  fs::create_directories(t.path() / "out");
  fs::create_symlink(t.path() / "outside.txt", t.path() / "out" / "summary.json");
  write_file_atomically(t.path() / "out" / "summary.json", "{}\n");
  EXPECT_EQ(read_text(t.path() / "outside.txt"), "precious");
  EXPECT_FALSE(fs::is_symlink(t.path() / "out" / "summary.json"));
  EXPECT_EQ(read_text(t.path() / "out" / "summary.json"), "{}\n");
  // A failed write (a folder where the file goes) leaves what was there and no temporary file.
  fs::create_directories(t.path() / "out" / "metrics.json");
  try {
    write_file_atomically(t.path() / "out" / "metrics.json", "x");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("metrics.json: write failed"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(t.path() / "out" / "metrics.json"));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(t.path() / "out")) ++entries;
  EXPECT_EQ(entries, 2u);  // summary.json and the metrics.json folder
}

TEST(OutputFolder, OpenOutputFileRefusesALinkAtItsPath) {
  TempDir t;
  write(t.path() / "outside.txt", "precious");
  fs::create_symlink(t.path() / "outside.txt", t.path() / "trajectory.csv");
  try {
    std::FILE* f = open_output_file(t.path() / "trajectory.csv");
    std::fclose(f);
    ADD_FAILURE() << "opened through a link";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("symbolic link"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_text(t.path() / "outside.txt"), "precious");
  std::FILE* f = open_output_file(t.path() / "new.csv");
  ASSERT_NE(f, nullptr);
  std::fputs("t\n", f);
  EXPECT_EQ(std::fclose(f), 0);
  EXPECT_EQ(read_text(t.path() / "new.csv"), "t\n");
}

TEST(OutputFolder, ForceRefusesALinkPlantedInTheFolderAndLeavesItsTargetAlone) {
  TempDir t;
  const fs::path dir = t.path() / "out", outside = t.path() / "outside.txt";
  write(outside, "precious");
  used_folder(dir);
  // In place of a listed file, and at a path the next command writes (a run folder it did not list).
  fs::remove(dir / "summary.json");
  fs::create_symlink(outside, dir / "summary.json");
  fs::create_directories(dir / "runs" / "0001");
  fs::create_symlink(outside, dir / "runs" / "0001" / "metrics.json");
  const std::string why = refusal(dir, "sweep", {.force = true});
  EXPECT_NE(why.find("not a regular file"), std::string::npos) << why;
  EXPECT_NE(why.find("runs/0001/metrics.json"), std::string::npos) << why;
  EXPECT_NE(why.find("summary.json"), std::string::npos) << why;
  EXPECT_EQ(read_text(outside), "precious");
  EXPECT_TRUE(fs::is_symlink(dir / "summary.json"));  // refused: nothing changed
  EXPECT_TRUE(fs::exists(dir / "runs" / "0000" / "metrics.json"));
  // A link to a folder (runs/ pointing elsewhere) too.
  TempDir u;
  fs::create_directories(u.path() / "elsewhere");
  fs::create_directories(u.path() / "out");
  fs::create_directory_symlink(u.path() / "elsewhere", u.path() / "out" / "runs");
  EXPECT_NE(refusal(u.path() / "out", "sweep", {.force = true}).find("runs"), std::string::npos);
}

TEST(OutputFolder, ForceRefusesUnlistedFilesInAnExclusiveSubFolder) {
  TempDir t;
  used_folder(t.path());
  write(t.path() / "runs" / "0050" / "metrics.json");  // a run the manifest does not list
  write(t.path() / "notes.txt");
  const std::string why = refusal(t.path(), "sweep", {.force = true, .exclusive = {"runs"}});
  EXPECT_NE(why.find("runs/ holds 1 file that no manifest lists (runs/0050/metrics.json)"), std::string::npos) << why;
  EXPECT_TRUE(fs::exists(t.path() / "runs" / "0000" / "metrics.json"));  // nothing removed
  fs::remove_all(t.path() / "runs" / "0050");
  std::ostringstream notes;
  { OutputFolder f = OutputFolder::claim(t.path(), "sweep", {.force = true, .exclusive = {"runs"}}, notes); }
  EXPECT_FALSE(fs::exists(t.path() / "runs"));
  EXPECT_TRUE(fs::exists(t.path() / "notes.txt"));  // outside runs/: kept, as ever
}

TEST(OutputFolder, ResumeKeepsTheListedFilesAndAddsTheNewOnes) {
  TempDir t;
  used_folder(t.path());
  {
    OutputFolder f = OutputFolder::resume(t.path(), "sweep");
    write(t.path() / "runs" / "0001" / "metrics.json");
    write(t.path() / "summary.json", "rewritten");
  }
  EXPECT_EQ(manifest_json(t.path())["files"]["outputs"],
            nlohmann::json({"runs/0000/metrics.json", "runs/0001/metrics.json", "summary.json"}));
  try {
    OutputFolder f = OutputFolder::resume(t.path(), "run");
    ADD_FAILURE() << "resumed another command's folder";
  } catch (const OutputFolderRefused& e) {
    EXPECT_NE(std::string(e.what()).find("not of `quadcosim run`"), std::string::npos) << e.what();
  }
  EXPECT_THROW(OutputFolder::resume(t.path() / "none", "sweep"), OutputFolderRefused);
}

}  // namespace
}  // namespace quadcosim::io
