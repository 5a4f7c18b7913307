// The recorder seam (io/recording.hpp): one Recording built from a run's output options records the
// rows and messages it was fed, in every format asked.
#include "io/recording.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/inprocess_transport.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"

namespace quadcosim::io {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  for (std::string line; std::getline(s, line);) out.push_back(line);
  return out;
}

std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, ',');) out.push_back(cell);
  return out;
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("recording_test_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

// Three ticks of 10 ms and three Pose messages (stamped 10, 20, 30 ms) into trajectory.csv, the
// series and run.mcap, built by make_recording.
TEST(RecordingTest, OneRecordingRecordsTheTicksAndTheTappedMessagesInEveryFormat) {
  TempDir dir;
  sim::InProcessTransport bus;
  SeriesRecorder series;
  series.clear(3);
  RecordingOptions o;
  o.csv = (dir.path / "trajectory.csv").string();
  o.series = &series;
  o.mcap = (dir.path / "run.mcap").string();
  Recording rec = make_recording(o, &bus);
  ASSERT_NE(rec.mcap(), nullptr);
  const sim::Topics topics = sim::Topics::for_namespace("/drone");
  auto pose = bus.advertise<msg::PoseStamped>(topics.pose);

  msg::ControllerStatus status;  // a controller that asked z = 1.5 m and has no figures of its own
  status.setpoint = {0.0, 0.0, 1.5, 0.0, 0.0, 0.0};
  const double t_s[3] = {0.0, 0.01, 0.02};
  const std::int64_t t_ns[3] = {0, 10'000'000, 20'000'000};
  for (int k = 0; k < 3; ++k) {
    model::State x;
    x.p_W = {0.25 * k, -1.5, 2.0};
    const model::Vector4 command(4830.5, 4830.5, 4830.5, 4830.5);
    msg::PoseStamped p;
    p.header.stamp = msg::Time::from_ns(10'000'000 * (k + 1));
    pose.publish(p);
    rec.tick({k, t_s[k], t_ns[k], x, command, k == 0 ? nullptr : &status, k == 2});
  }
  EXPECT_EQ(rec.mcap()->messages(), 0u);  // messages stay 100 ms behind the tick (McapRecorder::kHoldNs)
  rec.finish(true);
  EXPECT_EQ(rec.mcap()->messages(), 3u);
  rec.finish(true);  // once only

  const std::vector<std::string> rows = lines_of(read_text(dir.path / "trajectory.csv"));
  ASSERT_EQ(rows.size(), 4u);  // header and three ticks
  const std::vector<std::string> header = cells_of(rows[0]);
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::vector<std::string> t_text = {"0", "0.01", "0.02"}, x_text = {"0", "0.25", "0.5"};
  for (std::size_t k = 0; k < 3; ++k) {
    const std::vector<std::string> c = cells_of(rows[k + 1]);
    ASSERT_EQ(c.size(), header.size()) << rows[k + 1];
    EXPECT_EQ(c[column("t")], t_text[k]);
    EXPECT_EQ(c[column("x")], x_text[k]);
    EXPECT_EQ(c[column("y")], "-1.5");
    EXPECT_EQ(c[column("cmd1")], "4830.5");
    EXPECT_EQ(c[column("watchdog")], k == 2 ? "1" : "0");
  }
  EXPECT_EQ(cells_of(rows[1])[column("z_des")], "nan");  // no status yet: open loop's NaN
  EXPECT_EQ(cells_of(rows[2])[column("z_des")], "1.5");

  const Series& s = series.series();
  ASSERT_EQ(s.t_s.size(), 3u);
  EXPECT_EQ(s.t_s[1], 0.01);
  EXPECT_EQ(s.values.at("x")[2], 0.5);
  EXPECT_EQ(s.values.at("z_des")[2], 1.5);
  EXPECT_EQ(s.values.at("watchdog")[2], 1.0);

  // metadata.yaml: three messages from 10 ms to 30 ms.
  const std::string meta = read_text(dir.path / "metadata.yaml");
  EXPECT_NE(meta.find("message_count: 3"), std::string::npos) << meta;
  EXPECT_NE(meta.find("nanoseconds_since_epoch: 10000000"), std::string::npos) << meta;
  EXPECT_NE(meta.find("nanoseconds: 20000000"), std::string::npos) << meta;
}

// run.mcap is written as the ticks go: a tick 100 ms after a message writes it; a finish that is not
// a completed run's closes the file without metadata.yaml.
TEST(RecordingTest, McapWritesWhatIsSettledAtEachTickAndDescribesOnlyACompletedRun) {
  TempDir dir;
  sim::InProcessTransport bus;
  RecordingOptions o;
  o.mcap = (dir.path / "run.mcap").string();
  Recording rec = make_recording(o, &bus);
  auto pose = bus.advertise<msg::PoseStamped>(sim::Topics::for_namespace("/drone").pose);
  for (std::int64_t ms : {10, 20, 30}) {
    msg::PoseStamped p;
    p.header.stamp = msg::Time::from_ns(ms * 1'000'000);
    pose.publish(p);
  }
  const model::State x;
  const model::Vector4 w = model::Vector4::Zero();
  rec.tick({11, 0.11, 110'000'000, x, w, nullptr, false});  // writes what is before 10 ms: nothing
  EXPECT_EQ(rec.mcap()->messages(), 0u);
  rec.tick({12, 0.115, 115'000'000, x, w, nullptr, false});  // before 15 ms: the first
  EXPECT_EQ(rec.mcap()->messages(), 1u);
  rec.tick({13, 0.13, 130'000'001, x, w, nullptr, false});  // before 30.000001 ms: all three
  EXPECT_EQ(rec.mcap()->messages(), 3u);
  rec.finish(false);
  EXPECT_TRUE(fs::exists(dir.path / "run.mcap"));
  EXPECT_FALSE(fs::exists(dir.path / "metadata.yaml"));
}

TEST(RecordingTest, AskingForRunMcapWithoutABusIsAnErrorAndNothingAskedRecordsNothing) {
  RecordingOptions o;
  o.mcap = "/nonexistent/run.mcap";
  EXPECT_THROW((void)make_recording(o, nullptr), std::invalid_argument);
  Recording none = make_recording(RecordingOptions{}, nullptr);
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(none.mcap(), nullptr);
}

}  // namespace
}  // namespace quadcosim::io
