#include "sim/controller_node.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include <fmt/format.h>

#include "model/angle.hpp"
#include "sim/controller_thread.hpp"
#include "sim/sensor_wire.hpp"

namespace quadcosim::sim {

ControllerNode::ControllerNode(Transport& transport, const Topics& topics, const control::ControllerConfig& config,
                               SampleFilter accepts, const sensors::SensorSet& carried)
    : core_(config, topics, carried), accepts_(std::move(accepts)) {
  const control::Controller& controller = core_.controller();
  status_.controller = controller.type();
  status_.output_names.assign(controller.output_names().begin(), controller.output_names().end());
  status_.outputs = core_.output().outputs;
  status_pub_ = transport.advertise<msg::ControllerStatus>(topics.controller_status);
  command_pub_ = transport.advertise<msg::Float64MultiArray>(topics.motor_commands);
  command_msg_.data.resize(4);
  command_msg_.dim = {{"", 4, 4}};
  subscribe_sensors(transport, topics.ns, carried);
  if (accepts_) {  // over a network: each sample's writer is checked first
    transport.subscribe_with_sender<msg::PoseStamped>(topics.pose,
                                                      [this, t = topics.pose](const msg::PoseStamped& m, SenderId s) {
                                                        if (from_plant(t, s) && core_.take_pose(m) && on_sample_)
                                                          on_sample_();
                                                      });
    transport.subscribe_with_sender<msg::TwistStamped>(
        topics.velocity, [this, t = topics.velocity](const msg::TwistStamped& m, SenderId s) {
          if (from_plant(t, s) && core_.take_velocity(m) && on_sample_) on_sample_();
        });
    transport.subscribe_with_sender<msg::Imu>(topics.imu, [this, t = topics.imu](const msg::Imu& m, SenderId s) {
      if (from_plant(t, s) && core_.take_imu(m) && on_sample_) on_sample_();
    });
    return;
  }
  // The callbacks capture only the node: the transport stores them in place, not in a heap block of
  // their own read on every sample.
  transport.subscribe<msg::PoseStamped>(topics.pose, [this](const msg::PoseStamped& m) {
    if (core_.take_pose(m) && on_sample_) on_sample_();
  });
  transport.subscribe<msg::TwistStamped>(topics.velocity, [this](const msg::TwistStamped& m) {
    if (core_.take_velocity(m) && on_sample_) on_sample_();
  });
  transport.subscribe<msg::Imu>(topics.imu, [this](const msg::Imu& m) {
    if (core_.take_imu(m) && on_sample_) on_sample_();
  });
}

template <class Message, class Take>
void ControllerNode::subscribe_sample(Transport& transport, const std::string& topic, Take take) {
  if (accepts_) {
    transport.subscribe_with_sender<Message>(topic, [this, topic, take](const Message& m, SenderId s) {
      if (from_plant(topic, s) && take(m) && on_sample_) on_sample_();
    });
  } else {
    transport.subscribe<Message>(topic, [this, take](const Message& m) {
      if (take(m) && on_sample_) on_sample_();
    });
  }
}

void ControllerNode::subscribe_sensors(Transport& transport, const std::string& ns, const sensors::SensorSet& carried) {
  for_each_sensor(carried, [&]<class Wire>(const auto& config) {
    using Kind = typename Wire::Kind;
    // The messages of one sample (the GNSS: fix and velocity) are read into one sample; it is taken
    // when every one of them has come with the same stamp (again when one is repeated).
    struct Inbox {
      typename Kind::Sample sample{};
      msg::Time stamp;
      unsigned seen = 0;
    };
    constexpr unsigned kAll = (1u << Wire::kTopics.size()) - 1;
    auto inbox = std::make_shared<Inbox>();
    for_each_message<Wire>(ns, [&]<std::size_t I, class Message>(const std::string& topic) {
      subscribe_sample<Message>(transport, topic, [this, inbox, config](const Message& m) {
        Inbox& in = *inbox;
        if (m.header.stamp.sec != in.stamp.sec || m.header.stamp.nanosec != in.stamp.nanosec || in.seen == 0) {
          in.stamp = m.header.stamp;
          in.seen = 0;
        }
        Wire::read(m, in.sample, config);
        in.seen |= 1u << I;
        return in.seen == kAll && core_.template take<Kind>(in.sample, in.stamp);
      });
    });
  });
}

bool ControllerNode::from_plant(const std::string& topic, SenderId sender) {
  if (accepts_(topic, sender)) return true;
  if (foreign_log_.count()) {
    core_.log(
        fmt::format("controller: sample on {} from a writer other than the plant's ignored; {} ignored so far "
                    "(logged: 1st, then every 100th)",
                    topic, foreign_log_.total()));
  }
  return false;
}

const control::ControllerOutput& ControllerNode::step(std::int64_t now_ns, double dt_s) {
  const ControllerCore::Begun begun = core_.begin_step(now_ns);
  if (thread_ && !begun.safety) {
    step_on_thread(now_ns, begun.sim_now_ns, dt_s);
    return core_.output();
  }
  const std::lock_guard lock(publish_mutex_);
  core_.decide(begun.safety, dt_s);
  publish(core_.observation(), core_.reference(), core_.output(), begun.sim_now_ns);
  last_step_ns_ = now_ns;
  return core_.output();
}

void ControllerNode::publish(const control::Observation& obs, const control::Reference& ref,
                             const control::ControllerOutput& out, std::int64_t sim_now_ns) {
  status_.header.stamp = msg::Time::from_ns(sim_now_ns);
  if (const char* mode = control::to_string(ref.mode); status_.mode != mode) status_.mode = mode;
  status_.setpoint = {ref.p_W.x(), ref.p_W.y(), ref.p_W.z(), out.roll_des_rad, out.pitch_des_rad, ref.yaw_rad};
  for (int i = 0; i < 3; ++i) status_.position_error[i] = ref.p_W[i] - obs.p_W[i];
  status_.yaw_error = model::wrap_pi(ref.yaw_rad - obs.yaw_rad);
  status_.attitude_error = out.attitude_error;
  for (int i = 0; i < 4; ++i) status_.u[i] = out.U[i];
  status_.rotor_saturated = out.rotor_saturated.value;  // entries past the rotor count are false
  status_.tilt_saturated = out.tilt_saturated;
  status_.safety = out.safety;
  status_.rejected_non_finite = core_.rejected(SensorFault::kNonFinite);
  status_.rejected_bad_quaternion = core_.rejected(SensorFault::kBadQuaternion);
  status_.rejected_bad_stamp = core_.rejected(SensorFault::kBadStamp);
  status_.rejected_stamp_backwards = core_.rejected(SensorFault::kStampBackwards);
  status_.rejected_stamp_ahead = core_.rejected(SensorFault::kStampAhead);
  status_.outputs = out.outputs;
  status_pub_.publish(status_);

  msg::write_command_label(command_msg_.dim[0].label, sim_now_ns);
  write_command(out, command_msg_);
  command_pub_.publish(command_msg_);
}

ControllerNode::~ControllerNode() {
  // The controller's thread first: a step's continuation uses the members below.
  core_.controller_slot().reset();
}

void ControllerNode::run_controller_on_thread(ControllerThreading threading) {
  std::unique_ptr<control::Controller>& slot = core_.controller_slot();
  auto on_thread = std::make_unique<ControllerThread>(std::move(slot), threading.thread_host);
  thread_ = on_thread.get();
  slot = std::move(on_thread);
  threading_ = std::move(threading);
}

std::optional<std::string> ControllerNode::controller_failure() const {
  const std::lock_guard lock(publish_mutex_);
  return failure_;
}

bool ControllerNode::controller_failed(const std::exception_ptr& error, std::int64_t sim_now_ns) {
  std::string what;
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
    what = "the controller's step threw something that is not a std::exception";
  }
  if (threading_.on_error == ControllerThreading::OnError::kStop) {
    if (!threading_.asynchronous) throw ControllerFailure(what);
    if (!failure_) {
      failure_ = what;
      if (threading_.on_failure) threading_.on_failure(what);
    }
    return false;
  }
  if (failure_log_.count()) {
    core_.log(
        fmt::format("controller: {}; the safety command was sent instead (t = {:g} s); {} failed steps so far "
                    "(logged: 1st, then every 100th)",
                    what, static_cast<double>(sim_now_ns) / 1e9, failure_log_.total()));
  }
  return true;
}

