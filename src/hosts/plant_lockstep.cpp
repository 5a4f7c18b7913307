// The plant process's drivers: lockstep (with the --sync clock barrier for a controller stepping on ROS
// time, and the checks that each control tick is answered once) and real time, and the scenario's
// schedule applied through the controller's parameter services.
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "dds/graph.hpp"
#include "hosts/parameter_binding.hpp"
#include "hosts/plant_process_class.hpp"
#include "hosts/signals.hpp"

namespace quadcosim::hosts {

int PlantProcess::choose_sync() {
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
        for (const std::string& topic : command_topics()) {
          for (std::string& n : dds::parameter_nodes_writing(own, topic)) {
            if (std::find(nodes.begin(), nodes.end(), n) == nodes.end()) nodes.push_back(std::move(n));
          }
        }
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
  if (!transport_.spin_until([&] { return stop_requested() || transport_.matched_readers(topics_.clock) > own; },
                             timeout_ns())) {
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

bool PlantProcess::before_clock(sim::Tick k) {
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

bool PlantProcess::apply_due_schedule(sim::Tick k) {
  for (; scheduler_ && next_event_ != sc_.schedule.end() && next_event_->tick <= k; ++next_event_) {
    // The reply comes through Cyclone's receive thread: let deliveries on arrival through meanwhile.
    const auto r = host_.unlocked([&] {
      return scheduler_->set({{next_event_->name, to_ros(next_event_->value)}}, timeout_ns());
    });
    if (r.size() != 1 || !r[0].successful) {
      std::cerr << fmt::format("plant: scheduled {} at t = {} s refused by {}: {}\n", next_event_->name,
                               clock_.seconds(k), o_.one_vehicle.schedule_node, r.empty() ? "no result" : r[0].reason);
      return false;
    }
  }
  return true;
}

int PlantProcess::run_realtime() {
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

int PlantProcess::run_lockstep() {
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
    std::cerr << lockstep_timeout_message(transport_, topics_, clock_, k, o_.timeout_s, o_.lockstep_only.on_timeout);
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
  return r == drivers::LockstepResult::kDone && !stop_requested() ? check_answer_count() : kExitOk;
}

int PlantProcess::check_answer_count() {
  const std::int64_t until = steady_ns() + 200'000'000;
  while (transport_.spin_once(20'000'000) > 0 && steady_ns() < until) {
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

void PlantProcess::check_one_answer_per_period(sim::Tick k) {
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
  request_stop();
}

bool PlantProcess::schedule_due(sim::Tick k) const {
  return scheduler_ && next_event_ != sc_.schedule.end() && next_event_->tick <= k;
}

}  // namespace quadcosim::hosts
