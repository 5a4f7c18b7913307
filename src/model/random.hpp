// Seeded random numbers for the realism models: a small generator whose every output is defined here,
// so a seed gives the same numbers on every standard library (std::normal_distribution's algorithm
// is left to the library; std::mt19937_64 is fixed but its distributions are not).
//
// Generator: SplitMix64 (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
// OOPSLA 2014): a 64-bit counter advanced by the golden-ratio increment and passed through a
// bijective 64-bit finaliser. It passes BigCrush, has no bad seeds, and makes independent streams
// cheap: each noise source seeds its own generator with stream_seed(seed, vehicle, source), so
// adding a source never shifts the numbers of another.
// Normal deviates: the Box-Muller transform (Box and Muller 1958), both outputs used; uniforms in
// (0, 1) from the top 53 bits plus half an ulp, so log() never sees 0. log, sqrt, cos, sin come from
// the C library: identical on one platform and build (the determinism this project promises).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string_view>

namespace quadcosim::model {

/// SplitMix64's finaliser: a bijection on 64-bit words that spreads every input bit.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// FNV-1a hash of a name (stable across platforms), used to name streams.
constexpr std::uint64_t hash_name(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : s) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

/// The seed of the stream of `source` (e.g. "imu.gyro") of `vehicle` (e.g. "/drone") under the run
/// seed `seed`.
constexpr std::uint64_t stream_seed(std::uint64_t seed, std::string_view vehicle, std::string_view source) {
  return mix64(mix64(seed ^ mix64(hash_name(vehicle))) ^ hash_name(source));
}

class Rng {
 public:
  explicit Rng(std::uint64_t seed = 0) : state_(seed) {}

  /// The next 64 random bits.
  std::uint64_t next_u64() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return mix64(state_);
  }
  /// Uniform in the open interval (0, 1).
  double uniform() { return (static_cast<double>(next_u64() >> 11) + 0.5) * 0x1.0p-53; }
  /// Uniform in the open interval (a, b): a + (b - a) u.
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Standard normal N(0, 1) (Box-Muller; the second deviate of each pair is kept for the next call).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(uniform()));
    const double phi = 2.0 * std::numbers::pi * uniform();
    spare_ = r * std::sin(phi);
    has_spare_ = true;
    return r * std::cos(phi);
  }

 private:
  std::uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace quadcosim::model
