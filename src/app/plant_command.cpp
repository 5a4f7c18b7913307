// `quadcosim plant`: the plant node as a long-running process over DDS, in lockstep (deterministic,
// as fast as plant and controller can go) or in real time (paced by the wall clock).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/foxglove_cli.hpp"
#include "app/swarm.hpp"
#include "dds/dds_transport.hpp"
#include "dds/graph.hpp"
#include "dds/node_announcer.hpp"
#include "dds/parameter_client.hpp"
#include "dds/peer_pairing.hpp"
#include "drivers/lockstep_plant_driver.hpp"
#include "drivers/realtime_plant_driver.hpp"
#include "hosts/node_common.hpp"
#include "hosts/parameter_binding.hpp"
#include "hosts/signals.hpp"
#include "io/mcap_recorder.hpp"
#include "io/scenario.hpp"
#include "io/trajectory_csv.hpp"
#include "sim/plant_node.hpp"
#include "sim/sensor_wire.hpp"
#include "sim/topics.hpp"

namespace quadcosim::app {

namespace {

/// Exit codes of `plant` (docs/cosimulation.md).
constexpr int kExitOk = exit_code::kOk, kExitRefused = exit_code::kBadInput, kExitNoController = exit_code::kNoPeer,
              kExitInterrupted = exit_code::kInterrupted;

/// One plant process: the node on its DDS transport, what it records, and the driver that advances
/// it (lockstep or real time). Construction does all the setup; run() runs the driver.
class PlantProcess {
 public:
  PlantProcess(const PlantCommandOptions& o, io::Scenario sc)
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
        [this](sim::SenderId s) { return pairing_.accepts(topics_.motor_commands, s) || take_over(s); });
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
      hosts::request_stop();  // wakes the lockstep's wait for the answer that will not come
    });
    transport_.subscribe_with_sender<msg::ControllerStatus>(topics_.controller_status,
                                                            [this](const msg::ControllerStatus& m, sim::SenderId s) {
                                                              if (!pairing_.accepts(topics_.controller_status, s))
                                                                return;  // a stranger's says nothing of this run
                                                              status_ = m;
                                                              have_status_ = true;
                                                            });
    if (!o_.one_vehicle.record.empty()) csv_ = std::make_unique<io::TrajectoryWriter>(o_.one_vehicle.record);
    if (!o_.one_vehicle.mcap.empty()) {
      mcap_ = std::make_unique<io::McapRecorder>(o_.one_vehicle.mcap, transport_, topics_);
      if (sc_.simulation.plant.publish_tf) mcap_->record_vehicle(sc_.vehicle, sc_.simulation.ns, clock_.ns(0));
      mcap_->record_sensors(transport_, sc_.simulation.ns, sc_.simulation.plant.realism.extra_sensors);
    }
    foxglove_ = hosts::start_foxglove(o_.foxglove, "plant", transport_, topics_, sc_);
    if (!o_.one_vehicle.schedule_node.empty()) {
      scheduler_ = std::make_unique<dds::ParameterClient>(transport_.participant().handle(),
                                                          dds::parse_node_name(o_.one_vehicle.schedule_node));
    }
    next_event_ = sc_.schedule.begin();
    if (o_.lockstep) plant_.before_clock([this](sim::Tick k) { return before_clock(k); });
    // Real time: the watchdog measures how long ago a command arrived on the wall clock, so a
    // controller that dies is noticed within its limit however the ticks are paced.
    if (!o_.lockstep) plant_.use_receipt_clock(hosts::steady_ns);
    announcer_.announce();  // `ros2 node list` shows /quadrotor_plant
    std::cerr << fmt::format(
        "plant: domain {}, namespace {}, {} mode, {} ticks of {} s{}\n", transport_.participant().domain_id(),
        sc_.simulation.ns, o_.lockstep ? "lockstep" : "real-time", sc_.simulation.duration_ticks, clock_.period_s(),
        sc_.simulation.plant.external ? "; plant: " + sc_.simulation.plant.external->describe() : std::string());
  }

  /// Runs every tick; returns the process's exit code.
  int run() {
    if ((o_.lockstep || o_.realtime.wait_for_controller) && !wait_for_controller()) return kExitNoController;
    if (o_.lockstep && !hosts::stop_requested()) {
      if (const int rc = choose_sync(); rc != kExitOk) return rc;
    }
    loop_start_ns_ = hosts::steady_ns();
    const int rc = o_.lockstep ? run_lockstep() : run_realtime();
    finish(rc);
    if (rc == kExitOk) report();
    if (foxglove_) hosts::finish_foxglove(o_.foxglove, "plant", *foxglove_);
    if (rc != kExitOk) return rc;
    return hosts::stop_requested() ? kExitInterrupted : kExitOk;
  }

 private:
  sim::PlantNode make_plant() {
    if (o_.sensor_qos) hosts::use_sensor_qos(transport_, topics_);
    if (!pair_token_.empty()) {
      transport_.set_user_data_keys(std::string(dds::kPairTokenKey) + "=" + pair_token_ + ";");
      pairing_.pair_by_token(pair_token_);
    }
    sim::PlantOptions po = sc_.simulation.plant;
    po.drop_stale_commands = o_.lockstep;
    return sim::PlantNode(transport_, topics_, sc_.vehicle, po, io::initial_state(sc_));
  }

  /// Readers of this process's own on each topic (the recorder's, the Foxglove server's): matched
  /// counts include them.
  int own_readers() const { return (mcap_ ? 1 : 0) + (foxglove_ ? 1 : 0); }

  using Guid = std::array<std::uint8_t, 16>;

  static std::string hex(const Guid& g) {
    std::string s;
    for (std::uint8_t b : g) s += fmt::format("{:02x}", b);
    return s;
  }

  /// The participants whose writers of the motor commands may be the controller's: with a pairing
  /// token, those whose writers carry it; otherwise those whose writers carry no token (a token means
  /// the controller of another quadcosim run) and, with --controller-node, only the node's own.
  std::vector<Guid> controller_candidates() const {
    std::vector<Guid> found;
    for (const sim::SenderId s : transport_.matched_senders(topics_.motor_commands)) {
      const auto info = transport_.sender_info(topics_.motor_commands, s);
      if (!info) continue;
      if (pair_token_.empty() ? !info->pair_token.empty() : info->pair_token != pair_token_) continue;
      if (node_participant_ && info->participant != *node_participant_) continue;
      if (std::find(found.begin(), found.end(), info->participant) == found.end()) found.push_back(info->participant);
    }
    return found;
  }

  /// The topics of every sensor the plant publishes: Pose, Velocity, Imu, then the extra sensors'.
  std::vector<std::string> sensor_topics() const {
    std::vector<std::string> all{topics_.pose, topics_.velocity, topics_.imu};
    sim::for_each_sensor_topic(sc_.simulation.plant.realism.extra_sensors, topics_.ns,
                               [&]<class>(const std::string& topic) { all.push_back(topic); });
    return all;
  }

  /// Which of the sensor topics `peer` subscribes (readers matched by ours).
  std::vector<std::string> sensors_subscribed_by(const Guid& peer) const {
    std::vector<std::string> out;
    for (const std::string& t : sensor_topics()) {
      const auto parts = transport_.matched_reader_participants(t);
      if (std::find(parts.begin(), parts.end(), peer) != parts.end()) out.push_back(t);
    }
    return out;
  }

  /// Finds the controller, pairs with its writers (dds/peer_pairing.hpp: only its commands are
  /// answers; every other writer's are counted as foreign and ignored) and waits until it subscribes
  /// the sensors it needs (any of Pose, Velocity, Imu: what its participant's readers ask for), so
  /// tick 0 is not published into the void. False, with the reason on stderr, when none comes within
  /// the timeout or the controller is ambiguous (several participants could be it).
  bool wait_for_controller() {
    const std::string& node = o_.lockstep_only.controller_node;
    if (pair_token_.empty() && !node.empty() && !find_node_participant(node)) return false;
    // Discovery of one participant's endpoints arrives close together but not at once: once the
    // controller subscribes one sensor, the others it subscribes have this long to show up.
    constexpr std::int64_t kSettleNs = 300'000'000;
    std::optional<Guid> peer;
    std::vector<std::string> sensors;
    std::int64_t settled_at = 0;
    bool ambiguous = false;
    const std::size_t all_sensors = sensor_topics().size();
    const bool found = transport_.spin_until(
        [&] {
          if (hosts::stop_requested()) return true;
          const std::vector<Guid> candidates = controller_candidates();
          if (candidates.size() > 1 && pair_token_.empty()) {
            ambiguous = true;
            std::string list;
            for (const Guid& g : candidates) list += " " + hex(g);
            std::cerr << fmt::format(
                "plant: {} participants publish {} and could be the controller:{}; a stranger or a controller "
                "left over from an earlier run? End it, use another ROS_DOMAIN_ID, or name the controller's node "
                "with --controller-node\n",
                candidates.size(), topics_.motor_commands, list);
            return true;
          }
          if (candidates.empty()) return false;
          peer = candidates.front();
          const std::vector<std::string> now = sensors_subscribed_by(*peer);
          if (now.size() != sensors.size()) settled_at = hosts::steady_ns() + kSettleNs;
          sensors = now;
          // The run's own controller (a token) publishes its status, which tick 0's answer includes:
          // matched too, or tick 0 would be taken without it.
          if (!pair_token_.empty() && !controller_writes_status()) return false;
          return sensors.size() == all_sensors || (!sensors.empty() && hosts::steady_ns() >= settled_at);
        },
        timeout_ns());
    if (ambiguous) return false;
    if (!found) {
      std::string subscribed;
      for (const std::string& t : sensors) subscribed += (subscribed.empty() ? "" : ", ") + t;
      std::cerr << fmt::format("plant: no controller on {} within {} s: {}; is it running on ROS_DOMAIN_ID {}?\n",
                               topics_.motor_commands, o_.timeout_s,
                               !peer ? fmt::format("no {}writer of {} is matched{}",
                                                   pair_token_.empty() ? "" : "paired ", topics_.motor_commands,
                                                   transport_.matched_writers(topics_.motor_commands) > 0
                                                       ? fmt::format(" ({} writers of other runs or nodes are)",
                                                                     transport_.matched_writers(topics_.motor_commands))
                                                       : "")
                                     : fmt::format("participant {} publishes it but subscribes none of {}, {}, {}",
                                                   hex(*peer), topics_.pose, topics_.velocity, topics_.imu),
                               transport_.participant().domain_id());
      return false;
    }
    if (!peer) return true;  // stopped
    peer_ = peer;
    if (pair_token_.empty()) pairing_.pair_by_participant(*peer);
    if (scheduler_) scheduler_->only_from(*peer);  // the schedule goes to the controller's node, not a namesake
    subscribed_ = sensors;
    if (sensors.size() < all_sensors) {
      std::string list;
      for (const std::string& t : sensors) list += (list.empty() ? "" : ", ") + t;
      std::cerr << fmt::format("plant: the controller subscribes {} only; the other sensor samples go to no one\n",
                               list);
    }
    return true;
  }

  /// A controller that was restarted (killed, started again: the paper's stale-data scenario) is a
  /// new participant. Without a token it may take over from the paired one, but only once the
  /// watchdog holds (the paired controller has been silent past its limit: it is gone as far as the
  /// vehicle is concerned), only when it carries no token, and only when it is the one participant
  /// besides the old one that could be the controller. So a stranger cannot take over from a
  /// controller that is alive, nor two newcomers race. True when `s` is now the controller's.
  bool take_over(sim::SenderId s) {
    if (!pair_token_.empty() || !peer_ || !plant_.watchdog_active()) return false;
    const auto info = transport_.sender_info(topics_.motor_commands, s);
    if (!info || !info->pair_token.empty() || info->participant == *peer_) return false;
    if (node_participant_) return false;  // --controller-node names one participant, the one found at the start
    std::vector<Guid> others = controller_candidates();
    std::erase(others, *peer_);
    if (others.size() != 1 || others.front() != info->participant) return false;
    std::cerr << fmt::format(
        "plant: the controller's participant {} has been silent past the watchdog's limit; participant {} "
        "publishes {} now and is taken as the controller\n",
        hex(*peer_), hex(info->participant), topics_.motor_commands);
    peer_ = info->participant;
    pairing_.pair_by_participant(*peer_);
    status_writers_seen_ = -1;  // whose statuses count changed with the controller
    if (scheduler_) scheduler_->only_from(*peer_);
    return true;
  }

  /// --controller-node without a pairing token: the participant hosting that node's parameter
  /// services is the controller's. False, with the reason on stderr, when it is not found in time.
  bool find_node_participant(const std::string& node) {
    const std::string request = "rq" + node + "/get_parametersRequest";
    std::optional<Guid> found;
    host_.unlocked([&] {
      dds::discover_endpoints(transport_.participant().handle(), timeout_ns(), [&](const auto& endpoints) {
        for (const dds::Endpoint& e : endpoints) {
          if (!e.writer && e.dds_topic == request) found = e.participant;
        }
        return found.has_value() || hosts::stop_requested();
      });
      return 0;
    });
    if (!found) {
      std::cerr << fmt::format("plant: --controller-node {}: no such node (no reader of {}) within {} s\n", node,
                               request, o_.timeout_s);
      return false;
    }
    node_participant_ = found;
    return true;
  }

  /// Lockstep: how the controller steps (--sync). A controller that steps on each control tick's
  /// samples needs nothing more. One that steps from a timer on ROS time (an rclcpp or rclpy node
  /// with use_sim_time) reads whatever samples its subscriptions took when /clock makes the timer
  /// due, and first answers one control period in; for it every tick sends its samples, then a
  /// get_parameters request to its node, and a control tick's /clock waits for the reply (its
  /// executor serves services after the subscriptions that were ready in the same wait, so the reply
  /// means the samples are taken: before_clock; docs/ros2.md, "Lockstep with your own ROS 2
  /// controller").
  int choose_sync() {
    const std::string& sync = o_.lockstep_only.sync;
    if (sync == "samples" || (sync == "auto" && o_.clock_after_sensors)) return kExitOk;
    const bool required = sync == "clock";
    auto fallback = [&](const std::string& why) {
      if (required) {
        std::cerr << fmt::format("plant: --sync clock: {}\n", why);
        return kExitNoController;
      }
      std::cerr << fmt::format("plant: lockstep: the controller steps on the samples ({})\n", why);
      return kExitOk;
    };
    std::string node = o_.lockstep_only.controller_node;
    if (node.empty()) {
      // The node is in the process that publishes the commands: the one with parameter services there.
      std::vector<std::string> nodes;
      const std::int64_t wait_ns = required ? timeout_ns() : std::min<std::int64_t>(timeout_ns(), 500'000'000);
      host_.unlocked([&] {
        return dds::discover_endpoints(transport_.participant().handle(), wait_ns, [&](const auto& endpoints) {
          // The controller's own participant only: a stranger's nodes are not asked.
          std::vector<dds::Endpoint> own;
          for (const dds::Endpoint& e : endpoints) {
            if (!peer_ || e.participant == *peer_) own.push_back(e);
          }
          nodes = dds::parameter_nodes_writing(own, topics_.motor_commands);
          return !nodes.empty();
        });
      });
      if (nodes.size() != 1) {
        std::string names;
        for (const auto& n : nodes) names += (names.empty() ? "" : ", ") + n;
        return fallback(nodes.empty()
                            ? fmt::format("no node with parameter services publishes {}", topics_.motor_commands)
                            : fmt::format("the process publishing {} has several nodes ({}); name one "
                                          "with --controller-node",
                                          topics_.motor_commands, names));
      }
      node = nodes.front();
    }
    auto client = std::make_unique<dds::ParameterClient>(transport_.participant().handle(), dds::parse_node_name(node));
    if (peer_) client->only_from(*peer_);  // the controller's node, not a namesake's
    std::vector<dds::ParamValue> v;
    try {
      v = host_.unlocked([&] { return client->get({"use_sim_time"}, timeout_ns()); });
    } catch (const dds::ParameterCallError& e) {
      return fallback(e.what());
    }
    const bool sim_time = v.size() == 1 && v[0].type == dds::ParamType::kBool && v[0].bool_value;
    if (!sim_time) {
      const bool declared = v.size() == 1 && v[0].type != dds::ParamType::kNotSet;
      if (declared && !required) {
        std::cerr << fmt::format(
            "plant: warning: {} has use_sim_time false: if it steps from a timer, that timer runs on the wall "
            "clock and lockstep cannot drive it; run it with --ros-args -p use_sim_time:=true\n",
            node);
      }
      return fallback(fmt::format("{} has {}", node, declared ? "use_sim_time false" : "no use_sim_time parameter"));
    }
    // The timer's /clock subscription must be there too, or its first /clock is lost.
    const int own = own_readers();
    if (!transport_.spin_until(
            [&] { return hosts::stop_requested() || transport_.matched_readers(topics_.clock) > own; }, timeout_ns())) {
      std::cerr << fmt::format("plant: {} does not subscribe {} within {} s\n", node, topics_.clock, o_.timeout_s);
      return kExitNoController;
    }
    barrier_ = std::move(client);
    // The reply is delivered like a command (on arrival, on the receiving thread): it releases the
    // tick's /clock there, so a control period wakes no other thread of this process.
    const dds_entity_t replies = barrier_->get_reply_reader();
    transport_.subscribe_raw_with_sender(
        replies, "get_parameters reply from " + node, [this, replies](const void* reply, sim::SenderId from) {
          if (clock_held_ >= 0 && dds::ParameterClient::is_reply_to(reply, barrier_request_) &&
              barrier_->from_peer(replies, from)) {
            clock_released_ = std::exchange(clock_held_, -1);
            plant_.publish_clock(clock_released_);
          }
        });
    plant_.set_clock_after_sensors(true);
    std::cerr << fmt::format(
        "plant: lockstep with {} on ROS time: every tick sends its samples, then a get_parameters request; a "
        "control tick's /clock waits for the reply; the first command is expected at t = {:g} s\n",
        node, clock_.seconds(divider_));
    return kExitOk;
  }

  /// Between tick k's samples and its /clock (when /clock goes last); false holds the /clock back.
  bool before_clock(sim::Tick k) {
    if (k == 0 && !samples_acknowledged_) {
      // A peer that steps on /clock reads whatever samples it holds then. Matched on our side does
      // not mean it has discovered our writers: its readers may still drop tick 0's samples while a
      // /clock gets through. So tick 0's /clock waits until the samples are acknowledged (on the main
      // thread, where tick 0 is published; deliveries go on meanwhile). Later ticks rely on in-order
      // delivery (docs/simulink.md).
      samples_acknowledged_ = host_.unlocked([this] {
        for (const std::string& t : subscribed_) {
          if (!transport_.wait_for_acks(t, timeout_ns())) return false;
        }
        return true;
      });
      if (!samples_acknowledged_) {
        std::cerr << fmt::format("plant: warning: tick 0's samples not acknowledged within {} s\n", o_.timeout_s);
      }
    }
    if (!barrier_) return true;
    // A request after every tick's samples, answered in order, one per executor wait (rclcpp and
    // rclpy take one request per service, and one sample per ready subscription, per wait): the reply
    // to tick k's request means every sample up to tick k has been taken, however many ticks'
    // samples were queued. A control tick's /clock waits for that reply.
    const auto request = barrier_->send_get({});
    if (k < divider_ || k % divider_ != 0) return true;
    // The tick published again (its answer is slow: the lockstep's retry) after its /clock went out: the
    // controller may have stepped already and its command be on its way, so the /clock goes out again
    // at once. Held again, that command would arrive while the /clock is held, and be taken for one
    // that answers no tick.
    if (k == clock_released_) return true;
    barrier_request_ = request;
    clock_held_ = k;
    return false;  // the reply's delivery publishes tick k's /clock
  }

  /// The schedule through the controller's parameter services: each change due by tick k is
  /// acknowledged before tick k is published, so the run stays deterministic. False when refused.
  bool apply_due_schedule(sim::Tick k) {
    for (; scheduler_ && next_event_ != sc_.schedule.end() && next_event_->tick <= k; ++next_event_) {
      // The reply comes through Cyclone's receive thread: let deliveries on arrival through meanwhile.
      const auto r = host_.unlocked([&] {
        return scheduler_->set({{next_event_->name, hosts::to_ros(next_event_->value)}}, timeout_ns());
      });
      if (r.size() != 1 || !r[0].successful) {
        std::cerr << fmt::format("plant: scheduled {} at t = {} s refused by {}: {}\n", next_event_->name,
                                 clock_.seconds(k), o_.one_vehicle.schedule_node,
                                 r.empty() ? "no result" : r[0].reason);
        return false;
      }
    }
    return true;
  }

  /// Real time: each tick published, paced by the wall clock, then completed
  /// (drivers::RealtimePlantDriver).
  int run_realtime() {
    drivers::RealtimeOptions ro;
    ro.clock = clock_;
    ro.duration_ticks = sc_.simulation.duration_ticks;
    ro.rate_factor = o_.realtime.rate_factor;
    drivers::RealtimeHooks h;
    h.before_outputs = [this](sim::Tick k) { return apply_due_schedule(k); };
    h.after_latch = [this](std::size_t, sim::Tick k) { after_latch(k); };
    realtime_.emplace(std::vector<sim::SteppablePlant*>{&plant_}, ro, std::move(h), host_);
    return realtime_->run() == drivers::RealtimeResult::kRefused ? kExitRefused : kExitOk;
  }

  /// Lockstep (drivers::LockstepPlantDriver): commands and statuses are delivered on arrival (on
  /// Cyclone's receive thread), and the delivery that completes the awaited tick's answer runs the
  /// ticks that follow right there, up to the next control tick's publication: a control period
  /// wakes no thread of this process but the receive thread. The main thread is woken for what
  /// needs it: a scheduled change through the parameter services (a blocking request), a timeout,
  /// the hold policy's unpaced ticks, the end.
  int run_lockstep() {
    drivers::LockstepOptions lo;
    lo.clock = clock_;
    lo.duration_ticks = sc_.simulation.duration_ticks;
    lo.controller_divider = divider_;
    if (barrier_) lo.first_control_tick = divider_;  // a ROS-time timer first fires one period after it starts
    lo.timeout_ns = timeout_ns();
    lo.on_timeout =
        o_.lockstep_only.on_timeout == "hold" ? drivers::TimeoutPolicy::kHold : drivers::TimeoutPolicy::kAbort;
    drivers::DrivenPlant p{&plant_, [this] { return controller_writes_status(); },
                           [this] { return status_.header.stamp.to_ns(); }};
    drivers::LockstepHooks h;
    h.main_thread_due = [this](sim::Tick k) { return schedule_due(k); };
    h.before_outputs = [this](sim::Tick k) { return ambiguous_.empty() && apply_due_schedule(k); };
    h.after_latch = [this](std::size_t, sim::Tick k) {
      after_latch(k);
      check_one_answer_per_period(k);
    };
    h.on_timeout = [this](std::size_t, sim::Tick k) {
      std::cerr << hosts::lockstep_timeout_message(transport_, topics_, clock_, k, o_.timeout_s,
                                                   o_.lockstep_only.on_timeout);
      if (!barrier_) return;
      const double period_s = clock_.seconds(divider_);
      std::cerr << (clock_held_ == k
                        ? fmt::format("plant: the controller's node has not answered tick {}'s get_parameters request, "
                                      "so its /clock was held back: is its executor blocked?\n",
                                      k)
                        : fmt::format("plant: tick {}'s /clock went out but no command followed: the controller's "
                                      "timer must fire every {:g} s on ROS time (the scenario's controller_rate_hz "
                                      "{:g}), first at t = {:g} s\n",
                                      k, period_s, 1.0 / period_s, period_s));
    };
    h.on_resume = [](sim::Tick k) {
      std::cerr << fmt::format("plant: commands are back at tick {}; lockstep resumes\n", k);
    };
    lockstep_.emplace(std::vector<drivers::DrivenPlant>{std::move(p)}, lo, std::move(h), host_);
    host_.on_delivery([this] { return lockstep_->on_delivery(); });
    const drivers::LockstepResult r = lockstep_->run();
    host_.on_delivery(nullptr);
    if (!ambiguous_.empty()) {
      std::cerr << "plant: " << ambiguous_ << '\n';
      return kExitNoController;
    }
    if (r == drivers::LockstepResult::kRefused) return kExitRefused;
    if (r == drivers::LockstepResult::kTimedOut) return kExitNoController;
    return r == drivers::LockstepResult::kDone && !hosts::stop_requested() ? check_answer_count() : kExitOk;
  }

  /// Lockstep matches an unlabelled command to the tick being awaited when it is delivered. A
  /// controller that sends more commands than it was asked for (one per sensor sample, or again when
  /// a tick's samples were published twice) leaves the surplus queued, and each later tick then takes
  /// an answer to an earlier one: the per-period count cannot see this, the total can. So once the
  /// last tick ran and what is still arriving came in (a 20 ms lull, at most 200 ms), more commands
  /// than control periods (one may answer the final samples) stop the run's success.
  int check_answer_count() {
    const std::int64_t until = hosts::steady_ns() + 200'000'000;
    while (transport_.spin_once(20'000'000) > 0 && hosts::steady_ns() < until) {
    }
    const std::uint64_t periods = lockstep_->round_trips_ns().count();
    const std::uint64_t answers = plant_.command_receipt().received;
    if (answers <= periods + 1) return kExitOk;
    std::cerr << fmt::format(
        "plant: the controller sent {} commands for {} control periods, where lockstep expects one each: it "
        "publishes more than once per control period (e.g. answering every Pose, Velocity or Imu sample), so "
        "every command after the first surplus one was taken as the answer to a later tick than the one it "
        "answered, and this run's trajectory depends on timing. Publish once per control period, label each "
        "command with its tick (docs/ros2.md, \"Lockstep with your own ROS 2 controller\"), or set "
        "simulation.controller_rate_hz to the rate it publishes at\n",
        answers, periods);
    return kExitNoController;
  }

  /// What follows tick k's latch, before the plant integrates: log, record.
  /// The paired controller publishes its status (so a control tick's answer includes it).
  /// Asked once per control tick: the writers are looked at again only when their count changed (a
  /// status read costs tens of instructions, the matched writers' list about 1,400 per tick).
  bool controller_writes_status() {
    const int writers = transport_.matched_writers(topics_.controller_status);
    if (writers == status_writers_seen_) return status_from_controller_;
    status_from_controller_ = false;
    bool described = true;  // a writer discovery cannot describe yet is looked at again next time
    for (const sim::SenderId s : transport_.matched_senders(topics_.controller_status)) {
      if (pairing_.accepts(topics_.controller_status, s)) {
        status_from_controller_ = true;
      } else if (!transport_.sender_info(topics_.controller_status, s)) {
        described = false;
      }
    }
    status_writers_seen_ = described || status_from_controller_ ? writers : -1;
    return status_from_controller_;
  }

  /// Lockstep: the controller answers each control tick once. A second command within one control
  /// period cannot be matched to a tick (it would be latched by its arrival time: not deterministic),
  /// so the run stops at the first one, saying what the controller must change.
  void check_one_answer_per_period(sim::Tick k) {
    if (k % divider_ != 0 || k < (barrier_ ? divider_ : 0)) return;
    const sim::CommandReceipt r = plant_.command_receipt();
    const std::uint64_t answers = r.received - answers_at_last_control_;
    answers_at_last_control_ = r.received;
    if (answers <= 1 || !ambiguous_.empty()) return;
    ambiguous_ = fmt::format(
        "the controller sent {} commands in the control period ending at t = {:g} s, where lockstep expects one: it "
        "publishes faster than the scenario's controller_rate_hz ({:g}), e.g. {}. Which tick such a command answers "
        "depends on when it arrives, so the run stopped rather than fly a trajectory that differs from run to run. "
        "Publish once per control period, or set simulation.controller_rate_hz to the rate it publishes at "
        "(docs/ros2.md, \"Lockstep with your own ROS 2 controller\")",
        answers, clock_.seconds(k), 1.0 / clock_.seconds(divider_),
        barrier_ ? "from a timer faster than that rate" : "answering every Pose, Velocity or Imu sample");
    hosts::request_stop();
  }

  void after_latch(sim::Tick k) {
    log_watchdog(k);
    record(k);
    if (mcap_) mcap_->flush_settled(clock_.ns(k));
  }

  bool schedule_due(sim::Tick k) const {
    return scheduler_ && next_event_ != sc_.schedule.end() && next_event_->tick <= k;
  }

  /// The watchdog's changes as events on stderr (simulated time, and the monotonic wall clock).
  void log_watchdog(sim::Tick k) {
    if (plant_.watchdog_active() == watchdog_logged_) return;
    watchdog_logged_ = plant_.watchdog_active();
    const double mono_s = static_cast<double>(hosts::steady_ns()) / 1e9;
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

  void record(sim::Tick k) {
    if (!csv_) return;
    csv_->write(clock_.seconds(k), plant_.state(), plant_.latched_command(),
                have_status_ ? io::ControlColumns::from(status_) : io::ControlColumns::none(),
                plant_.watchdog_active());
  }

  /// Completes the recordings (also on the error paths, so what was recorded is readable).
  int finish(int code) {
    // Delivery on arrival ended with the driver's run: what is still in the readers is taken below.
    if (csv_) csv_->close();
    if (mcap_ && code == kExitOk) {
      // What is still in the readers. In lockstep, also what is still arriving: the delivery that
      // answered the last tick may have ended the run before Cyclone put the same sample into the
      // recorder's own reader, so wait for a 20 ms lull (at most 200 ms), or the recording could
      // miss the last command or status under load.
      const std::int64_t lull_ns = o_.lockstep ? 20'000'000 : 0, until = hosts::steady_ns() + 200'000'000;
      while (transport_.spin_once(lull_ns) > 0 && hosts::steady_ns() < until) {
      }
      mcap_->close();
      const std::filesystem::path p(o_.one_vehicle.mcap);
      mcap_->write_bag_metadata(p.parent_path().empty() ? "." : p.parent_path().string(), p.filename().string());
    }
    return code;
  }

  void report() {
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
    const double wall_s = static_cast<double>(hosts::steady_ns() - loop_start_ns_) / 1e9;
    // The simulated time reached, not the time asked for: a run stopped early (Ctrl-C) integrated
    // only the ticks it completed.
    const sim::Tick asked = sc_.simulation.duration_ticks;
    const sim::Tick completed = realtime_ ? realtime_->ticks_run() : lockstep_ ? lockstep_->ticks_run() : asked;
    const double sim_s = clock_.seconds(std::min(completed, asked));
    std::cerr << fmt::format(
        "plant: done; {:g} s simulated in {:.3f} s ({:.1f}x real time); commands received {}, "
        "rejected {}, clamped {}, stale {}; foreign (not the controller's writers) {}\n",
        sim_s, wall_s, sim_s / wall_s, st.commands_received, st.commands_rejected, st.commands_clamped,
        st.commands_stale, st.commands_foreign);
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
    if (!o_.stats.empty()) hosts::write_stats(o_.stats, stats);
  }

  std::int64_t timeout_ns() const { return static_cast<std::int64_t>(o_.timeout_s * 1e9); }

  const PlantCommandOptions& o_;
  io::Scenario sc_;
  sim::TickClock clock_;
  int divider_;
  sim::Topics topics_;
  dds::DdsTransport transport_;
  std::string pair_token_;   ///< $QUADCOSIM_PAIR_TOKEN: the controller's writers carry it (run --transport dds)
  dds::PeerFilter pairing_;  ///< whose commands are the controller's (set by wait_for_controller)
  std::optional<std::array<std::uint8_t, 16>> node_participant_;  ///< --controller-node's participant
  std::optional<std::array<std::uint8_t, 16>> peer_;              ///< the controller's participant
  int status_writers_seen_ = -1;  ///< matched ControllerStatus writers when status_from_controller_ was found
  bool status_from_controller_ = false;
  sim::PlantNode plant_;
  dds::NodeAnnouncer announcer_;
  msg::ControllerStatus status_;
  bool have_status_ = false;
  std::unique_ptr<io::TrajectoryWriter> csv_;
  std::unique_ptr<io::McapRecorder> mcap_;
  // Served from the transport's deliveries, like the recorder; stopped at the end of run().
  std::unique_ptr<foxglove::Server> foxglove_;
  std::unique_ptr<dds::ParameterClient> scheduler_;
  std::vector<sim::ScheduledParameter>::const_iterator next_event_;
  bool watchdog_logged_ = false;
  std::vector<std::string> subscribed_;  ///< the sensor topics the controller subscribes (wait_for_controller)
  bool samples_acknowledged_ = false;    ///< /clock last: tick 0's samples reached the peer
  std::unique_ptr<dds::ParameterClient> barrier_;  ///< --sync clock: the controller node's parameter client
  dds::ParameterClient::Header barrier_request_;   ///< the last barrier request sent
  sim::Tick clock_held_ = -1;                      ///< the tick whose /clock awaits the barrier reply
  sim::Tick clock_released_ = -1;                  ///< the last tick whose held /clock went out
  std::uint64_t answers_at_last_control_ = 0;      ///< the plant's command receipts at the last control tick
  std::string ambiguous_;  ///< why the controller's answers cannot be matched to ticks ("": they can)
  std::int64_t loop_start_ns_ = 0;
  // Last: the drivers and their host (with delivery on arrival) go first.
  hosts::DdsDriverHost host_{transport_};
  std::optional<drivers::LockstepPlantDriver> lockstep_;
  std::optional<drivers::RealtimePlantDriver> realtime_;
};

}  // namespace

