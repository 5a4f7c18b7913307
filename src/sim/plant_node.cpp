#include "sim/plant_node.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include "sim/msg_eigen.hpp"
#include "sim/vehicle_description.hpp"

namespace quadcosim::sim {

std::string external_plant_conflict(const RealismConfig& realism, const model::VehicleParams& vehicle) {
  if (realism.wind.active()) return "environment";
  if (!realism.faults.empty()) return "faults";
  if (vehicle.aero.active()) {
    for (const model::VehicleParameter& p : model::vehicle_parameters()) {
      if (p.section() == "aero" && p.kind == model::VehicleParameter::Kind::kNumber && p.get(vehicle) != 0.0) {
        return "vehicle." + std::string(p.name);
      }
    }
    return "vehicle.aero";
  }
  return {};
}

PlantNode::PlantNode(Transport& transport, const Topics& topics, const model::VehicleParams& vehicle,
                     const PlantOptions& options, const model::State& initial)
    : core_(vehicle, options.realism, options.clock, initial,
            // The vehicle's namespace names its noise streams.
            topics.ns),
      options_(options) {
  log_ = [](const std::string& line) { std::cerr << line << '\n'; };
  if (options.inner_loops) core_.set_inner_loops(*options.inner_loops);
  if (options.external) {
    if (std::string key = external_plant_conflict(options.realism, vehicle); !key.empty()) {
      throw std::invalid_argument(key + ": acts inside quadcosim's own plant model only, not with " +
                                  options.external->describe() + " as the plant");
    }
    external_ = options.external->make(vehicle, initial, options.clock);
  }
  status_pub_ = transport.advertise<msg::PlantStatus>(topics.plant_status);
  if (options.publish_clock) clock_pub_ = transport.advertise<msg::Clock>(topics.clock);
  pose_pub_ = transport.advertise<msg::PoseStamped>(topics.pose);
  velocity_pub_ = transport.advertise<msg::TwistStamped>(topics.velocity);
  imu_pub_ = transport.advertise<msg::Imu>(topics.imu);
  pose_.header.frame_id = options.frame_id;
  twist_.header.frame_id = options.frame_id;
  imu_.header.frame_id = "base_link";
  if (options.realism.extra_sensors.any()) {
    extra_sensors_ =
        std::make_unique<SensorChannels>(options.realism.extra_sensors, topics.ns, transport, options.frame_id);
  }
  if (options.publish_tf) {
    // tf2 names frames without a leading '/', the vehicle's namespace as their prefix (/drone ->
    // drone/base_link), so many vehicles share one /tf.
    const std::string& ns = topics.ns;
    tf_.transforms.resize(1);
    tf_.transforms[0].header.frame_id = options.frame_id;
    tf_.transforms[0].child_frame_id = tf_prefix(ns) + "base_link";
    VehicleDescription d = describe_vehicle(vehicle, ns, msg::Time::from_ns(options.clock.ns(0)));
    tf_static_ = std::move(d.rotors);
    description_ = std::move(d.urdf);
    tf_pub_ = transport.advertise<msg::TFMessage>(topics.tf);
    tf_static_pub_ = transport.advertise<msg::TFMessage>(topics.tf_static);
    description_pub_ = transport.advertise<msg::String>(topics.robot_description);
  }
  status_period_ticks_ = options.status_period_ticks > 0 ? options.status_period_ticks
                                                         : std::max<Tick>(1, 1'000'000'000 / options.clock.period_ns);
  command_topics_[0] = topics.motor_commands;
  for (std::size_t i = 0; i < topics.level_commands.size(); ++i) command_topics_[1 + i] = topics.level_commands[i];
  transport.subscribe_with_sender<msg::Float64MultiArray>(
      topics.motor_commands, [this](const msg::Float64MultiArray& m, SenderId sender) { on_command(m, sender); });
  if (!options.typed_command_topics) return;
  msg::for_each_level_message([&]<class T>() {
    transport.subscribe_with_sender<T>(topics.level_commands[static_cast<std::size_t>(T::kLevel)],
                                       [this](const T& m, SenderId sender) { on_level_command(m, sender); });
  });
}

template <class Check>
void PlantNode::intake(int source, SenderId sender, std::int64_t stamp, Check check) {
  const std::string& topic = command_topics_[static_cast<std::size_t>(source)];
  // How the logs name it (built only when one is written).
  const auto what = [&] { return source == 0 ? std::string("motor command") : "command on " + topic; };
  if (command_filter_ && !command_filter_(topic, sender)) {
    ++stats_.commands_foreign;
    if (foreign_log_.count()) {
      log_("plant: " + what() + " from a writer other than the controller's ignored; " +
           std::to_string(foreign_log_.total()) + " ignored so far (logged: 1st, then every 100th)");
    }
    return;
  }
  if (clock_held_ >= 0) {
    ++stats_.commands_early;
    if (on_early_command_) on_early_command_(clock_held_);
    return;
  }
  // One topic commands a tick: a command on another topic than the one that answered this plant tick
  // (or, in lockstep, the tick its label names) is refused, so no tick is commanded twice.
  if (last_source_ >= 0 && source != last_source_ &&
      (last_source_tick_ == current_tick_ || (stamp >= 0 && stamp == last_source_label_))) {
    ++stats_.commands_rejected_second_topic;
    stats_.last_problem = fmt::format(
        "a command on {} for the tick (t = {:g} s) that {} already commanded: one "
        "topic commands a tick",
        topic, options_.clock.seconds(stamp >= 0 ? stamp / options_.clock.period_ns : current_tick_),
        command_topics_[static_cast<std::size_t>(last_source_)]);
    if (second_topic_log_.count()) {
      log_("plant: " + stats_.last_problem + "; ignored, " + std::to_string(second_topic_log_.total()) +
           " so far (logged: 1st, then every 100th)");
    }
    return;
  }
  ++stats_.commands_received;
  // Lockstep repeats, whatever their content: an answer to an earlier tick, or a second copy of the
  // accepted answer to this one (the controller sends its last command again when the plant repeats
  // a tick). Dropped and counted apart, so the other counters are those of a run without repeats.
  // The label is read only in lockstep, where commands cross a network and may come twice or late;
  // delivered in-process, every command answers the tick it arrives in. What a label says counts
  // for later commands only once the command is accepted (below).
  if (stamp >= 0 && (stamp < options_.clock.ns(current_tick_) || stamp == last_label_accepted_ns_)) {
    ++stats_.commands_stale;
    if (on_label_behind_ && stamp < options_.clock.ns(current_tick_)) on_label_behind_(stamp, current_tick_);
    return;
  }
  last_command_stamp_ns_ = stamp;  // the controller's answer to its tick, whatever its verdict
  last_source_ = source;
  last_source_tick_ = current_tick_;
  last_source_label_ = stamp;
  // Checked, and queued unless rejected (PlantCore::take_checked).
  const CommandCheck c = check();
  core_.take_checked(current_tick_, options_.command_delay_ticks, c);
  if (c.verdict() == CommandVerdict::kRejected) {
    stats_.last_problem = c.reason();
    ++stats_.commands_rejected;
    ++(c.fault == CommandFault::kWrongLength     ? stats_.commands_rejected_length
       : c.fault == CommandFault::kBadQuaternion ? stats_.commands_rejected_bad_quaternion
                                                 : stats_.commands_rejected_non_finite);
    if (rejected_log_.count()) {
      log_("plant: " + what() + " rejected (" + stats_.last_problem + "), last good command held; " +
           std::to_string(rejected_log_.total()) + " rejected so far (logged: 1st, then every 100th)");
    }
    return;
  }
  if (stamp >= 0) last_label_accepted_ns_ = stamp;
  ++stats_.commands_accepted;
  if (c.fault == CommandFault::kOutOfRange) {
    stats_.last_problem = c.reason();
    ++stats_.commands_clamped;
    if (clamped_log_.count()) {
      log_("plant: " + what() + " clamped (" + stats_.last_problem + "); " + std::to_string(clamped_log_.total()) +
           " clamped so far (logged: 1st, then every 100th)");
    }
  }
  if (receipt_clock_) last_valid_receipt_ns_ = receipt_clock_();
}

void PlantNode::on_command(const msg::Float64MultiArray& m, SenderId sender) {
  intake(0, sender, options_.drop_stale_commands ? msg::command_stamp_ns(m) : -1,
         [&] { return check_command(m, core_.omega_max_rad_s(), core_.rotor_count()); });
}

template <class T>
void PlantNode::on_level_command(const T& m, SenderId sender) {
  // header.stamp is the label (a stamp before 0 is none).
  const std::int64_t stamp = options_.drop_stale_commands ? std::max<std::int64_t>(-1, m.header.stamp.to_ns()) : -1;
  intake(1 + static_cast<int>(T::kLevel), sender, stamp, [&] {
    const msg::LevelValues v = msg::level_values(m);
    return check_command(v.level, v.data(), v.count(), core_.omega_max_rad_s(), core_.rotor_count(), v.attitude_norm);
  });
}

void PlantNode::publish_status(Tick k) {
  const bool problem = stats_.commands_rejected_length != status_.commands_rejected_length ||
                       stats_.commands_rejected_non_finite != status_.commands_rejected_non_finite ||
                       stats_.commands_clamped != status_.commands_clamped ||
                       stats_.commands_foreign != status_.commands_foreign ||
                       stats_.commands_rejected_second_topic != status_.commands_rejected_second_topic ||
                       stats_.commands_rejected_bad_quaternion != status_.commands_rejected_bad_quaternion ||
                       watchdog_active_ != status_.watchdog_active;
  if (!problem && k % status_period_ticks_ != 0) return;
  if (k == last_status_tick_) return;  // one status per tick, also when a tick's outputs are repeated
  last_status_tick_ = k;
  status_.header = msg::Header{msg::Time::from_ns(options_.clock.ns(k)), options_.frame_id};
  status_.commands_accepted = stats_.commands_accepted;
  status_.commands_clamped = stats_.commands_clamped;
  status_.commands_rejected_length = stats_.commands_rejected_length;
  status_.commands_rejected_non_finite = stats_.commands_rejected_non_finite;
  status_.last_problem = stats_.last_problem;
  status_.watchdog_active = watchdog_active_;
  status_.watchdog_trips = stats_.watchdog_trips;
  status_.watchdog_ticks = stats_.watchdog_ticks;
  status_.commands_stale = stats_.commands_stale;
  status_.commands_foreign = stats_.commands_foreign;
  status_.commands_rejected_second_topic = stats_.commands_rejected_second_topic;
  status_.commands_rejected_bad_quaternion = stats_.commands_rejected_bad_quaternion;
  status_pub_.publish(status_);
}

void PlantNode::publish_outputs(Tick k) {
  current_tick_ = k;
  const msg::Time stamp = msg::Time::from_ns(options_.clock.ns(k));
  const model::Outputs y = external_ ? external_outputs(k) : core_.outputs(options_.clock, k);

  const bool clock_first = !options_.clock_after_sensors;
  if (clock_pub_ && clock_first) clock_pub_.publish(msg::Clock{stamp});
  if (description_pub_ && !description_sent_) {
    description_sent_ = true;
    description_pub_.publish(description_);
    tf_static_pub_.publish(tf_static_);
  }
  publish_status(k);

  // The messages are kept between ticks (their frame ids are set once); every field that changes
  // is written by sense, with what the sensors make of it (noise, rates, latency; the same sample on
  // a repeated tick).
  const PlantRealism::Due due = core_.sense(k, y, stamp, pose_, twist_, imu_);
  if (due.pose) pose_pub_.publish(pose_);
  if (due.velocity) velocity_pub_.publish(twist_);
  if (due.imu) imu_pub_.publish(imu_);
  if (core_.sense_extra(k, y)) extra_sensors_->publish(*core_.extra_sensors(), k, stamp);
  if (tf_pub_) {  // the true pose, whatever the sensors made of it
    msg::TransformStamped& t = tf_.transforms.front();
    t.header.stamp = stamp;
    t.translation = to_msg(y.p_W);
    t.rotation = to_msg(y.q_WB);
    tf_pub_.publish(tf_);
  }
  if (clock_pub_ && !clock_first) {
    if (!before_clock_ || before_clock_(k)) {
      clock_pub_.publish(msg::Clock{stamp});
    } else {
      clock_held_ = k;
    }
  }
}

void PlantNode::publish_clock(Tick k) {
  if (k == clock_held_) clock_held_ = -1;
  if (clock_pub_) clock_pub_.publish(msg::Clock{msg::Time::from_ns(options_.clock.ns(k))});
}

model::Outputs PlantNode::external_outputs(Tick k) {
  model::Outputs y;
  external_->outputs(k, y, core_.state());
  return y;
}

void PlantNode::latch_command(Tick k) {
  if (options_.watchdog_ticks <= 0) {
    core_.latch_due(k);
    return;
  }
  if (receipt_clock_) {
    const std::int64_t now = receipt_clock_();
    if (last_valid_receipt_ns_ < 0) last_valid_receipt_ns_ = now;  // the limit runs from the first tick
    command_age_ns_ = now - last_valid_receipt_ns_;
  } else {
    command_age_ns_ = core_.command_age_ns(options_.clock, k);
  }
  const bool expired =
      core_.latch(k, command_age_ns_, options_.clock.ns(options_.watchdog_ticks), options_.watchdog_policy);
  if (expired && !watchdog_active_) ++stats_.watchdog_trips;
  watchdog_active_ = expired;
  if (expired) ++stats_.watchdog_ticks;
}

void PlantNode::integrate(Tick k) {
  if (external_) {
    external_->step(k, core_.latched());
    return;
  }
  core_.integrate(options_.clock, k, options_.substeps);
}

}  // namespace quadcosim::sim
