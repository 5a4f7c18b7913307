// Unpacking zip archives (fmi/unzip.hpp): archives written here with minizip's zip writer, among them
// entries that try to leave the target directory.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zip.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "fmi/fmu.hpp"
#include "fmi/unzip.hpp"

namespace quadcosim::fmi {
namespace {

namespace fs = std::filesystem;

/// Writes a zip archive with the (name, content) entries, names as given (no checks).
void make_zip(const std::string& path, const std::vector<std::pair<std::string, std::string>>& entries) {
  zipFile zip = zipOpen64(path.c_str(), APPEND_STATUS_CREATE);
  ASSERT_NE(zip, nullptr);
  for (const auto& [name, content] : entries) {
    zip_fileinfo info{};
    ASSERT_EQ(zipOpenNewFileInZip64(zip, name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr, Z_DEFLATED,
                                    Z_DEFAULT_COMPRESSION, 0),
              ZIP_OK);
    if (!content.empty()) {
      ASSERT_EQ(zipWriteInFileInZip(zip, content.data(), static_cast<unsigned>(content.size())), ZIP_OK);
    }
    ASSERT_EQ(zipCloseFileInZip(zip), ZIP_OK);
  }
  ASSERT_EQ(zipClose(zip, nullptr), ZIP_OK);
}

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string unzip_error(const std::string& archive, const std::string& dir) {
  try {
    unzip(archive, dir);
  } catch (const FmuError& e) {
    return e.what();
  }
  return "";
}

TEST(TempDir, IsPrivateAndRemovesItself) {
  std::string path;
  {
    TempDir dir;
    path = dir.path();
    EXPECT_NE(fs::path(path).filename().string().find("quadcosim-fmu-"), std::string::npos);
    struct stat st {};
    ASSERT_EQ(::stat(path.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0700u);
    fs::create_directories(fs::path(path) / "a" / "b");
    std::ofstream(fs::path(path) / "a" / "b" / "c.txt") << "x";
  }
  EXPECT_FALSE(fs::exists(path));
}

TEST(Unzip, ExtractsNestedEntriesByteForByte) {
  TempDir work;
  const std::string archive = work.path() + "/good.zip";
  std::string binary(70000, '\0');
  for (std::size_t i = 0; i < binary.size(); ++i) binary[i] = static_cast<char>((i * 7919) % 251);
  make_zip(archive, {{"modelDescription.xml", "<x/>"},
                     {"binaries/", ""},
                     {"binaries/linux64/m.so", binary},
                     {"./resources/data.txt", "data"},
                     {"documentation\\index.html", "<html/>"}});
  TempDir out;
  unzip(archive, out.path());
  EXPECT_EQ(read(fs::path(out.path()) / "modelDescription.xml"), "<x/>");
  EXPECT_EQ(read(fs::path(out.path()) / "binaries/linux64/m.so"), binary);
  EXPECT_EQ(read(fs::path(out.path()) / "resources/data.txt"), "data");
  EXPECT_EQ(read(fs::path(out.path()) / "documentation/index.html"), "<html/>");
}

TEST(Unzip, RefusesEntriesThatLeaveTheDirectory) {
  struct Case {
    std::string entry, why;
  };
  const Case cases[] = {
      {"../evil.txt", "has a '..' component"},
      {"resources/../../evil.txt", "has a '..' component"},
      {"resources\\..\\..\\evil.txt", "has a '..' component"},
      {"/tmp/evil.txt", "has an absolute path"},
      {"C:/evil.txt", "has an absolute path"},
  };
  for (const Case& c : cases) {
    TempDir work;
    const std::string archive = work.path() + "/slip.zip";
    make_zip(archive, {{"modelDescription.xml", "<x/>"}, {c.entry, "pwned"}});
    const fs::path out = fs::path(work.path()) / "a" / "b";
    fs::create_directories(out);
    const std::string message = unzip_error(archive, out.string());
    EXPECT_NE(message.find(archive + ": refused entry '" + c.entry + "': it " + c.why), std::string::npos) << message;
    // Nothing landed outside the target directory.
    EXPECT_FALSE(fs::exists(fs::path(work.path()) / "evil.txt"));
    EXPECT_FALSE(fs::exists(fs::path(work.path()) / "a" / "evil.txt"));
  }
}

TEST(Unzip, FmuLoadRefusesAZipSlipAndNamesTheEntry) {
  TempDir work;
  const std::string archive = work.path() + "/slip.fmu";
  make_zip(archive, {{"modelDescription.xml", "<x/>"}, {"binaries/../../../escape.so", "x"}});
  try {
    Fmu::load(archive);
    FAIL() << "loaded";
  } catch (const FmuError& e) {
    EXPECT_NE(std::string(e.what()).find("refused entry 'binaries/../../../escape.so'"), std::string::npos) << e.what();
  }
}

TEST(Unzip, RefusesDuplicateAndConflictingEntries) {
  TempDir work;
  const std::string twice = work.path() + "/twice.zip";
  make_zip(twice, {{"a.txt", "1"}, {"a.txt", "2"}});
  TempDir out1;
  EXPECT_NE(unzip_error(twice, out1.path()).find("entry 'a.txt': cannot create"), std::string::npos);
  EXPECT_NE(unzip_error(twice, TempDir().path()).find("appears twice"), std::string::npos);
  const std::string conflict = work.path() + "/conflict.zip";
  make_zip(conflict, {{"a", "file"}, {"a/b.txt", "under a file"}});
  TempDir out2;
  const std::string message = unzip_error(conflict, out2.path());
  EXPECT_NE(message.find("entry 'a/b.txt'"), std::string::npos) << message;
}

TEST(Unzip, RefusesACorruptArchive) {
  TempDir work;
  const std::string archive = work.path() + "/good.zip";
  std::string big(100000, 'q');
  for (std::size_t i = 0; i < big.size(); i += 3) big[i] = static_cast<char>(i % 97);
  make_zip(archive, {{"data.bin", big}});
  std::string bytes = read(archive);
  // Flip bytes in the middle of the compressed data.
  for (std::size_t i = 200; i < 260; ++i) bytes[i] = static_cast<char>(~bytes[i]);
  const std::string corrupt = work.path() + "/corrupt.zip";
  std::ofstream(corrupt, std::ios::binary) << bytes;
  TempDir out;
  const std::string message = unzip_error(corrupt, out.path());
  EXPECT_NE(message.find(corrupt + ": entry 'data.bin': "), std::string::npos) << message;
  // Cut short: the directory at the end is gone.
  const std::string cut = work.path() + "/cut.zip";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_NE(unzip_error(cut, TempDir().path()).find(cut + ": cannot open as a zip archive"), std::string::npos);
}

}  // namespace
}  // namespace quadcosim::fmi
