// What the foreign participants (foreign_controller.cpp, foreign_levels.cpp) share: plain Cyclone C
// API and the ROS 2 facts about domains and discovery (docs/ros2.md), nothing of quadcosim.
#pragma once

#include <dds/dds.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <string>

namespace foreign {

/// The program's name in its messages; each main sets it first.
inline const char* program = "foreign";

inline std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

[[noreturn]] inline void die(const char* what, dds_return_t rc) {
  std::fprintf(stderr, "%s: %s failed: %s\n", program, what, dds_strretcode(rc));
  std::exit(2);
}

inline dds_entity_t check(dds_entity_t e, const char* what) {
  if (e < 0) die(what, e);
  return e;
}

/// ROS_DOMAIN_ID as rcl reads it: strtoul base 0; unset or empty means 0.
inline dds_domainid_t ros_domain_id() {
  const char* s = std::getenv("ROS_DOMAIN_ID");
  if (s == nullptr || *s == '\0') return 0;
  char* end = nullptr;
  errno = 0;
  const unsigned long v = std::strtoul(s, &end, 0);
  if (errno != 0 || *end != '\0' || v > 232) {
    std::fprintf(stderr, "%s: ROS_DOMAIN_ID '%s' is not a domain id\n", program, s);
    std::exit(2);
  }
  return static_cast<dds_domainid_t>(v);
}

/// rmw_cyclonedds' configuration for ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST (docs/ros2.md, Domain and
/// discovery): participant index auto (max 32), no multicast, localhost as the static peer;
/// CYCLONEDDS_URI is appended after it.
inline std::string localhost_config() {
  std::string xml =
      "<CycloneDDS><Domain id=\"any\">"
      "<General><AllowMulticast>false</AllowMulticast></General>"
      "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
      "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"
      "<Peers><Peer address=\"localhost\"/></Peers></Discovery>"
      "</Domain></CycloneDDS>";
  if (const char* uri = std::getenv("CYCLONEDDS_URI"); uri != nullptr && *uri != '\0') {
    xml += ",";
    xml += uri;
  }
  return xml;
}

/// Takes every available sample of `reader` (loaned) and hands each valid one to `f`.
template <typename T, typename F>
void take_all(dds_entity_t reader, F&& f) {
  constexpr int kBatch = 16;
  void* samples[kBatch];
  dds_sample_info_t infos[kBatch];
  for (;;) {
    std::fill(std::begin(samples), std::end(samples), nullptr);
    const dds_return_t n = dds_take(reader, samples, infos, kBatch, kBatch);
    if (n < 0) die("dds_take", n);
    for (int i = 0; i < n; ++i) {
      if (infos[i].valid_data) f(*static_cast<const T*>(samples[i]));
    }
    if (n > 0) dds_return_loan(reader, samples, n);
    if (n < kBatch) return;
  }
}

}  // namespace foreign
