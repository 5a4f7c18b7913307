// The plant process finds its controller: the participant whose writers of the motor commands are the
// controller's (by the run's pairing token, by --controller-node, or the one candidate), the sensors it
// subscribes, a restarted controller taking over, whether it publishes its status.
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "dds/graph.hpp"
#include "hosts/plant_process_class.hpp"
#include "hosts/signals.hpp"
#include "sim/sensor_wire.hpp"

namespace quadcosim::hosts {

std::string PlantProcess::hex(const Guid& g) {
  std::string s;
  for (std::uint8_t b : g) s += fmt::format("{:02x}", b);
  return s;
}

std::vector<std::string> PlantProcess::command_topics() const {
  std::vector<std::string> all{topics_.motor_commands};
  all.insert(all.end(), topics_.level_commands.begin(), topics_.level_commands.end());
  return all;
}

std::vector<PlantProcess::Guid> PlantProcess::controller_candidates() const {
  std::vector<Guid> found;
  // A controller commands on motor_commands or on a typed /<ns>/cmd/<level> topic.
  for (const std::string& topic : command_topics()) {
    for (const sim::SenderId s : transport_.matched_senders(topic)) {
      const auto info = transport_.sender_info(topic, s);
      if (!info) continue;
      if (pair_token_.empty() ? !info->pair_token.empty() : info->pair_token != pair_token_) continue;
      if (node_participant_ && info->participant != *node_participant_) continue;
      if (std::find(found.begin(), found.end(), info->participant) == found.end()) found.push_back(info->participant);
    }
  }
  return found;
}

std::vector<std::string> PlantProcess::sensor_topics() const {
  std::vector<std::string> all{topics_.pose, topics_.velocity, topics_.imu};
  sim::for_each_sensor_topic(sc_.simulation.plant.realism.extra_sensors, topics_.ns,
                             [&]<class>(const std::string& topic) { all.push_back(topic); });
  return all;
}

std::vector<std::string> PlantProcess::sensors_subscribed_by(const Guid& peer,
                                                             const std::vector<std::string>& topics) const {
  std::vector<std::string> out;
  for (const std::string& t : topics) {
    const auto parts = transport_.matched_reader_participants(t);
    if (std::find(parts.begin(), parts.end(), peer) != parts.end()) out.push_back(t);
  }
  return out;
}

bool PlantProcess::wait_for_controller() {
  const std::string& node = o_.lockstep_only.controller_node;
  if (pair_token_.empty() && !node.empty() && !find_node_participant(node)) return false;
  // Discovery of one participant's endpoints arrives close together but not at once: once the
  // controller subscribes one sensor, the others it subscribes have this long to show up.
  constexpr std::int64_t kSettleNs = 300'000'000;
  std::optional<Guid> peer;
  std::vector<std::string> sensors;
  std::int64_t settled_at = 0;
  bool ambiguous = false;
  const std::vector<std::string> sensor_topics_all = sensor_topics();
  const bool found = transport_.spin_until(
      [&] {
        if (stop_requested()) return true;
        const std::vector<Guid> candidates = controller_candidates();
        if (candidates.size() > 1 && pair_token_.empty()) {
          ambiguous = true;
          std::string list;
          for (const Guid& g : candidates) {
            list += ' ';  // piece by piece: `" " + hex(g)` inlined here warns (GCC 12 -Wrestrict, a false positive)
            list += hex(g);
          }
          std::cerr << fmt::format(
              "plant: {} participants publish {} and could be the controller:{}; a stranger or a controller "
              "left over from an earlier run? End it, use another ROS_DOMAIN_ID, or name the controller's node "
              "with --controller-node\n",
              candidates.size(), topics_.motor_commands, list);
          return true;
        }
        if (candidates.empty()) return false;
        peer = candidates.front();
        const std::vector<std::string> now = sensors_subscribed_by(*peer, sensor_topics_all);
        if (now.size() != sensors.size()) settled_at = steady_ns() + kSettleNs;
        sensors = now;
        // The run's own controller (a token) publishes its status, which a recorded tick 0's answer
        // includes: matched too, or tick 0 would be taken without it.
        if (!pair_token_.empty() && !recording_.empty() && !controller_writes_status()) return false;
        return sensors.size() == sensor_topics_all.size() || (!sensors.empty() && steady_ns() >= settled_at);
      },
      timeout_ns());
  if (ambiguous) return false;
  if (!found) {
    std::string subscribed;
    for (const std::string& t : sensors) subscribed += (subscribed.empty() ? "" : ", ") + t;
    std::cerr << fmt::format("plant: no controller on {} within {} s: {}; is it running on ROS_DOMAIN_ID {}?\n",
                             topics_.motor_commands, o_.timeout_s,
                             !peer ? fmt::format("no {}writer of {} is matched{}", pair_token_.empty() ? "" : "paired ",
                                                 topics_.motor_commands,
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
  if (sensors.size() < sensor_topics_all.size()) {
    std::string list;
    for (const std::string& t : sensors) list += (list.empty() ? "" : ", ") + t;
    std::cerr << fmt::format("plant: the controller subscribes {} only; the other sensor samples go to no one\n", list);
  }
  return true;
}

bool PlantProcess::take_over(const std::string& topic, sim::SenderId s) {
  if (!pair_token_.empty() || !peer_ || !plant_.watchdog_active()) return false;
  const auto info = transport_.sender_info(topic, s);
  if (!info || !info->pair_token.empty() || info->participant == *peer_) return false;
  if (node_participant_) return false;  // --controller-node names one participant, the one found at the start
  std::vector<Guid> others = controller_candidates();
  std::erase(others, *peer_);
  if (others.size() != 1 || others.front() != info->participant) return false;
  std::cerr << fmt::format(
      "plant: the controller's participant {} has been silent past the watchdog's limit; participant {} "
      "publishes {} now and is taken as the controller\n",
      hex(*peer_), hex(info->participant), topic);
  peer_ = info->participant;
  pairing_.pair_by_participant(*peer_);
  status_writers_seen_ = -1;  // whose statuses count changed with the controller
  if (scheduler_) scheduler_->only_from(*peer_);
  return true;
}

bool PlantProcess::find_node_participant(const std::string& node) {
  const std::string request = "rq" + node + "/get_parametersRequest";
  std::optional<Guid> found;
  host_.unlocked([&] {
    dds::discover_endpoints(transport_.participant().handle(), timeout_ns(), [&](const auto& endpoints) {
      for (const dds::Endpoint& e : endpoints) {
        if (!e.writer && e.dds_topic == request) found = e.participant;
      }
      return found.has_value() || stop_requested();
    });
    return 0;
  });
  if (!found) {
    std::cerr << fmt::format("plant: --controller-node {}: no such node (no reader of {}) within {} s\n", node, request,
                             o_.timeout_s);
    return false;
  }
  node_participant_ = found;
  return true;
}

bool PlantProcess::controller_writes_status() {
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

}  // namespace quadcosim::hosts
