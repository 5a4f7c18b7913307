// The plant process (`quadcosim plant`, one vehicle): the node on its DDS transport, its setup, its
// run, and what it records and reports at the end. Finding the controller is plant_pairing.cpp; the
// lockstep barrier, the schedule and the drivers are plant_lockstep.cpp.
#include "hosts/plant_process.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "hosts/plant_process_class.hpp"
#include "hosts/recording.hpp"
#include "hosts/signals.hpp"
#include "sim/sensor_wire.hpp"

namespace quadcosim::hosts {

PlantProcess::PlantProcess(const PlantProcessOptions& o, io::Scenario sc)
    : o_(o),
      sc_(std::move(sc)),
      clock_(sc_.simulation.plant.clock),
      divider_(sc_.simulation.controller_divider),
      topics_(sim::Topics::for_namespace(sc_.simulation.ns)),
      transport_(dds::read_ros_environment(o.enclave)),
      pair_token_(dds::pair_token_from_environment()),
      pairing_(transport_),
      plant_(make_plant()),
      announcer_(transport_.participant().handle(), "quadrotor_plant") {
  status_.header.stamp = msg::Time::from_ns(-1);
  plant_.set_command_filter(
      [this](const std::string& topic, sim::SenderId s) { return pairing_.accepts(topic, s) || take_over(topic, s); });
  plant_.on_early_command([this](sim::Tick k) {
    if (!ambiguous_.empty()) return;
    // The /clock of the tick before went out unheld when that tick is no control tick: a timer on ROS
    // time faster than the control rate fires on it, and its command can come while this one is held.
    const bool faster_timer = divider_ > 1;
    ambiguous_ = fmt::format(
        "the controller sent a command before tick {}'s /clock (t = {:g} s) went out: it does not publish only "
        "from a timer on ROS time at the control rate ({:g} Hz); it publishes from a subscription callback, from "
        "a wall-clock timer{}. With --sync clock such a command answers no tick, so the run stopped rather than "
        "fly a trajectory that differs from run to run. {}A controller that answers each control tick's samples "
        "runs with --sync samples; one that answers every sample needs simulation.controller_rate_hz equal to "
        "that sample rate (docs/ros2.md)",
        k, clock_.seconds(k), 1.0 / clock_.seconds(divider_),
        faster_timer ? fmt::format(", or from a timer faster than the control rate (firing on the /clock of tick "
                                   "{}, which is no control tick)",
                                   k - 1)
                     : std::string(),
        faster_timer ? "A faster timer needs simulation.controller_rate_hz set to its rate. " : "");
    request_stop();  // wakes the lockstep's wait for the answer that will not come
  });
  plant_.on_label_behind([this](std::int64_t label_ns, sim::Tick k) {
    // A timer on ROS time fires once per control tick, after the reply that says the tick's samples
    // were taken: a command labelled with older samples (the oldest it used, as a node that labels its
    // commands does) is a step on samples its executor had not yet delivered to the node.
    if (!barrier_ || !ambiguous_.empty()) return;
    ambiguous_ = fmt::format(
        "the controller stepped at tick {} (t = {:g} s) on samples of t = {:g} s (its command's label "
        "rotors@{}): its executor ran the timer before a subscription callback that held the tick's samples "
        "(a multi-threaded executor, or subscriptions in a callback group of another executor), so the run "
        "stopped rather than fly a trajectory that differs from run to run. Serve the subscriptions, the "
        "timer and the parameter services from one single-threaded executor (docs/ros2.md, \"Lockstep with "
        "your own ROS 2 controller\")",
        k, clock_.seconds(k), static_cast<double>(label_ns) * 1e-9, label_ns);
    request_stop();
  });
  RecordingOptions ro(io::RecordingOptions::for_run(sc_));
  ro.csv = o_.one_vehicle.record;
  ro.mcap = o_.one_vehicle.mcap;
  ro.foxglove = o_.foxglove;
  ro.who = "plant";
  recording_ = make_recording(ro, &transport_);
  // The controller's status is written beside each tick by what records; a plant that records nothing
  // does not read it (as a swarm's unrecorded vehicles), so the controller sends one datagram a control
  // period fewer and no tick waits for it.
  if (!recording_.empty()) {
    transport_.subscribe_with_sender<msg::ControllerStatus>(topics_.controller_status,
                                                            [this](const msg::ControllerStatus& m, sim::SenderId s) {
                                                              if (!pairing_.accepts(topics_.controller_status, s))
                                                                return;  // a stranger's says nothing of this run
                                                              status_ = m;
                                                              have_status_ = true;
                                                            });
  }
  if (!o_.one_vehicle.schedule_node.empty()) {
    scheduler_ = std::make_unique<dds::ParameterClient>(transport_.participant().handle(),
                                                        dds::parse_node_name(o_.one_vehicle.schedule_node));
  }
  next_event_ = sc_.schedule.begin();
  if (o_.lockstep) plant_.before_clock([this](sim::Tick k) { return before_clock(k); });
  // Real time: the watchdog measures how long ago a command arrived on the wall clock, so a
  // controller that dies is noticed within its limit however the ticks are paced.
  if (!o_.lockstep) plant_.use_receipt_clock(steady_ns);
  announcer_.announce();  // `ros2 node list` shows /quadrotor_plant
  std::cerr << fmt::format(
      "plant: domain {}, namespace {}, {} mode, {} ticks of {} s{}\n", transport_.participant().domain_id(),
      sc_.simulation.ns, o_.lockstep ? "lockstep" : "real-time", sc_.simulation.duration_ticks, clock_.period_s(),
      sc_.simulation.plant.external ? "; plant: " + sc_.simulation.plant.external->describe() : std::string());
}

int PlantProcess::run() {
  if ((o_.lockstep || o_.realtime.wait_for_controller) && !wait_for_controller()) return kExitNoController;
  if (o_.lockstep && !stop_requested()) {
    if (const int rc = choose_sync(); rc != kExitOk) return rc;
  }
  loop_start_ns_ = steady_ns();
  const int rc = o_.lockstep ? run_lockstep() : run_realtime();
  finish(rc);
  if (rc == kExitOk) report();
  if (rc != kExitOk) return rc;
  return stop_requested() ? kExitInterrupted : kExitOk;
}

sim::PlantNode PlantProcess::make_plant() {
  if (o_.sensor_qos) use_sensor_qos(transport_, topics_);
  if (!pair_token_.empty()) {
    transport_.set_user_data_keys(std::string(dds::kPairTokenKey) + "=" + pair_token_ + ";");
    pairing_.pair_by_token(pair_token_);
  }
  sim::PlantOptions po = sc_.simulation.plant;
  po.drop_stale_commands = o_.lockstep;
  return sim::PlantNode(transport_, topics_, sc_.vehicle, po, io::initial_state(sc_));
}

void PlantProcess::after_latch(sim::Tick k) {
  log_watchdog(k);
  record(k);
}

void PlantProcess::log_watchdog(sim::Tick k) {
  if (plant_.watchdog_active() == watchdog_logged_) return;
  watchdog_logged_ = plant_.watchdog_active();
  const double mono_s = static_cast<double>(steady_ns()) / 1e9;
  if (watchdog_logged_) {
    std::cerr << fmt::format(
        "plant: watchdog: no valid motor command for {:.3f} s (limit {:g} s) at t = {:g} s "
        "(monotonic {:.6f} s); policy {}\n",
        static_cast<double>(plant_.command_age_ns()) / 1e9, clock_.seconds(plant_.options().watchdog_ticks),
        clock_.seconds(k), mono_s, sim::to_string(plant_.options().watchdog_policy));
  } else {
    std::cerr << fmt::format("plant: watchdog: valid motor commands again at t = {:g} s (monotonic {:.6f} s)\n",
                             clock_.seconds(k), mono_s);
  }
}

void PlantProcess::record(sim::Tick k) {
  recording_.tick({k, clock_.seconds(k), clock_.ns(k), plant_.state(), plant_.latched_command(),
                   have_status_ ? &status_ : nullptr, plant_.watchdog_active()});
}

int PlantProcess::finish(int code) {
  // Delivery on arrival ended with the driver's run: what is still in the readers is taken below.
  if (recording_.mcap() && code == kExitOk) {
    // What is still in the readers. In lockstep, also what is still arriving: the delivery that
    // answered the last tick may have ended the run before Cyclone put the same sample into the
    // recorder's own reader, so wait for a 20 ms lull (at most 200 ms), or the recording could
    // miss the last command or status under load.
    const std::int64_t lull_ns = o_.lockstep ? 20'000'000 : 0, until = steady_ns() + 200'000'000;
    while (transport_.spin_once(lull_ns) > 0 && steady_ns() < until) {
    }
  }
  recording_.finish(code == kExitOk);  // run.mcap's metadata.yaml only for a completed run
  return code;
}

void PlantProcess::report() {
  nlohmann::json stats;
  // lockstep: sensor publication -> command back, percentiles within 1.6 % (util/log_histogram.hpp)
  if (lockstep_ && !lockstep_->round_trips_ns().empty()) {
    const util::LogHistogram& round_trip_ns = lockstep_->round_trips_ns();
    auto pct = [&](double q) { return static_cast<double>(round_trip_ns.percentile_lower(q)) / 1e3; };
    std::cerr << fmt::format(
        "plant: lockstep round trip (outputs published -> command received) over {} "
        "control periods: p50 {:.1f} us, p99 {:.1f} us, max {:.1f} us\n",
        round_trip_ns.count(), pct(0.5), pct(0.99), pct(1.0));
    stats["roundtrip_us_p50"] = pct(0.5);
    stats["roundtrip_us_p99"] = pct(0.99);
    stats["roundtrip_us_max"] = pct(1.0);
  }
  const auto& st = plant_.stats();
  const double wall_s = static_cast<double>(steady_ns() - loop_start_ns_) / 1e9;
  // The simulated time reached, not the time asked for: a run stopped early (Ctrl-C) integrated
  // only the ticks it completed.
  const sim::Tick asked = sc_.simulation.duration_ticks;
  const sim::Tick completed = realtime_ ? realtime_->ticks_run() : lockstep_ ? lockstep_->ticks_run() : asked;
  const double sim_s = clock_.seconds(std::min(completed, asked));
  std::cerr << fmt::format(
      "plant: done; {:g} s simulated in {:.3f} s ({:.1f}x real time); commands received {}, "
      "rejected {}, clamped {}, stale {}; foreign (not the controller's writers) {}; on a second topic {}\n",
      sim_s, wall_s, sim_s / wall_s, st.commands_received, st.commands_rejected, st.commands_clamped, st.commands_stale,
      st.commands_foreign, st.commands_rejected_second_topic);
  std::cerr << fmt::format("plant: watchdog ({:g} s, policy {}) took over {} times for {} ticks\n",
                           clock_.seconds(plant_.options().watchdog_ticks),
                           sim::to_string(plant_.options().watchdog_policy), st.watchdog_trips, st.watchdog_ticks);
  if (realtime_) {
    std::cerr << fmt::format(
        "plant: real-time pacing: {} ticks in {:.3f} s wall ({:.1f} ticks/s), max lateness "
        "{:.1f} ms, {} ticks more than one period late\n",
        realtime_->ticks_run(), wall_s, static_cast<double>(realtime_->ticks_run()) / wall_s,
        static_cast<double>(realtime_->max_late_ns()) / 1e6, realtime_->late_ticks());
  }
  stats["simulated_s"] = sim_s;
  stats["wall_s"] = wall_s;
  stats["real_time_factor"] = sim_s / wall_s;
  if (!o_.stats.empty()) write_stats(o_.stats, stats);
}

int run_plant_process(const PlantProcessOptions& o, io::Scenario sc) {
  PlantProcess process(o, std::move(sc));
  return process.run();
}

}  // namespace quadcosim::hosts
