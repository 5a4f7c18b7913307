#include "io/realism_yaml.hpp"

#include "io/criteria_yaml.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "control/inner_loops.hpp"
#include "model/wind.hpp"
#include "sensors/registry.hpp"

namespace quadcosim::io {

namespace {

constexpr double kBig = 1e6;

Eigen::Vector3d vec3(YamlSection& s, const std::string& key, const Eigen::Vector3d& fallback, double min, double max) {
  const auto v = s.numbers(key, {fallback.x(), fallback.y(), fallback.z()}, 3);
  for (double e : v) {
    if (e < min || e > max)
      s.fail(key, fmt::format("got an entry {:g}, expected numbers in [{:g}, {:g}]", e, min, max));
  }
  return {v[0], v[1], v[2]};
}

// rate_hz -> its divider n of the plant rate (default `default_hz`, or the plant rate when that is
// lower), and latency_ticks. n must divide the controller period: lockstep needs a complete
// Pose/Velocity/Imu sample at every control tick. With `slower_ok` (the magnetometer, barometer and
// GNSS, which are not part of that sample) n may also be a whole multiple of it, so a sample still
// lands on a control tick (GNSS at 5-10 Hz is slower than the controller).
sim::SensorTiming read_timing(YamlSection& s, const sim::SimulationConfig& cfg,
                              double default_hz = std::numeric_limits<double>::infinity(), bool slower_ok = false) {
  sim::SensorTiming t;
  const double plant_hz = 1e9 / static_cast<double>(cfg.plant.clock.period_ns);
  const double rate = s.number("rate_hz", std::min(default_hz, plant_hz), 1e-6, plant_hz);
  const double div = plant_hz / rate;
  const long n = std::lround(div);
  const long c = cfg.controller_divider;
  const bool fits = c % n == 0 || (slower_ok && n % c == 0);
  if (std::abs(div - static_cast<double>(n)) > 1e-9 || !fits) {
    if (slower_ok) {
      s.fail("rate_hz",
             fmt::format("got {:g}, expected the plant rate ({:g} Hz) divided by a whole number that "
                         "divides the controller period ({} plant ticks) or is a multiple of it, e.g. "
                         "{:g} or {:g}",
                         rate, plant_hz, c, plant_hz / static_cast<double>(c), plant_hz / static_cast<double>(5 * c)));
    }
    s.fail("rate_hz", fmt::format("got {:g}, expected the plant rate ({:g} Hz) divided by a whole number that "
                                  "also divides the controller period ({} plant ticks), e.g. {:g} or {:g}",
                                  rate, plant_hz, c, plant_hz, plant_hz / static_cast<double>(c)));
  }
  t.divider = static_cast<int>(n);
  t.latency_ticks = static_cast<int>(s.integer("latency_ticks", 0, 0, 1000));
  return t;
}

constexpr double kDeg = std::numbers::pi / 180.0;

// environment.site: where the world origin is on the Earth (GNSS, barometer).
sensors::Geodetic read_site(YamlSection& g) {
  sensors::Geodetic site;
  site.latitude_rad = g.number("latitude_deg", 0.0, -90.0, 90.0) * kDeg;
  site.longitude_rad = g.number("longitude_deg", 0.0, -180.0, 180.0) * kDeg;
  site.height_m = g.number("altitude_m", 0.0, -500.0, 10000.0);
  g.reject_unknown_keys();
  return site;
}

// Every sensor of the registry the scenario configures (sensors.<name>), read from its kind's
// scenario keys (sensors/registry.hpp).
void read_extra_sensors(YamlSection& s, const sim::SimulationConfig& cfg, const sensors::Geodetic& site,
                        sensors::SensorSet& set) {
  sensors::for_each_kind([&]<class Kind>() {
    auto section = s.section(std::string(Kind::kName));
    if (!section) return;
    typename Kind::Config c;
    c.timing = read_timing(*section, cfg, Kind::kDefaultRateHz, /*slower_ok=*/true);
    for (const auto& key : Kind::kScenarioKeys) {
      const std::string name(key.name);
      if (!section->has(name)) continue;  // the default, exactly
      if (key.number != nullptr) {
        c.*key.number = section->number(name, 0.0, key.min, key.max) * key.to_si;
      } else {
        c.*key.vector = vec3(*section, name, Eigen::Vector3d::Zero(), key.min, key.max) * key.to_si;
      }
    }
    if constexpr (requires { Kind::at_site(c, site); }) Kind::at_site(c, site);
    section->reject_unknown_keys();
    if constexpr (requires { Kind::check(c); }) {
      if (const std::string err = Kind::check(c); !err.empty()) s.fail(std::string(Kind::kName), err);
    }
    Kind::config(set) = c;
  });
}

}  // namespace

void read_realism(YamlSection& root, Scenario& sc) {
  sim::RealismConfig& r = sc.simulation.plant.realism;
  const auto& cfg = sc.simulation;
  r.seed = static_cast<std::uint64_t>(root.integer("seed", 0, 0, std::numeric_limits<long long>::max()));
  sensors::Geodetic site;  // the world origin on the Earth (environment.site)
  if (auto e = root.section("environment")) {
    r.wind.mean_W_m_s = vec3(*e, "wind_m_s", r.wind.mean_W_m_s, -200.0, 200.0);
    if (auto g = e->section("site")) site = read_site(*g);
    if (auto g = e->section("gusts")) {
      r.wind.gusts.enabled = true;
      r.wind.gusts.w20_m_s = g->number("w20_m_s", r.wind.gusts.w20_m_s, 0.0, 100.0);
      r.wind.gusts.altitude_m = g->number("altitude_m", r.wind.gusts.altitude_m, 1e-3, 1e4);
      r.wind.gusts.airspeed_m_s = g->number("airspeed_m_s", r.wind.gusts.airspeed_m_s, 0.0, 200.0);
      g->reject_unknown_keys();
    }
    e->reject_unknown_keys();
  }
  if (auto s = root.section("sensors")) {
    if (auto i = s->section("imu")) {
      r.imu.timing = read_timing(*i, cfg);
      r.imu.gyro_noise_density = i->number("gyro_noise_density_rad_s_sqrt_hz", 0.0, 0.0, 10.0);
      r.imu.gyro_bias_random_walk = i->number("gyro_bias_random_walk_rad_s2_sqrt_hz", 0.0, 0.0, 10.0);
      r.imu.gyro_bias_initial = i->number("gyro_bias_initial_rad_s", 0.0, 0.0, 10.0);
      r.imu.accel_noise_density = i->number("accel_noise_density_m_s2_sqrt_hz", 0.0, 0.0, 100.0);
      r.imu.accel_bias_random_walk = i->number("accel_bias_random_walk_m_s3_sqrt_hz", 0.0, 0.0, 100.0);
      r.imu.accel_bias_initial = i->number("accel_bias_initial_m_s2", 0.0, 0.0, 100.0);
      r.imu.orientation_sigma_rad = i->number("orientation_sigma_rad", 0.0, 0.0, 1.0);
      i->reject_unknown_keys();
    }
    if (auto p = s->section("pose")) {
      r.pose.timing = read_timing(*p, cfg);
      r.pose.position_sigma_m = p->number("position_sigma_m", 0.0, 0.0, 1e3);
      r.pose.orientation_sigma_rad = p->number("orientation_sigma_rad", 0.0, 0.0, 1.0);
      p->reject_unknown_keys();
    }
    if (auto v = s->section("velocity")) {
      r.velocity.timing = read_timing(*v, cfg);
      r.velocity.linear_sigma_m_s = v->number("linear_sigma_m_s", 0.0, 0.0, 1e3);
      r.velocity.angular_sigma_rad_s = v->number("angular_sigma_rad_s", 0.0, 0.0, 100.0);
      v->reject_unknown_keys();
    }
    read_extra_sensors(*s, cfg, site, r.extra_sensors);
    s->reject_unknown_keys();
  }
  const double duration_s = cfg.plant.clock.seconds(cfg.duration_ticks);
  int index = 0;
  for (const YAML::Node& n : root.sequence("faults")) {
    const std::string where = "faults[" + std::to_string(index++) + "]";
    if (!n.IsMap()) root.fail(where, "expected a mapping with at_s, rotor, efficiency");
    YamlSection s(n, root.file(), root.key_path(where));
    sim::RotorFault f;
    if (!s.has("rotor")) s.fail("rotor", "missing; expected the rotor number 1..4");
    const double at = s.number("at_s", 0.0, 0.0, duration_s);
    const double ticks = at / cfg.plant.clock.period_s();
    if (std::abs(ticks - std::round(ticks)) > 1e-6) {
      s.fail("at_s", fmt::format("got {:g} s, expected a whole number of plant periods ({:g} s)", at,
                                 cfg.plant.clock.period_s()));
    }
    f.tick = static_cast<sim::Tick>(std::round(ticks));
    f.rotor = static_cast<int>(s.integer("rotor", 1, 1, 4)) - 1;
    f.efficiency = s.number("efficiency", 0.0, 0.0, 1.0);
    s.reject_unknown_keys();
    r.faults.push_back(f);
  }
  std::stable_sort(r.faults.begin(), r.faults.end(), [](const auto& a, const auto& b) { return a.tick < b.tick; });
  if (std::string err = model::validate(r.wind); !err.empty()) root.fail("environment", err);
  read_inner_loops(root, sc);
}

void read_inner_loops(YamlSection& root, Scenario& sc) {
  auto s = root.section("inner_loops");
  if (!s) return;
  const double period_s = sc.simulation.plant.clock.period_s();
  const auto& table = control::inner_loop_table();
  control::InnerLoopParams p = control::InnerLoopParams::for_vehicle(sc.vehicle, period_s);
  constexpr std::string_view kPrefix = "inner.";
  for (const control::ParameterSpec& spec : table.specs()) {
    const std::string key(spec.name.substr(kPrefix.size()));  // the section's keys drop "inner."
    const double value = s->number(key, std::get<double>(*table.get(p, spec.name)), spec.min, spec.max);
    table.set(p, spec.name, value);
  }
  s->reject_unknown_keys();
  if (std::string err = control::check_inner_loops(p, sc.vehicle, period_s); !err.empty()) {
    root.fail("inner_loops", err);
  }
  sc.simulation.plant.inner_loops = p;
}

HoldSpec read_hold(YamlSection& s, double duration_s) {
  HoldSpec h;
  h.after_s = s.number("after_s", 0.0, 0.0, duration_s);
  auto criteria = read_criteria_sets(s, hold_figure_names(), "hold figure");
  if (!criteria) s.fail("spec", "missing; expected e.g. spec: {max_horizontal_error_m: [null, 0.5]}");
  h.criteria = std::move(*criteria);
  if (h.criteria.empty()) s.fail("spec", "expected at least one figure");
  s.reject_unknown_keys();
  return h;
}

}  // namespace quadcosim::io
