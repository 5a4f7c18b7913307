#include "io/recording.hpp"

#include <exception>
#include <filesystem>
#include <stdexcept>

#include "io/scenario.hpp"
#include "sim/topics.hpp"

namespace quadcosim::io {

namespace {
ControlColumns columns_of(const sim::RecordedTick& t) {
  return t.status ? ControlColumns::from(*t.status) : ControlColumns::none();
}
}  // namespace

RecordingOptions RecordingOptions::for_run(const Scenario& sc) {
  RecordingOptions o;
  o.ns = sc.simulation.ns;
  if (sc.simulation.plant.publish_tf) o.vehicle = &sc.vehicle;
  o.start_ns = sc.simulation.plant.clock.ns(0);
  o.sensors = &sc.simulation.plant.realism.extra_sensors;
  return o;
}

void CsvRecorder::tick(const sim::RecordedTick& t) {
  writer_.write(t.t_s, t.state, t.command, columns_of(t), t.watchdog);
}

void SeriesRecording::tick(const sim::RecordedTick& t) {
  series_.add(t.t_s, t.state, t.command, columns_of(t), t.watchdog);
}

McapRecording::McapRecording(const RecordingOptions& o, sim::Transport& bus)
    : recorder_(o.mcap, bus, sim::Topics::for_namespace(o.ns), o.topics), path_(o.mcap), live_(o.live) {
  if (o.vehicle) recorder_.record_vehicle(*o.vehicle, o.ns, o.start_ns);
  if (o.sensors) recorder_.record_sensors(bus, o.ns, *o.sensors);
}

void McapRecording::idle() {
  // Header times are simulated time; a second of it stays in memory to put late arrivals in order.
  if (live_) recorder_.flush_before(recorder_.newest_ns() - 1'000'000'000);
}

void McapRecording::finish(bool completed) {
  recorder_.close();
  if (!completed) return;
  const std::filesystem::path p(path_);
  recorder_.write_bag_metadata(p.parent_path().empty() ? "." : p.parent_path().string(), p.filename().string());
}

void Recording::tick(const sim::RecordedTick& t) {
  for (auto& r : parts_) r->tick(t);
}

void Recording::idle() {
  for (auto& r : parts_) r->idle();
}

void Recording::finish(bool completed) {
  if (finished_) return;
  finished_ = true;
  std::exception_ptr first;
  for (auto& r : parts_) {
    try {
      r->finish(completed);
    } catch (...) {
      if (!first) first = std::current_exception();
    }
  }
  if (first) std::rethrow_exception(first);
}

Recording make_recording(const RecordingOptions& o, sim::Transport* bus) {
  Recording rec;
  if (!o.csv.empty()) rec.add(std::make_unique<CsvRecorder>(o.csv));
  if (o.series) rec.add(std::make_unique<SeriesRecording>(*o.series));
  if (!o.mcap.empty()) {
    if (!bus) throw std::invalid_argument("make_recording: " + o.mcap + ": run.mcap needs the run's bus");
    auto mcap = std::make_unique<McapRecording>(o, *bus);
    rec.mcap_ = mcap.get();
    rec.add(std::move(mcap));
  }
  return rec;
}

}  // namespace quadcosim::io
