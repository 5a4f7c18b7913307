// What the long-running node processes (`plant`, `controller`) share: the wall clock they pace and
// measure with, how they find their scenario, and the sensor-data QoS option.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dds/arrival_executor.hpp"
#include "dds/dds_transport.hpp"
#include "dds/steady_clock.hpp"
#include "drivers/driver_host.hpp"
#include "io/scenario.hpp"
#include "sim/topics.hpp"

namespace quadcosim::hosts {

constexpr std::int64_t kMs = 1'000'000;  ///< [ns]

/// Monotonic wall clock [ns]; only the real-time loops and the latency figures read it.
using dds::steady_ns;

/// The start of a `plant` or `controller` process (`who` names it in messages): Ctrl-C handlers, the
/// --cpus affinity (before any DDS participant, so Cyclone's threads inherit it), then the scenario at
/// `scenario` (the built-in defaults when empty) with its vehicle replaced by the one in `vehicle` and
/// its namespace by `ns` when they are given. nullopt, after printing why, when the CPUs are refused
/// (exit 2); throws io::ConfigError for a bad file or when the scenario asks for injected faults,
/// which only the in-process transport can inject (over DDS, faults come from the network: tc netem,
/// docs/reliability.md).
/// `controller_type`, when not empty, replaces the scenario's controller.type (--controller); the
/// scenario's FMUs and Python classes are made by `resolvers`.
std::optional<io::Scenario> start_node_process(const std::string& who, const std::string& cpus,
                                               const std::string& scenario, const std::string& vehicle,
                                               const std::string& ns, const io::ScenarioResolvers& resolvers,
                                               const std::string& controller_type = "");

/// Real-time loops: lets the DDS transport deliver messages until 1 ms before `deadline_ns`
/// (steady_ns), then spins on the clock until the deadline (5 % of a core for a 20 ms period), so
/// the wake-up lands on the deadline instead of a scheduler wake-up later. The first call also asks
/// the kernel for 1 ns timer slack (default 50 us) for the blocking part.
void wait_until(dds::DdsTransport& transport, std::int64_t deadline_ns);

/// A driver's host on a DdsTransport (drivers/driver_host.hpp): the monotonic wall clock, Ctrl-C,
/// waits by spin_once, and, while a driver awaits answers, delivery on arrival through a
/// dds::ArrivalExecutor (its threading rule) that runs `on_delivery` after each delivery.
class DdsDriverHost final : public drivers::DriverHost {
 public:
  /// `precise_deadlines`: wait_until spins its last millisecond (hosts::wait_until), for the
  /// real-time controller's timer.
  explicit DdsDriverHost(dds::DdsTransport& transport, bool precise_deadlines = false)
      : transport_(transport), precise_(precise_deadlines) {}
  /// What runs after each delivery on arrival (e.g. LockstepPlantDriver::on_delivery); true wakes
  /// the waiting thread. Set it before the driver runs.
  void on_delivery(std::function<bool()> f) { on_delivery_ = std::move(f); }
  std::int64_t now_ns() override { return steady_ns(); }
  void wait(std::int64_t timeout_ns, const std::function<bool()>& woken) override;
  void wait_until(std::int64_t deadline_ns) override;
  bool stop_requested() override;
  void deliver_on_arrival(bool on) override;
  void hold_outputs(bool on) override { transport_.hold_sends(on); }
  /// Runs `blocking()` with deliveries on arrival let through (a blocking service call), or just
  /// runs it.
  template <class F>
  auto unlocked(F blocking) {
    return arrival_ ? arrival_->unlocked(std::move(blocking)) : blocking();
  }

 private:
  dds::DdsTransport& transport_;
  bool precise_;
  std::function<bool()> on_delivery_;
  std::optional<dds::ArrivalExecutor> arrival_;
};

/// The lockstep plant's diagnostic when the answer to tick k did not come within timeout_s (one
/// line, for one vehicle and a swarm's alike): the topic, the tick and its time, the matched command
/// writers, the policy.
std::string lockstep_timeout_message(const dds::DdsTransport& transport, const sim::Topics& topics,
                                     const sim::TickClock& clock, sim::Tick k, double timeout_s,
                                     const std::string& policy);

/// Real time: runs the calling thread under SCHED_FIFO at `priority` (1..99) so other processes do
/// not delay its wake-ups. Returns "" on success, else why not (e.g. no CAP_SYS_NICE): the caller
/// warns and goes on with normal scheduling. priority 0: does nothing.
std::string use_realtime_priority(int priority);

/// A CPU list as taskset and /proc write it: "1", "0,2", "0-3", "0-1,4". Fills `cpus` (sorted, no
/// repeats); returns "" or what is wrong with `text`.
std::string parse_cpu_list(const std::string& text, std::vector<int>& cpus);

/// `--cpus LIST`: runs this process on the CPUs of `list` only (sched_setaffinity on the calling
/// thread; every thread it starts afterwards, Cyclone's included, inherits it), so call it before
/// any DDS participant exists. Returns "" or what is wrong: the list, or why the kernel refused
/// (e.g. no such CPU). An empty list does nothing.
std::string use_cpus(const std::string& list);

/// The first two CPUs this process may run on (its affinity mask); empty with fewer.
std::vector<int> two_cpus();

/// `run --pin`: adds `--cpus` to the plant's (first CPU) and the controller's (second CPU) command
/// lines; with fewer than two CPUs it says so on stderr and leaves them unpinned.
void pin_apart(std::vector<std::string>& plant_args, std::vector<std::string>& controller_args);

/// Period jitter of a periodic loop: |t_k - t_k-1 - period| over every period [us].
class PeriodJitter {
 public:
  explicit PeriodJitter(std::int64_t period_ns) : period_ns_(period_ns) {}
  /// The loop's k-th wake-up time [ns].
  void add(std::int64_t now_ns);
  /// {"period_jitter_us_p50", "_p99", "_max", "periods"} (zeros before two wake-ups).
  nlohmann::json figures() const;

 private:
  std::int64_t period_ns_;
  std::int64_t last_ns_ = -1;
  std::vector<std::int64_t> jitter_ns_;
};

/// Writes `stats` as one JSON object to `path` (the --stats option of plant and controller, read by
/// `quadcosim bench`); a failure is reported on stderr, not fatal.
void write_stats(const std::string& path, const nlohmann::json& stats);

/// ROS sensor-data QoS (KEEP_LAST 5, BEST_EFFORT) on the three sensor topics.
void use_sensor_qos(dds::DdsTransport& transport, const sim::Topics& topics);

}  // namespace quadcosim::hosts
