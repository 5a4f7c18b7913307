// The recordings of a run (sim/recorder.hpp's seam): trajectory.csv, the judged series in memory and
// run.mcap as recorders, and the one place that builds them from a run's output options, for every
// host (in-process runs and swarms, sweeps, the DDS plant and swarm processes, `record`, `openloop`).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/mcap_recorder.hpp"
#include "io/trajectory_csv.hpp"
#include "model/vehicle_params.hpp"
#include "sensors/sensor_set.hpp"
#include "sim/recorder.hpp"
#include "sim/transport.hpp"

namespace quadcosim::io {

struct Scenario;

/// What a run records and where ("" or nullptr: not that recording).
struct RecordingOptions {
  std::string csv;                   ///< trajectory.csv's path
  SeriesRecorder* series = nullptr;  ///< the judged series in memory (emptied by its owner before the run)
  std::string mcap;                  ///< run.mcap's path; its metadata.yaml is written beside it
  std::vector<std::string> topics;   ///< run.mcap: only these topics (empty: every topic of the vehicle)
  /// run.mcap: the vehicle's namespace, its description (recorded at start_ns when not nullptr: the plant
  /// publishes /tf) and the extra sensors whose topics are recorded too (nullptr: none).
  std::string ns = "/drone";
  const model::VehicleParams* vehicle = nullptr;
  std::int64_t start_ns = 0;
  const sensors::SensorSet* sensors = nullptr;
  /// run.mcap of a host without plant ticks (idle()): written up to a second behind the newest message.
  bool live = false;

  /// What the run of `sc` describes in run.mcap (namespace, vehicle when its plant publishes /tf, start
  /// time, extra sensors); the paths are the caller's. `sc` must outlive the recording.
  static RecordingOptions for_run(const Scenario& sc);
};

/// trajectory.csv: one row per tick (TrajectoryWriter).
class CsvRecorder final : public sim::Recorder {
 public:
  /// Throws std::runtime_error naming `path` when it cannot be opened.
  explicit CsvRecorder(const std::string& path) : writer_(path) {}
  void tick(const sim::RecordedTick& t) override;
  void finish(bool) override { writer_.close(); }

 private:
  TrajectoryWriter writer_;
};

/// The same rows in memory (SeriesRecorder: what read_series gives for the CSV, bit for bit).
class SeriesRecording final : public sim::Recorder {
 public:
  explicit SeriesRecording(SeriesRecorder& series) : series_(series) {}
  void tick(const sim::RecordedTick& t) override;
  void finish(bool) override {}

 private:
  SeriesRecorder& series_;
};

/// run.mcap (McapRecorder): taps the vehicle's topics on the bus, writes what is settled at each tick,
/// and on a completed finish the metadata.yaml beside the file.
class McapRecording final : public sim::Recorder {
 public:
  McapRecording(const RecordingOptions& o, sim::Transport& bus);
  void tick(const sim::RecordedTick& t) override { recorder_.flush_settled(t.t_ns); }
  void idle() override;
  void finish(bool completed) override;
  const McapRecorder& recorder() const { return recorder_; }

 private:
  McapRecorder recorder_;
  std::string path_;
  bool live_;
};

/// The recorders of one run, fed together in the order they were built (CSV, series, MCAP).
class Recording final : public sim::Recorder {
 public:
  void add(std::unique_ptr<sim::Recorder> r) { parts_.push_back(std::move(r)); }
  bool empty() const { return parts_.empty(); }
  void tick(const sim::RecordedTick& t) override;
  void idle() override;
  /// Finishes every part (each once), the first error rethrown after all were tried.
  void finish(bool completed) override;
  /// run.mcap's recorder (its counts), nullptr when the run records none.
  const McapRecorder* mcap() const { return mcap_ ? &mcap_->recorder() : nullptr; }

 private:
  friend Recording make_recording(const RecordingOptions& o, sim::Transport* bus);
  std::vector<std::unique_ptr<sim::Recorder>> parts_;
  const McapRecording* mcap_ = nullptr;
  bool finished_ = false;
};

/// Builds the recordings `o` asks for: trajectory.csv, the series, run.mcap (subscribed through `bus`,
/// which must outlive the recording; std::invalid_argument when run.mcap is asked without a bus).
/// Throws std::runtime_error naming a file that cannot be opened.
Recording make_recording(const RecordingOptions& o, sim::Transport* bus);

}  // namespace quadcosim::io
