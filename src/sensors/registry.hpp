// The registry of the sensors a vehicle can carry beyond the paper's Pose, Velocity and Imu: one
// entry ("kind") per sensor, naming its configuration in SensorSet, its model and sample, how the
// model is made and measures, and the sample's fields as named columns of numbers. Everything that
// handles the sensors generically is derived from this list: the vehicle's sensor suite
// (sensors/suite.hpp), Batch's arrays, the plant FMU's output variables; the wire side (topics,
// messages) is the plant's (sim/sensor_wire.hpp).
//
// To add a sensor (docs/sensors.md, "Add a sensor"): its model (sensors/<name>.{hpp,cpp}), its line in
// SensorSet, its kind here (and in Kinds: with its scenario keys, columns and configuration fields)
// and its wire form (sim/sensor_wire.hpp).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>

#include "model/quadrotor.hpp"
#include "model/random.hpp"
#include "sensors/sensor_set.hpp"

namespace quadcosim::sensors {

/// The configuration's numbers by name, for what stores a configuration outside a scenario (the
/// plant FMU's resources): Kind::config_fields(config, f) calls f(name, member) for every member, an
/// int, a double or an Eigen::Vector3d (const or not, as `config` is). The timing comes first.
template <class C, class F>
void timing_fields(C& timing, F&& f) {
  f("divider", timing.divider);
  f("latency_ticks", timing.latency_ticks);
}

/// One scenario key of a sensor's configuration (sensors.<name>.<key>, docs/sensors.md): a number,
/// or a list of three for a vector member, in the key's own unit (uT, deg, ...), within [min, max]
/// in that unit; `to_si` turns it into the configuration's SI member. An absent key leaves the
/// member at its default. Besides these, every sensor reads rate_hz and latency_ticks (its timing),
/// and Kind::at_site(config, site) copies what it needs of environment.site.
template <class Config>
struct ScenarioKey {
  std::string_view name;
  double min = 0.0, max = 0.0;
  double to_si = 1.0;
  double Config::*number = nullptr;           ///< the member a number key sets, or
  Eigen::Vector3d Config::*vector = nullptr;  ///< the member a three-number key sets
};

inline constexpr double kDegToRad = std::numbers::pi / 180.0;

/// One named field of a sample: `width` numbers in `unit`, written by `write(sample, out)`.
template <class Sample>
struct Column {
  std::string_view name;  ///< "field": with the sensor's name, "magnetometer.field"
  int width = 1;          ///< numbers per sample (3 for a vector)
  std::string_view unit;  ///< SI unit as FMI writes it ("T", "Pa", "m", "deg", "m/s", "1")
  std::string_view description;
  void (*write)(const Sample&, double* out) = nullptr;
  bool boolean = false;  ///< a flag written as 1 or 0 (Python shows a bool where it shows one sample)
};

/// What a kind states alike for every sensor: its configuration, model and sample types, where its
/// configuration sits in SensorSet, and by default how the model is made (from the configuration and
/// its random stream) and measures (from the truth alone). A kind whose model needs more says so.
template <class C, class M, class S, std::optional<C> SensorSet::*kMember>
struct KindBase {
  using Config = C;
  using Model = M;
  using Sample = S;
  static const std::optional<Config>& config(const SensorSet& s) { return s.*kMember; }
  static std::optional<Config>& config(SensorSet& s) { return s.*kMember; }
  static Model make(const Config& c, model::Rng rng, double /*plant_period_s*/) { return Model(c, rng); }
  static Sample measure(Model& m, const model::Outputs& truth, double /*truth_t_s*/) { return m.measure(truth); }
};

struct MagnetometerKind : KindBase<MagnetometerConfig, Magnetometer, MagnetometerSample, &SensorSet::magnetometer> {
  static constexpr std::string_view kName = "magnetometer";  ///< also its random stream's name
  template <class C, class F>
  static void config_fields(C& c, F&& f) {
    timing_fields(c.timing, f);
    f("field_T", c.field_T);
    f("inclination_rad", c.inclination_rad);
    f("declination_rad", c.declination_rad);
    f("noise_sigma_T", c.noise_sigma_T);
    f("hard_iron_T", c.hard_iron_T);
  }
  static constexpr double kDefaultRateHz = 100.0;
  static constexpr std::array<ScenarioKey<Config>, 5> kScenarioKeys{{
      {"field_uT", 1.0, 100.0, 1e-6, &Config::field_T},
      {"inclination_deg", -90.0, 90.0, kDegToRad, &Config::inclination_rad},
      {"declination_deg", -180.0, 180.0, kDegToRad, &Config::declination_rad},
      {"noise_sigma_uT", 0.0, 100.0, 1e-6, &Config::noise_sigma_T},
      {"hard_iron_uT", -1000.0, 1000.0, 1e-6, nullptr, &Config::hard_iron_T},
  }};
  static constexpr std::array<Column<Sample>, 1> kColumns{{
      {"field", 3, "T", "the measured magnetic field in the body frame",
       [](const Sample& s, double* o) {
         for (int a = 0; a < 3; ++a) o[a] = s.field_B_T[a];
       }},
  }};
};

struct BarometerKind : KindBase<BarometerConfig, Barometer, BarometerSample, &SensorSet::barometer> {
  static constexpr std::string_view kName = "barometer";
  /// The drift steps once per sample: the model is told the sample period.
  static Model make(const Config& c, model::Rng rng, double plant_period_s) {
    return Model(c, plant_period_s * c.timing.divider, rng);
  }
  template <class C, class F>
  static void config_fields(C& c, F&& f) {
    timing_fields(c.timing, f);
    f("site_altitude_m", c.site_altitude_m);
    f("sea_level_pressure_Pa", c.sea_level_pressure_Pa);
    f("noise_sigma_Pa", c.noise_sigma_Pa);
    f("drift_Pa_sqrt_s", c.drift_Pa_sqrt_s);
    f("bias_initial_Pa", c.bias_initial_Pa);
  }
  static constexpr double kDefaultRateHz = 50.0;
  static constexpr std::array<ScenarioKey<Config>, 4> kScenarioKeys{{
      {"sea_level_pressure_Pa", 80000.0, 110000.0, 1.0, &Config::sea_level_pressure_Pa},
      {"noise_sigma_Pa", 0.0, 1000.0, 1.0, &Config::noise_sigma_Pa},
      {"drift_Pa_sqrt_s", 0.0, 100.0, 1.0, &Config::drift_Pa_sqrt_s},
      {"bias_initial_Pa", 0.0, 1000.0, 1.0, &Config::bias_initial_Pa},
  }};
  /// The world origin's altitude: the pressure there follows from it.
  static void at_site(Config& c, const Geodetic& site) { c.site_altitude_m = site.height_m; }
  static constexpr std::array<Column<Sample>, 2> kColumns{{
      {"pressure", 1, "Pa", "the static pressure reading", [](const Sample& s, double* o) { o[0] = s.pressure_Pa; }},
      {"altitude", 1, "m", "the reading's ISA pressure altitude above mean sea level",
       [](const Sample& s, double* o) { o[0] = s.altitude_m; }},
  }};
};

struct GnssKind : KindBase<GnssConfig, Gnss, GnssSample, &SensorSet::gnss> {
  static constexpr std::string_view kName = "gnss";
  /// The receiver's fix and outages depend on the time.
  static Sample measure(Model& m, const model::Outputs& truth, double truth_t_s) { return m.measure(truth, truth_t_s); }
  template <class C, class F>
  static void config_fields(C& c, F&& f) {
    timing_fields(c.timing, f);
    f("site_latitude_rad", c.site.latitude_rad);
    f("site_longitude_rad", c.site.longitude_rad);
    f("site_height_m", c.site.height_m);
    f("horizontal_sigma_m", c.horizontal_sigma_m);
    f("vertical_sigma_m", c.vertical_sigma_m);
    f("velocity_sigma_m_s", c.velocity_sigma_m_s);
    f("fix_after_s", c.fix_after_s);
    f("outage_from_s", c.outage_from_s);
    f("outage_to_s", c.outage_to_s);
  }
  static constexpr double kDefaultRateHz = 10.0;
  static constexpr std::array<ScenarioKey<Config>, 6> kScenarioKeys{{
      {"horizontal_sigma_m", 0.0, 1000.0, 1.0, &Config::horizontal_sigma_m},
      {"vertical_sigma_m", 0.0, 1000.0, 1.0, &Config::vertical_sigma_m},
      {"velocity_sigma_m_s", 0.0, 100.0, 1.0, &Config::velocity_sigma_m_s},
      {"fix_after_s", 0.0, 1e6, 1.0, &Config::fix_after_s},
      {"outage_from_s", 0.0, 1e6, 1.0, &Config::outage_from_s},
      {"outage_to_s", 0.0, 1e6, 1.0, &Config::outage_to_s},
  }};
  /// What the keys cannot say alone: "" or why the configuration is not one (the reader names it).
  static std::string check(const Config& c) { return sensors::check(c); }
  /// The world origin is where the receiver's positions are measured from.
  static void at_site(Config& c, const Geodetic& site) { c.site = site; }
  /// Without a fix only the fix flag is a number; the rest is NaN by definition.
  static bool has_numbers(const Sample& s) { return s.fix; }
  static constexpr double kDeg = 180.0 / std::numbers::pi;
  static constexpr std::array<Column<Sample>, 5> kColumns{{
      {"fix", 1, "1", "1 with a fix, 0 without (then the rest is NaN)",
       [](const Sample& s, double* o) { o[0] = s.fix ? 1.0 : 0.0; }, true},
      {"latitude_deg", 1, "deg", "WGS-84 geodetic latitude",
       [](const Sample& s, double* o) { o[0] = s.position.latitude_rad * kDeg; }},
      {"longitude_deg", 1, "deg", "WGS-84 longitude",
       [](const Sample& s, double* o) { o[0] = s.position.longitude_rad * kDeg; }},
      {"altitude_m", 1, "m", "height above the WGS-84 ellipsoid",
       [](const Sample& s, double* o) { o[0] = s.position.height_m; }},
      {"v", 3, "m/s", "velocity in the world frame (ENU)",
       [](const Sample& s, double* o) {
         for (int a = 0; a < 3; ++a) o[a] = s.velocity_W[a];
       }},
  }};
};

/// Every kind, in a fixed order (the order of samples, arrays and variables).
using Kinds = std::tuple<MagnetometerKind, BarometerKind, GnssKind>;

/// Calls f.template operator()<Kind>() for every kind of the registry, in order.
template <class F>
void for_each_kind(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) { (f.template operator()<std::tuple_element_t<I, Kinds>>(), ...); }
  (std::make_index_sequence<std::tuple_size_v<Kinds>>{});
}