CLI::App* add_plant_subcommand(CLI::App& app, PlantCommandOptions& plant) {
  auto* plant_cmd = app.add_subcommand("plant", "the plant as a ROS 2 node over DDS (until done or Ctrl-C)");
  plant_cmd->add_option("--scenario", plant.scenario, "scenario YAML (vehicle, rates, duration, initial state)")
      ->check(CLI::ExistingFile);
  plant_cmd->add_option("--vehicle", plant.vehicle, "vehicle YAML (replaces the scenario's vehicle)")
      ->check(CLI::ExistingFile);
  plant_cmd
      ->add_option("--fmu", plant.fmu,
                   "fly this co-simulation FMU as the plant, its variables by their default names "
                   "(replaces the scenario's plant; docs/fmi.md)")
      ->check(CLI::ExistingPath);
  add_node_host_options(plant_cmd, plant.ns, plant.swarm, plant.sensor_qos,
                        "publish Pose/Velocity/Imu best effort (ROS sensor data QoS)", plant.cpus);
  plant_cmd->add_flag("!--realtime", plant.lockstep, "pace by the wall clock instead of lockstep (one vehicle)");
  plant_cmd->add_option("--rate-factor", plant.realtime.rate_factor, "real time: run k times faster")
      ->check(CLI::Range(1e-3, 1e6));
  plant_cmd->add_option("--duration", plant.duration_s, "simulated time [s]")->check(CLI::Range(0.0, 1e9));
  plant_cmd->add_option("--record", plant.one_vehicle.record, "one vehicle: write the trajectory CSV here");
  plant_cmd->add_option("--mcap", plant.one_vehicle.mcap,
                        "one vehicle: record the topics as MCAP here (metadata.yaml beside it)");
  plant_cmd
      ->add_option("--timeout", plant.timeout_s,
                   "lockstep: wait for the controller / a command; real time: for the controller "
                   "(--wait-for-controller) and each --schedule-via answer [s]")
      ->check(CLI::Range(0.01, 3600.0));
  plant_cmd
      ->add_option("--schedule-via", plant.one_vehicle.schedule_node,
                   "one vehicle: apply the scenario's schedule through this node's parameter services")
      ->check(CLI::Validator(check_node_name, "NODE"));
  plant_cmd->add_flag("--wait-for-controller", plant.realtime.wait_for_controller,
                      "real time: start only once a controller is matched (up to --timeout)");
  plant_cmd->add_option("--stats", plant.stats, "write the run's figures (real-time factor, round trip) as JSON here");
  plant_cmd->add_option("--swarm-out", plant.swarm.out, "with --vehicles: write summary.json, vehicles.csv here");
  plant_cmd
      ->add_option("--on-timeout", plant.lockstep_only.on_timeout, "lockstep: abort (exit 4) or hold the last command")
      ->check(CLI::IsMember({"abort", "hold"}));
  plant_cmd
      ->add_option("--watchdog", plant.watchdog_s,
                   "no valid motor command for this long [s] -> the watchdog policy (0: off; "
                   "default: the scenario's simulation.watchdog_s, 0.5)")
      ->check(CLI::Range(0.0, 1e6));
  plant_cmd
      ->add_option("--watchdog-policy", plant.watchdog_policy,
                   "hold: keep the last command; stop: motors to omega_min (default: the scenario's, stop)")
      ->check(CLI::IsMember({"hold", "stop"}));

  plant_cmd
      ->add_option("--sync", plant.lockstep_only.sync,
                   "lockstep, one vehicle: how the controller steps: samples (on each control tick's samples, "
                   "as quadcosim's controller), clock (from a timer on ROS time, as rclcpp and rclpy nodes with "
                   "use_sim_time: each tick's samples then a get_parameters request to its node, a control tick's "
                   "/clock after the reply), auto (clock when "
                   "the node publishing the commands has use_sim_time true; docs/ros2.md)")
      ->check(CLI::IsMember({"auto", "samples", "clock"}));
  plant_cmd
      ->add_option("--controller-node", plant.lockstep_only.controller_node,
                   "the controller's node: only the writers of its process are the controller's, and --sync "
                   "clock/auto asks it (default: the one process publishing the motor commands, and its node with "
                   "parameter services)")
      ->check(CLI::Validator(check_node_name, "NODE"));
  plant_cmd->add_flag("--clock-after-sensors", plant.clock_after_sensors,
                      "publish /clock after each tick's Pose, Velocity and Imu (for a peer that steps on "
                      "/clock and reads the newest samples: Simulink's ROS 2 time model; docs/simulink.md)");

  add_foxglove_options(*plant_cmd, plant.foxglove, /*inprocess=*/false);
  add_enclave_option(plant_cmd, plant.enclave);
  // Flags that do nothing in the chosen mode are refused (exit 2), naming the flag and the mode.
  plant_cmd->parse_complete_callback([plant_cmd, &plant] {
    const bool swarm = plant.swarm.vehicles > 0, realtime = !plant.lockstep;
    refuse_idle_flags(
        *plant_cmd,
        {
            {"--realtime", !swarm, "--vehicles; a swarm runs in lockstep only"},
            {"--namespace", !swarm, "--vehicles; each vehicle's namespace is <--ns-prefix>0000, ..."},
            {"--record", !swarm, "--vehicles; a swarm records with --swarm-out"},
            {"--mcap", !swarm, "--vehicles; a swarm records with --swarm-out"},
            {"--foxglove", !swarm, "--vehicles; one vehicle is served"},
            {"--schedule-via", !swarm, "--vehicles; each vehicle's controller applies the schedule"},
            {"--ns-prefix", swarm, "one vehicle; it needs --vehicles N"},
            {"--threads", swarm, "one vehicle; it needs --vehicles N"},
            {"--swarm-out", swarm, "one vehicle; it needs --vehicles N"},
            {"--rate-factor", realtime, "lockstep; it needs --realtime"},
            {"--wait-for-controller", realtime, "lockstep; it needs --realtime (lockstep always waits)"},
            {"--on-timeout", !realtime, "--realtime; it is the lockstep timeout's policy"},
            {"--sync", !realtime && !swarm, "--realtime or --vehicles; it is one vehicle's lockstep protocol"},
            {"--controller-node", !swarm && (!realtime || plant.realtime.wait_for_controller),
             "--vehicles, or --realtime without --wait-for-controller"},
            {"--timeout", !realtime || plant.realtime.wait_for_controller || !plant.one_vehicle.schedule_node.empty(),
             "--realtime alone; it needs lockstep, --wait-for-controller or --schedule-via"},
        });
  });
  return plant_cmd;
}

