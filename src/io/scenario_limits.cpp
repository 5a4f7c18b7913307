#include "io/scenario_limits.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/statvfs.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "io/scenario.hpp"

namespace quadcosim::io {

namespace {

Limits& limits_in_force() {
  static Limits limits;  // set once by the command line, before any file is read
  return limits;
}

std::string mb(double bytes) { return fmt::format("{:.1f} MB", bytes / 1e6); }

}  // namespace

const std::vector<std::string>& limit_names() {
  static const std::vector<std::string> names = {"scenario_bytes", "schedule_entries",   "plant_rate_hz",
                                                 "fmu_entries",    "fmu_unpacked_bytes", "fmu_variables"};
  return names;
}

const Limits& limits() { return limits_in_force(); }

void set_limits(const Limits& l) {
  limits_in_force() = l;
  fmi::FmuLimits f = l.fmu;
  f.enabled = l.enabled;
  fmi::set_fmu_limits(f);
}

std::string apply_limit(Limits& l, const std::string& assignment) {
  const auto eq = assignment.find('=');
  const std::string name = assignment.substr(0, eq);
  const auto& names = limit_names();
  if (eq == std::string::npos || std::find(names.begin(), names.end(), name) == names.end()) {
    return fmt::format("--limit {}: expected NAME=VALUE with NAME one of {}", assignment, fmt::join(names, ", "));
  }
  const std::string text = assignment.substr(eq + 1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v) || v <= 0.0) {
    return fmt::format("--limit {}: the value must be a positive number, got '{}'", assignment, text);
  }
  const auto whole = [&](std::uint64_t& field) {
    if (v > 1.8e19) v = 1.8e19;
    field = static_cast<std::uint64_t>(v);
  };
  if (name == "scenario_bytes") whole(l.scenario_bytes);
  if (name == "schedule_entries") whole(l.schedule_entries);
  if (name == "plant_rate_hz") l.plant_rate_hz = v;
  if (name == "fmu_entries") whole(l.fmu.entries);
  if (name == "fmu_unpacked_bytes") whole(l.fmu.unpacked_bytes);
  if (name == "fmu_variables") whole(l.fmu.variables);
  return "";
}

long long free_disk_bytes(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p = fs::absolute(folder.empty() ? "." : folder, ec);
  while (!p.empty() && !fs::exists(p, ec)) {
    if (p == p.parent_path()) break;
    p = p.parent_path();
  }
  struct statvfs st {};
  // A file system without blocks (procfs, sysfs) says nothing about space: the write itself will fail.
  if (::statvfs(p.c_str(), &st) != 0 || st.f_blocks == 0) return -1;
  return static_cast<long long>(st.f_bavail) * static_cast<long long>(st.f_frsize);
}

long long available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  long long kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit) {
    if (key == "MemAvailable:") return kb * 1024;
  }
  return -1;
}

void check_output_fits(const std::string& what, const std::string& folder, double plant_ticks, double control_steps) {
  const Limits& l = limits();
  if (!l.enabled || !l.check_disk) return;
  const double projected = plant_ticks * kOutputBytesPerPlantTick + control_steps * kOutputBytesPerControlStep;
  const long long free = free_disk_bytes(folder);
  if (free < 0 || projected <= static_cast<double>(free)) return;
  throw ConfigError(fmt::format(
      "{}: the outputs would need about {} ({:.0f} plant ticks at about {:.0f} bytes each, {:.0f} controller steps at "
      "about {:.0f}), more than the {} free on the disk of {}; shorten simulation.duration_s, lower the rates, free "
      "space, or pass --no-limits",
      what, mb(projected), plant_ticks, kOutputBytesPerPlantTick, control_steps, kOutputBytesPerControlStep,
      mb(static_cast<double>(free)), folder));
}

void check_swarm_fits(int vehicles) {
  const Limits& l = limits();
  if (!l.enabled || !l.check_memory) return;
  const double projected = vehicles * kSwarmBytesPerVehicle;
  const long long available = available_memory_bytes();
  if (available < 0 || projected <= static_cast<double>(available)) return;
  throw ConfigError(fmt::format(
      "--vehicles {}: the swarm would need about {} of memory (about {:.0f} bytes per vehicle), more than the {} "
      "available (MemAvailable); fly fewer vehicles, or pass --no-limits",
      vehicles, mb(projected), kSwarmBytesPerVehicle, mb(static_cast<double>(available))));
}

std::vector<std::string> limit_arguments(const Limits& l) {
  if (!l.enabled) return {"--no-limits"};
  const Limits d;
  std::vector<std::string> args;
  const auto pass = [&](const char* name, double value, double fallback) {
    if (value != fallback) {
      args.emplace_back("--limit");
      args.push_back(fmt::format("{}={}", name, value));
    }
  };
  pass("scenario_bytes", static_cast<double>(l.scenario_bytes), static_cast<double>(d.scenario_bytes));
  pass("schedule_entries", static_cast<double>(l.schedule_entries), static_cast<double>(d.schedule_entries));
  pass("plant_rate_hz", l.plant_rate_hz, d.plant_rate_hz);
  pass("fmu_entries", static_cast<double>(l.fmu.entries), static_cast<double>(d.fmu.entries));
  pass("fmu_unpacked_bytes", static_cast<double>(l.fmu.unpacked_bytes), static_cast<double>(d.fmu.unpacked_bytes));
  pass("fmu_variables", static_cast<double>(l.fmu.variables), static_cast<double>(d.fmu.variables));
  return args;
}

}  // namespace quadcosim::io