/// A sample's columns, in order, packed into out[0 .. sample_width<Kind>()).
template <class Kind>
void write_sample(const typename Kind::Sample& sample, double* out) {
  for (const auto& c : Kind::kColumns) {
    c.write(sample, out);
    out += c.width;
  }
}

/// Whether every column of `sample` holds a number (finite), as a controller may expect; false for a
/// sample whose kind says its numbers are undefined (Kind::has_numbers: a GNSS sample without a fix).
template <class Kind>
bool has_numbers(const typename Kind::Sample& sample) {
  if constexpr (requires { Kind::has_numbers(sample); }) {
    return Kind::has_numbers(sample);
  } else {
    return true;
  }
}

/// Kind's place in Kinds.
template <class Kind, std::size_t I = 0>
constexpr std::size_t kind_index() {
  if constexpr (std::is_same_v<Kind, std::tuple_element_t<I, Kinds>>) {
    return I;
  } else {
    return kind_index<Kind, I + 1>();
  }
}

/// Calls f.template operator()<Kind>(config) for every kind `set` configures, in order.
template <class F>
void for_each_configured(const SensorSet& set, F&& f) {
  for_each_kind([&]<class Kind>() {
    if (const auto& c = Kind::config(set)) f.template operator()<Kind>(*c);
  });
}

/// Numbers per sample of Kind (the sum of its columns' widths).
template <class Kind>
constexpr int sample_width() {
  int n = 0;
  for (const auto& c : Kind::kColumns) n += c.width;
  return n;
}

}  // namespace quadcosim::sensors