int plant_command(const PlantCommandOptions& o) {
  std::optional<io::Scenario> started = hosts::start_node_process("plant", o.cpus, o.scenario, o.vehicle, o.ns);
  if (!started) return exit_code::kBadInput;
  io::Scenario& sc = *started;
  if (!o.fmu.empty()) io::use_plant_fmu(sc, io::FmuSpec{o.fmu, {}}, "--fmu");
  if (o.watchdog_s >= 0.0) {
    const double ticks = o.watchdog_s / sc.simulation.plant.clock.period_s();
    if (std::abs(ticks - std::round(ticks)) > 1e-6) {
      std::cerr << fmt::format("error: --watchdog {:g}: expected a whole number of plant periods ({:g} s)\n",
                               o.watchdog_s, sc.simulation.plant.clock.period_s());
      return exit_code::kBadInput;
    }
    sc.simulation.plant.watchdog_ticks = static_cast<sim::Tick>(std::round(ticks));
  }
  if (!o.watchdog_policy.empty()) {
    sc.simulation.plant.watchdog_policy =
        o.watchdog_policy == "hold" ? sim::WatchdogPolicy::kHold : sim::WatchdogPolicy::kStop;
  }
  sc.simulation.plant.clock_after_sensors = o.clock_after_sensors;
  if (o.duration_s >= 0.0) {
    sc.simulation.duration_ticks = static_cast<sim::Tick>(o.duration_s / sc.simulation.plant.clock.period_s() + 0.5);
  }
  if (o.swarm.vehicles > 0) return swarm_plant_command(o, std::move(sc));
  PlantProcess process(o, std::move(sc));
  return process.run();
}

}  // namespace quadcosim::app
