// Every host's recordings (hosts/recording.hpp): io's recorders and, when --foxglove is given, the
// live view as one more recorder of the same io::Recording (fed the same ticks, finished with them).
#include "hosts/recording.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "io/scenario.hpp"
#include "sim/inprocess_transport.hpp"

namespace quadcosim::hosts {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("hosts_recording_test_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

std::size_t lines_in(const fs::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

// trajectory.csv and the live view (a free port on 127.0.0.1) built together: both are fed each
// tick, the live view holding tick 1 (t = 0.05 s) back until 5 ms after it was built under
// --foxglove-pace 10, and the CSV holds the three rows when the recording finishes.
TEST(HostsRecordingTest, TheLiveViewIsOneOfTheRunsRecorders) {
  TempDir dir;
  sim::InProcessTransport bus;
  RecordingOptions o;
  o.csv = (dir.path / "trajectory.csv").string();
  o.foxglove.listen = "127.0.0.1:0";
  o.foxglove.pace = 10.0;
  o.who = "test";
  const auto built = std::chrono::steady_clock::now();
  io::Recording rec = make_recording(o, &bus);
  model::State x;
  const model::Vector4 command(4830.5, 4830.5, 4830.5, 4830.5);
  for (int k = 0; k < 3; ++k) {
    rec.tick({k, 0.05 * k, 50'000'000LL * k, x, command, nullptr, false});
    if (k == 1) {
      EXPECT_GE(std::chrono::steady_clock::now() - built, std::chrono::milliseconds(5));
    }
  }
  rec.finish(true);
  EXPECT_EQ(lines_in(dir.path / "trajectory.csv"), 4u);  // the header and three ticks
}

TEST(HostsRecordingTest, ABadListenAddressIsAConfigErrorNamingTheOption) {
  sim::InProcessTransport bus;
  RecordingOptions o;
  o.foxglove.listen = "127.0.0.1:70000";
  try {
    (void)make_recording(o, &bus);
    FAIL() << "expected io::ConfigError";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("--foxglove \"127.0.0.1:70000\": the port must be a number 0..65535"),
              std::string::npos)
        << e.what();
  }
}

TEST(HostsRecordingTest, TheLiveViewNeedsTheBus) {
  RecordingOptions o;
  o.foxglove.listen = "127.0.0.1:0";
  EXPECT_THROW((void)make_recording(o, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace quadcosim::hosts
