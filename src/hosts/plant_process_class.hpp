// The plant process's class (plant_process.hpp runs it), shared by the files that hold its parts by
// job: plant_process.cpp (setup, run, recording and summary), plant_pairing.cpp (finding the
// controller and pairing with its writers), plant_lockstep.cpp (the lockstep barrier and --sync, the
// schedule, the drivers that advance the ticks).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dds/dds_transport.hpp"
#include "dds/node_announcer.hpp"
#include "dds/parameter_client.hpp"
#include "dds/peer_pairing.hpp"
#include "drivers/lockstep_plant_driver.hpp"
#include "drivers/realtime_plant_driver.hpp"
#include "hosts/exit_code.hpp"
#include "hosts/node_common.hpp"
#include "hosts/node_options.hpp"
#include "io/recording.hpp"
#include "io/scenario.hpp"
#include "sim/plant_node.hpp"
#include "sim/topics.hpp"

namespace quadcosim::hosts {

/// One plant process: the node on its DDS transport, what it records, and the driver that advances
/// it (lockstep or real time). Construction does all the setup; run() runs the driver.
class PlantProcess {
 public:
  /// Exit codes of `plant` (docs/cosimulation.md).
  static constexpr int kExitOk = exit_code::kOk, kExitRefused = exit_code::kBadInput,
                       kExitNoController = exit_code::kNoPeer, kExitInterrupted = exit_code::kInterrupted;

  PlantProcess(const PlantProcessOptions& o, io::Scenario sc);

  /// Runs every tick; returns the process's exit code.
  int run();

 private:
  sim::PlantNode make_plant();

  /// Readers of this process's own on each topic (the recorder's, the Foxglove server's): matched
  /// counts include them.
  int own_readers() const { return (recording_.mcap() ? 1 : 0) + (o_.foxglove.listen.empty() ? 0 : 1); }

  using Guid = std::array<std::uint8_t, 16>;

  static std::string hex(const Guid& g);

  /// The participants whose writers of the motor commands may be the controller's: with a pairing
  /// token, those whose writers carry it; otherwise those whose writers carry no token (a token means
  /// the controller of another quadcosim run) and, with --controller-node, only the node's own.
  std::vector<Guid> controller_candidates() const;

  /// The topics of every sensor the plant publishes: Pose, Velocity, Imu, then the extra sensors'.
  std::vector<std::string> sensor_topics() const;

  /// Which of `topics` (sensor_topics()) `peer` subscribes (readers matched by ours).
  std::vector<std::string> sensors_subscribed_by(const Guid& peer, const std::vector<std::string>& topics) const;

  /// Finds the controller, pairs with its writers (dds/peer_pairing.hpp: only its commands are
  /// answers; every other writer's are counted as foreign and ignored) and waits until it subscribes
  /// the sensors it needs (any of Pose, Velocity, Imu: what its participant's readers ask for), so
  /// tick 0 is not published into the void. False, with the reason on stderr, when none comes within
  /// the timeout or the controller is ambiguous (several participants could be it).
  bool wait_for_controller();

  /// A controller that was restarted (killed, started again: the paper's stale-data scenario) is a
  /// new participant. Without a token it may take over from the paired one, but only once the
  /// watchdog holds (the paired controller has been silent past its limit: it is gone as far as the
  /// vehicle is concerned), only when it carries no token, and only when it is the one participant
  /// besides the old one that could be the controller. So a stranger cannot take over from a
  /// controller that is alive, nor two newcomers race. True when `s` is now the controller's.
  bool take_over(const std::string& topic, sim::SenderId s);
  /// The topics a controller commands on: motor_commands and every /<ns>/cmd/<level>.
  std::vector<std::string> command_topics() const;

  /// --controller-node without a pairing token: the participant hosting that node's parameter
  /// services is the controller's. False, with the reason on stderr, when it is not found in time.
  bool find_node_participant(const std::string& node);

  /// Lockstep: how the controller steps (--sync). A controller that steps on each control tick's
  /// samples needs nothing more. One that steps from a timer on ROS time (an rclcpp or rclpy node
  /// with use_sim_time) reads whatever samples its subscriptions took when /clock makes the timer
  /// due, and first answers one control period in; for it every tick sends its samples, then a
  /// get_parameters request to its node, and a control tick's /clock waits for the reply (its
  /// executor serves services after the subscriptions that were ready in the same wait, so the reply
  /// means the samples are taken: before_clock; docs/ros2.md, "Lockstep with your own ROS 2
  /// controller").
  int choose_sync();

  /// Between tick k's samples and its /clock (when /clock goes last); false holds the /clock back.
  bool before_clock(sim::Tick k);

  /// The schedule through the controller's parameter services: each change due by tick k is
  /// acknowledged before tick k is published, so the run stays deterministic. False when refused.
  bool apply_due_schedule(sim::Tick k);

  /// Real time: each tick published, paced by the wall clock, then completed
  /// (drivers::RealtimePlantDriver).
  int run_realtime();

  /// Lockstep (drivers::LockstepPlantDriver): commands and statuses are delivered on arrival (on
  /// Cyclone's receive thread), and the delivery that completes the awaited tick's answer runs the
  /// ticks that follow right there, up to the next control tick's publication: a control period
  /// wakes no thread of this process but the receive thread. The main thread is woken for what
  /// needs it: a scheduled change through the parameter services (a blocking request), a timeout,
  /// the hold policy's unpaced ticks, the end.
  int run_lockstep();

  /// Lockstep matches an unlabelled command to the tick being awaited when it is delivered. A
  /// controller that sends more commands than it was asked for (one per sensor sample, or again when
  /// a tick's samples were published twice) leaves the surplus queued, and each later tick then takes
  /// an answer to an earlier one: the per-period count cannot see this, the total can. So once the
  /// last tick ran and what is still arriving came in (a 20 ms lull, at most 200 ms), more commands
  /// than control periods (one may answer the final samples) stop the run's success.
  int check_answer_count();

  /// The paired controller publishes its status (so a control tick's answer includes it).
  /// Asked once per control tick: the writers are looked at again only when their count changed (a
  /// status read costs tens of instructions, the matched writers' list about 1,400 per tick).
  bool controller_writes_status();

  /// Lockstep: the controller answers each control tick once. A second command within one control
  /// period cannot be matched to a tick (it would be latched by its arrival time: not deterministic),
  /// so the run stops at the first one, saying what the controller must change.
  void check_one_answer_per_period(sim::Tick k);

  /// What follows tick k's latch, before the plant integrates: log, record.
  void after_latch(sim::Tick k);

  bool schedule_due(sim::Tick k) const;

  /// The watchdog's changes as events on stderr (simulated time, and the monotonic wall clock).
  void log_watchdog(sim::Tick k);

  void record(sim::Tick k);

  /// Completes the recordings (also on the error paths, so what was recorded is readable).
  int finish(int code);

  void report();

  std::int64_t timeout_ns() const { return static_cast<std::int64_t>(o_.timeout_s * 1e9); }

  const PlantProcessOptions& o_;
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
  /// trajectory.csv (--record), run.mcap (--mcap) and the live view (--foxglove), as asked
  io::Recording recording_;
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
  DdsDriverHost host_{transport_};
  std::optional<drivers::LockstepPlantDriver> lockstep_;
  std::optional<drivers::RealtimePlantDriver> realtime_;
};

}  // namespace quadcosim::hosts
