// What a controller has of the extra sensors (sensors/registry.hpp): the newest sample of each sensor the
// vehicle carries, as the controller node took it in, with its stamp. Part of control::Observation.
//
// Plain data (no pointers, no heap): an Observation is copied byte for byte to a controller in a child
// process (src/isolation/).
#pragma once

#include <cstdint>
#include <type_traits>

#include "sensors/registry.hpp"

namespace quadcosim::sensors {

/// One sensor's newest sample as the controller node took it in.
template <class Kind>
struct Reading {
  typename Kind::Sample sample{};  ///< as read from its message(s): what they lack is NaN (sim/sensor_wire.hpp)
  std::int64_t stamp_ns = -1;      ///< header stamp [ns] (the plant tick that published it); -1 before the first
};

namespace detail {
template <class... K>
struct ReadingsOf;
template <>
struct ReadingsOf<> {};
template <class K, class... Rest>
struct ReadingsOf<K, Rest...> : ReadingsOf<Rest...> {
  Reading<K> reading;
};
template <class... K>
ReadingsOf<K...> readings_of(std::tuple<K...>*);
}  // namespace detail

/// The reading of every kind of the registry, and which of them the vehicle carries.
class Readings {
 public:
  /// Kind's reading, or null when the vehicle does not carry the sensor.
  template <class Kind>
  const Reading<Kind>* get() const {
    return carries<Kind>() ? &slot<Kind>() : nullptr;
  }
  template <class Kind>
  bool carries() const {
    return (carried_ & bit<Kind>()) != 0;
  }
  /// Any sensor carried.
  bool any() const { return carried_ != 0; }

  /// The vehicle carries Kind (its reading has stamp -1 until the first sample).
  template <class Kind>
  void carry() {
    carried_ |= bit<Kind>();
  }
  /// Kind's newest sample (Kind must be carried).
  template <class Kind>
  void set(const typename Kind::Sample& sample, std::int64_t stamp_ns) {
    Reading<Kind>& r = slot<Kind>();
    r.sample = sample;
    r.stamp_ns = stamp_ns;
  }

 private:
  template <class Kind>
  static constexpr unsigned bit() {
    return 1u << kind_index<Kind>();
  }
  template <class Kind>
  Reading<Kind>& slot() {
    return find_in<Kind>(readings_);
  }
  template <class Kind>
  const Reading<Kind>& slot() const {
    return const_cast<Readings*>(this)->slot<Kind>();
  }
  template <class Kind, class Head, class... Rest>
  static Reading<Kind>& find_in(detail::ReadingsOf<Head, Rest...>& r) {
    if constexpr (std::is_same_v<Kind, Head>) {
      return r.reading;
    } else {
      return find_in<Kind>(static_cast<detail::ReadingsOf<Rest...>&>(r));
    }
  }

  unsigned carried_ = 0;
  decltype(detail::readings_of(static_cast<Kinds*>(nullptr))) readings_;
};

}  // namespace quadcosim::sensors
