// Zip writing: what write_zip packs, fmi::unzip (a second implementation, the master's) unpacks
// byte for byte; the same contents give the same archive; bad entry names and unwritable archives
// are refused naming them, leaving no partial file behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "fmi/model_description.hpp"
#include "fmi/unzip.hpp"
#include "fmi/zip_writer.hpp"

namespace quadcosim::fmi {
namespace {

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string refusal(const std::filesystem::path& archive, const std::vector<ZipEntry>& entries) {
  try {
    write_zip(archive, entries);
  } catch (const ZipError& e) {
    return e.what();
  }
  return "";
}

TEST(ZipWriter, UnzipsToWhatWasPacked) {
  TempDir dir("quadcosim-zip-test-");
  const std::filesystem::path root = dir.path();
  std::string binary(300000, '\0');  // large enough to need more than one deflate block
  for (std::size_t i = 0; i < binary.size(); ++i) binary[i] = static_cast<char>((i * 7919u) >> 3);
  std::ofstream(root / "lib.so", std::ios::binary) << binary;
  const std::vector<ZipEntry> entries = {
      ZipEntry::from_bytes("modelDescription.xml", "<fmiModelDescription/>\n"),
      ZipEntry::from_file("binaries/linux64/model.so", root / "lib.so", true),
      ZipEntry::from_bytes("resources/quadcosim.json", "{\"a\": 1}"),
      ZipEntry::from_bytes("resources/empty", ""),
  };
  write_zip(root / "a.fmu", entries);
  std::filesystem::create_directory(root / "out");
  unzip((root / "a.fmu").string(), (root / "out").string());
  EXPECT_EQ(slurp(root / "out/modelDescription.xml"), "<fmiModelDescription/>\n");
  EXPECT_EQ(slurp(root / "out/binaries/linux64/model.so"), binary);
  EXPECT_EQ(slurp(root / "out/resources/quadcosim.json"), "{\"a\": 1}");
  EXPECT_TRUE(std::filesystem::is_regular_file(root / "out/resources/empty"));
  EXPECT_EQ(std::filesystem::file_size(root / "out/resources/empty"), 0u);

  // The same contents, the same bytes (fixed dates); replacing an existing archive.
  write_zip(root / "b.fmu", entries);
  EXPECT_EQ(slurp(root / "a.fmu"), slurp(root / "b.fmu"));
  write_zip(root / "b.fmu", {ZipEntry::from_bytes("x", "y")});
  EXPECT_NE(slurp(root / "a.fmu"), slurp(root / "b.fmu"));
}

TEST(ZipWriter, RefusesBadNamesAndUnwritableArchives) {
  TempDir dir("quadcosim-zip-test-");
  const std::filesystem::path a = std::filesystem::path(dir.path()) / "a.zip";
  EXPECT_EQ(refusal(a, {ZipEntry::from_bytes("../evil", "")}),
            a.string() + ": entry '../evil' has an empty, '.' or '..' part");
  EXPECT_EQ(refusal(a, {ZipEntry::from_bytes("/etc/x", "")}), a.string() + ": entry '/etc/x' has an absolute path");
  EXPECT_EQ(refusal(a, {ZipEntry::from_bytes("x", ""), ZipEntry::from_bytes("x", "")}),
            a.string() + ": entry 'x' is given twice");
  EXPECT_EQ(refusal(a, {ZipEntry::from_bytes("x", ""), ZipEntry::from_bytes("x/y", "")}),
            a.string() + ": entry 'x' is both a file and a folder");
  EXPECT_EQ(refusal(a, {ZipEntry::from_file("x", std::filesystem::path(dir.path()) / "missing")}),
            a.string() + ": cannot read " + dir.path() + "/missing (for x)");
  EXPECT_FALSE(std::filesystem::exists(a));  // nothing left behind
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 0);

  const std::filesystem::path nowhere = std::filesystem::path(dir.path()) / "no/such/dir/a.zip";
  EXPECT_NE(refusal(nowhere, {ZipEntry::from_bytes("x", "")}).find(nowhere.string() + ": cannot create"),
            std::string::npos);
}

}  // namespace
}  // namespace quadcosim::fmi