void ControllerNode::step_on_thread(std::int64_t now_ns, std::int64_t sim_now_ns, double dt_s) {
  auto job = std::make_shared<ControllerThread::Step>();
  job->observation = core_.observation();
  job->reference = core_.reference();
  job->dt_s = dt_s;
  job->output.outputs.assign(core_.output().outputs.size(), 0.0);
  const auto seconds = [](std::int64_t ns) { return fmt::format("{:g}", static_cast<double>(ns) / 1e9); };

  if (threading_.asynchronous) {
    {
      const std::lock_guard lock(publish_mutex_);
      if (failure_) return;  // the node has stopped answering
      step_in_flight_ = true;
    }
    const bool started = thread_->start(job, [this, sim_now_ns](ControllerThread::Step& s) {
      const std::lock_guard lock(publish_mutex_);
      step_in_flight_ = false;
      s.output.safety = false;
      if (s.error) {
        if (!controller_failed(s.error, sim_now_ns)) return;  // ends the node: nothing published
        s.output.safety = true;
        core_.safety_output(s.reference, s.output);
      }
      core_.output() = s.output;
      publish(s.observation, s.reference, core_.output(), sim_now_ns);
    });
    if (!started) {
      const std::lock_guard lock(publish_mutex_);
      step_in_flight_ = false;
      if (late_log_.count()) {
        core_.log("controller: tick of t = " + seconds(sim_now_ns) +
                  " s not answered: the controller has not returned from its previous step; " +
                  std::to_string(late_log_.total()) + " ticks not answered so far (logged: 1st, then every 100th)");
      }
      return;
    }
    last_step_ns_ = now_ns;
    return;
  }

  // Real time: wait for the controller up to the limit; the safety command when it is late.
  const bool returned = thread_->start(job) && thread_->wait_free(threading_.wait_ns);
  const std::lock_guard lock(publish_mutex_);
  control::ControllerOutput& output = core_.output();
  if (!returned) {
    output.safety = true;
    core_.safety_output(core_.reference(), output);
    if (late_log_.count()) {
      core_.log("controller: the controller did not return within " + seconds(threading_.wait_ns) +
                " s; the safety command was sent for the period of t = " + seconds(sim_now_ns) + " s; " +
                std::to_string(late_log_.total()) + " late periods so far (logged: 1st, then every 100th)");
    }
  } else if (job->error) {
    controller_failed(job->error, sim_now_ns);  // throws unless the safety command replaces the step
    output.safety = true;
    core_.safety_output(core_.reference(), output);
  } else {
    output = job->output;
    output.safety = false;
  }
  publish(core_.observation(), core_.reference(), output, sim_now_ns);
  last_step_ns_ = now_ns;
}

void ControllerNode::republish() {
  const std::lock_guard lock(publish_mutex_);
  if (step_in_flight_) return;  // its continuation publishes the answer
  status_pub_.publish(status_);
  command_pub_.publish(command_msg_);
}

}  // namespace quadcosim::sim
