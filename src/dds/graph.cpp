#include "dds/graph.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <map>
#include <set>

#include "dds/participant.hpp"

namespace quadcosim::dds {

std::optional<std::string> ros_topic_name(std::string_view dds_topic) {
  constexpr std::string_view prefix = "rt/";
  if (dds_topic.size() <= prefix.size() || dds_topic.substr(0, prefix.size()) != prefix) return std::nullopt;
  return std::string(dds_topic.substr(prefix.size() - 1));  // keep the '/'
}

std::string demangle_ros_type(std::string_view dds_type) {
  constexpr std::string_view marker = "dds_::";
  const auto at = dds_type.find(marker);
  if (dds_type.empty() || dds_type.back() != '_' || at == std::string_view::npos) return std::string(dds_type);
  std::string ns;  // "geometry_msgs::msg::" -> "geometry_msgs/msg/"
  for (std::size_t i = 0; i < at;) {
    if (dds_type.compare(i, 2, "::") == 0) {
      ns += '/';
      i += 2;
    } else {
      ns += dds_type[i++];
    }
  }
  const std::size_t start = at + marker.size();
  return ns + std::string(dds_type.substr(start, dds_type.size() - 1 - start));
}

bool is_hidden_topic(std::string_view ros_topic) {
  for (std::size_t i = 0; i < ros_topic.size(); ++i) {
    if (ros_topic[i] == '_' && (i == 0 || ros_topic[i - 1] == '/')) return true;
  }
  return false;
}

std::vector<RosTopic> ros_topics(const std::vector<Endpoint>& endpoints) {
  std::map<std::string, RosTopic> by_name;
  for (const Endpoint& e : endpoints) {
    const auto name = ros_topic_name(e.dds_topic);
    if (!name) continue;
    RosTopic& t = by_name[*name];
    t.name = *name;
    const std::string type = demangle_ros_type(e.dds_type);
    if (std::find(t.types.begin(), t.types.end(), type) == t.types.end()) t.types.push_back(type);
    if (e.writer) {
      ++t.publishers;
      if (!e.reliable) ++t.best_effort_publishers;
    } else {
      ++t.subscribers;
    }
  }
  std::vector<RosTopic> out;
  out.reserve(by_name.size());
  for (auto& [name, t] : by_name) {
    std::sort(t.types.begin(), t.types.end());
    out.push_back(std::move(t));
  }
  return out;
}

std::string format_topic_list(const std::vector<RosTopic>& topics, bool with_types, bool include_hidden) {
  std::string out;
  for (const RosTopic& t : topics) {
    if (!include_hidden && is_hidden_topic(t.name)) continue;
    out += t.name;
    if (with_types) {
      out += " [";
      for (std::size_t i = 0; i < t.types.size(); ++i) out += (i ? ", " : "") + t.types[i];
      out += ']';
    }
    out += '\n';
  }
  return out;
}

namespace {

using Key = std::array<std::uint8_t, 16>;

Key key_of(const dds_guid_t& g) {
  Key k;
  std::memcpy(k.data(), g.v, k.size());
  return k;
}

// Takes every pending sample of a built-in endpoint reader into `known` (alive endpoints added,
// disposed or unregistered ones removed).
void take_endpoints(dds_entity_t reader, bool writers, const Key& own, std::map<Key, Endpoint>& known) {
  constexpr int kBatch = 32;
  for (;;) {
    void* samples[kBatch] = {nullptr};
    dds_sample_info_t infos[kBatch];
    const dds_return_t n = check(dds_take(reader, samples, infos, kBatch, kBatch), "dds_take (built-in topic)");
    for (int i = 0; i < n; ++i) {
      const auto* s = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      const Key key = key_of(s->key);
      if (infos[i].instance_state != DDS_IST_ALIVE) {
        known.erase(key);
        continue;
      }
      if (!infos[i].valid_data || key_of(s->participant_key) == own) continue;
      Endpoint e;
      e.dds_topic = s->topic_name ? s->topic_name : "";
      e.dds_type = s->type_name ? s->type_name : "";
      e.writer = writers;
      std::copy(std::begin(s->participant_key.v), std::end(s->participant_key.v), e.participant.begin());
      dds_reliability_kind_t kind = DDS_RELIABILITY_RELIABLE;
      dds_duration_t blocking = 0;
      if (s->qos && dds_qget_reliability(s->qos, &kind, &blocking)) e.reliable = kind == DDS_RELIABILITY_RELIABLE;
      void* data = nullptr;
      size_t size = 0;
      if (s->qos && dds_qget_userdata(s->qos, &data, &size) && data != nullptr) {
        e.user_data.assign(static_cast<const char*>(data), size);
        dds_free(data);
      }
      known[key] = std::move(e);
    }
    if (n > 0) dds_return_loan(reader, samples, n);
    if (n < kBatch) break;
  }
}

}  // namespace

std::vector<std::string> parameter_nodes_writing(const std::vector<Endpoint>& endpoints, std::string_view ros_topic) {
  constexpr std::string_view kPrefix = "rq/", kSuffix = "/get_parametersRequest";
  std::set<std::array<std::uint8_t, 16>> writers;
  for (const Endpoint& e : endpoints) {
    if (e.writer && ros_topic_name(e.dds_topic) == ros_topic) writers.insert(e.participant);
  }
  std::set<std::string> nodes;
  for (const Endpoint& e : endpoints) {
    const std::string_view t = e.dds_topic;
    if (e.writer || !writers.contains(e.participant) || t.size() <= kPrefix.size() + kSuffix.size() ||
        !t.starts_with(kPrefix) || !t.ends_with(kSuffix)) {
      continue;
    }
    nodes.insert("/" + std::string(t.substr(kPrefix.size(), t.size() - kPrefix.size() - kSuffix.size())));
  }
  return {nodes.begin(), nodes.end()};
}

std::vector<Endpoint> discover_endpoints(dds_entity_t participant, std::int64_t wait_ns,
                                         const std::function<bool(const std::vector<Endpoint>&)>& done) {
  dds_guid_t own_guid;
  check(dds_get_guid(participant, &own_guid), "dds_get_guid");
  const Key own = key_of(own_guid);

  // Built-in topic readers default to RELIABLE TRANSIENT_LOCAL: they start with everything already
  // discovered, then receive changes.
  // Deleted on every way out (the readers take their read conditions with them).
  const Entity pubs(check(dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr),
                          "dds_create_reader (DCPSPublication)"));
  const Entity subs(check(dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr),
                          "dds_create_reader (DCPSSubscription)"));
  const Entity waitset(check(dds_create_waitset(participant), "dds_create_waitset"));
  std::map<Key, Endpoint> known;
  std::vector<Endpoint> list;
  for (const dds_entity_t reader : {pubs.get(), subs.get()}) {
    const dds_entity_t cond = check(dds_create_readcondition(reader, DDS_ANY_STATE), "dds_create_readcondition");
    check(dds_waitset_attach(waitset, cond, reader), "dds_waitset_attach");
  }
  const dds_time_t deadline = dds_time() + wait_ns;
  for (;;) {
    take_endpoints(pubs, true, own, known);
    take_endpoints(subs, false, own, known);
    list.clear();
    for (const auto& [key, e] : known) list.push_back(e);
    if ((done && done(list)) || dds_time() >= deadline) break;
    const dds_return_t rc = dds_waitset_wait_until(waitset, nullptr, 0, deadline);
    check(rc, "dds_waitset_wait_until");
  }
  return list;
}

}  // namespace quadcosim::dds
