// Fault injection for the in-process transport: per topic, a message is dropped with a probability
// and the survivors are delivered a whole number of plant ticks late. Decisions come from a seeded
// generator with one stream per topic, so the same seed gives the same faults, bit for bit, on every
// machine (std::mt19937_64 is specified exactly; the uniform draw is done by hand because the
// standard distributions are not).
#pragma once

#include <cstdint>
#include <map>
#include <random>
#include <string>

namespace quadcosim::sim {

struct TopicFaults {
  double drop_probability = 0.0;  ///< [0, 1]: chance that one message is lost
  std::int64_t delay_ticks = 0;   ///< >= 0: a message published during tick k arrives at the start of tick k + delay
  bool active() const { return drop_probability > 0.0 || delay_ticks > 0; }
};

struct FaultConfig {
  std::uint64_t seed = 1;
  std::map<std::string, TopicFaults> topics;  ///< by full topic name ("/drone/Pose")
  bool active() const {
    for (const auto& [name, f] : topics) {
      if (f.active()) return true;
    }
    return false;
  }
};

/// One topic's random stream: seeded from the run's seed and the topic name (FNV-1a, not std::hash,
/// whose values differ between standard libraries).
class FaultStream {
 public:
  FaultStream(std::uint64_t seed, const std::string& topic) : rng_(seed ^ fnv1a(topic)) {}
  /// A uniform draw in [0, 1) from the top 53 bits.
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

 private:
  static std::uint64_t fnv1a(const std::string& s) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
    return h;
  }
  std::mt19937_64 rng_;
};

}  // namespace quadcosim::sim
