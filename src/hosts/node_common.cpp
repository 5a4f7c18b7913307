#include "hosts/node_common.hpp"

#include <fmt/format.h>

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "analysis/percentile.hpp"
#include "hosts/signals.hpp"

namespace quadcosim::hosts {

std::optional<io::Scenario> start_node_process(const std::string& who, const std::string& cpus,
                                               const std::string& scenario, const std::string& vehicle,
                                               const std::string& ns, const io::ScenarioResolvers& resolvers,
                                               const std::string& controller_type) {
  hosts::install_stop_handlers();
  if (std::string err = use_cpus(cpus); !err.empty()) {
    std::cerr << "error: " << who << ": --cpus: " << err << '\n';
    return std::nullopt;
  }
  // One write: run --pin starts both processes on one stderr, and grep reads whole lines.
  if (!cpus.empty()) std::cerr << fmt::format("{}: on CPU(s) {} only\n", who, cpus);
  io::Scenario sc = scenario.empty() ? io::defaults_flown_by(controller_type, resolvers)
                                     : io::load_scenario(scenario, controller_type, resolvers);
  if (!vehicle.empty()) {
    sc.vehicle = io::load_vehicle(vehicle);
    if (sc.controller_fmu) {
      sc.controller.vehicle = sc.vehicle;  // an FMU controller brings its own design (the status's U uses this)
    } else {
      sc.controller = controllers::rebind_vehicle(sc.controller, sc.vehicle);
    }
  }
  if (!ns.empty()) sc.simulation.ns = ns;
  if (sc.simulation.faults.active()) {
    throw io::ConfigError((sc.path.empty() ? std::string("scenario") : sc.path) +
                          ": message_faults: message loss and delay are injected by the in-process transport only "
                          "(quadcosim run without --transport dds); over DDS use tc netem (docs/reliability.md)");
  }
  return sc;
}

void wait_until(dds::DdsTransport& transport, std::int64_t deadline_ns) {
  // (the timer slack matters for the blocking part)
  static const bool slack_set = prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) == 0;
  (void)slack_set;
  // Block on the waitset (delivering messages) until shortly before the deadline, then spin on the
  // clock for the rest: a blocked thread's wake-up lands tens of microseconds late, and on this VM the
  // waitset's timed wait and the spin's DDS work sometimes overran a 200 us margin by up to 2 ms
  // (controller alone, idle machine: period jitter p99 462 us with 200 us, 14 us with 1 ms).
  constexpr std::int64_t kSpinNs = 1'000'000;
  for (std::int64_t left; (left = deadline_ns - steady_ns()) > kSpinNs;) transport.spin_once(left - kSpinNs);
  transport.spin_once(0);
  while (steady_ns() < deadline_ns) {
  }
}

void DdsDriverHost::wait(std::int64_t timeout_ns, const std::function<bool()>& woken) {
  if (arrival_) {
    if (woken) {
      arrival_->wait_until(woken, timeout_ns);
    } else {
      arrival_->wait(timeout_ns);
    }
  } else if (woken) {
    transport_.spin_until(woken, timeout_ns);
  } else {
    transport_.spin_once(timeout_ns);
  }
}

void DdsDriverHost::wait_until(std::int64_t deadline_ns) {
  if (precise_ && !arrival_) {
    hosts::wait_until(transport_, deadline_ns);
  } else {
    DriverHost::wait_until(deadline_ns);
  }
}

std::string lockstep_timeout_message(const dds::DdsTransport& transport, const sim::Topics& topics,
                                     const sim::TickClock& clock, sim::Tick k, double timeout_s,
                                     const std::string& policy) {
  int typed = 0;  // writers of the typed command topics, whose header.stamp must name the tick
  for (const std::string& t : topics.level_commands) typed += transport.matched_writers(t);
  return fmt::format(
      "plant: lockstep timeout: no motor command on {} for tick {} (t = {} s) after {} s; "
      "matched command writers: {}{}; policy: {}\n",
      topics.motor_commands, k, clock.seconds(k), timeout_s, transport.matched_writers(topics.motor_commands),
      typed == 0 ? std::string()
                 : fmt::format(" (and {} on {}/cmd/<level>: a typed command answers the tick its header.stamp "
                               "names, {} ns here)",
                               typed, topics.ns, clock.ns(k)),
      policy);
}

bool DdsDriverHost::stop_requested() { return hosts::stop_requested(); }

void DdsDriverHost::deliver_on_arrival(bool on) {
  if (!on) {
    arrival_.reset();
    return;
  }
  if (arrival_) return;
  arrival_.emplace(transport_);
  if (on_delivery_) arrival_->after_each(on_delivery_);
}

std::string use_realtime_priority(int priority) {
  if (priority <= 0) return {};
  sched_param p{};
  p.sched_priority = priority;
  if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p); rc != 0) {
    return std::string("SCHED_FIFO priority ") + std::to_string(priority) + " refused: " + std::strerror(rc);
  }
  return {};
}

std::string parse_cpu_list(const std::string& text, std::vector<int>& cpus) {
  cpus.clear();
  // CPU numbers up to CPU_SETSIZE - 1 (1023): what a cpu_set_t holds.
  auto number = [](const std::string& t, int& v) {
    if (t.empty() || t.size() > 4 || t.find_first_not_of("0123456789") != std::string::npos) return false;
    v = std::stoi(t);
    return v < CPU_SETSIZE;
  };
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::size_t dash = item.find('-');
    int lo = 0, hi = 0;
    const bool ok = dash == std::string::npos ? number(item, lo) && number(item, hi)
                                              : number(item.substr(0, dash), lo) && number(item.substr(dash + 1), hi);
    if (!ok || lo > hi) {
      return "'" + text + "' is not a CPU list (e.g. 0, 0,2 or 0-3; CPUs 0.." + std::to_string(CPU_SETSIZE - 1) +
             "): bad item '" + item + "'";
    }
    for (int c = lo; c <= hi; ++c) cpus.push_back(c);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  std::sort(cpus.begin(), cpus.end());
  cpus.erase(std::unique(cpus.begin(), cpus.end()), cpus.end());
  return {};
}

std::string use_cpus(const std::string& list) {
  if (list.empty()) return {};
  std::vector<int> cpus;
  if (std::string err = parse_cpu_list(list, cpus); !err.empty()) return err;
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int c : cpus) CPU_SET(c, &set);
  if (sched_setaffinity(0, sizeof(set), &set) != 0) {
    const int err = errno;
    return "CPUs " + list + " refused: " + std::strerror(err) +
           (err == EINVAL ? " (none of them is online and allowed here; see nproc / taskset -p $$)" : "");
  }
  // Threads started before (the stop deadline's watcher, an interpreter's) are pinned too: the
  // affinity is per thread, and only threads started from now on inherit the caller's.
  std::error_code ec;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    const pid_t tid = static_cast<pid_t>(std::strtol(task.path().filename().c_str(), nullptr, 10));
    if (tid > 0) sched_setaffinity(tid, sizeof(set), &set);  // a thread that ended meanwhile: nothing to pin
  }
  return {};
}

std::vector<int> two_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> cpus;
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return cpus;
  for (int c = 0; c < CPU_SETSIZE && cpus.size() < 2; ++c) {
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  }
  if (cpus.size() < 2) cpus.clear();
  return cpus;
}

void pin_apart(std::vector<std::string>& plant_args, std::vector<std::string>& controller_args) {
  const std::vector<int> cpus = two_cpus();
  if (cpus.empty()) {
    std::cerr << "run: --pin: fewer than two CPUs available here; plant and controller not pinned\n";
    return;
  }
  plant_args.insert(plant_args.end(), {"--cpus", std::to_string(cpus[0])});
  controller_args.insert(controller_args.end(), {"--cpus", std::to_string(cpus[1])});
}

void PeriodJitter::add(std::int64_t now_ns) {
  if (last_ns_ >= 0) jitter_ns_.push_back(std::llabs(now_ns - last_ns_ - period_ns_));
  last_ns_ = now_ns;
}

nlohmann::json PeriodJitter::figures() const {
  std::vector<std::int64_t> j = jitter_ns_;
  std::sort(j.begin(), j.end());
  auto pct = [&](double q) { return j.empty() ? 0.0 : static_cast<double>(analysis::percentile_lower(j, q)) / 1e3; };
  return {{"period_jitter_us_p50", pct(0.5)},
          {"period_jitter_us_p99", pct(0.99)},
          {"period_jitter_us_max", pct(1.0)},
          {"periods", j.size()}};
}

void write_stats(const std::string& path, const nlohmann::json& stats) {
  std::ofstream f(path);
  f << stats.dump() << '\n';
  if (!f) std::cerr << "warning: cannot write statistics to " << path << '\n';
}

void use_sensor_qos(dds::DdsTransport& transport, const sim::Topics& topics) {
  for (const auto* t : {&topics.pose, &topics.velocity, &topics.imu}) {
    transport.set_qos(*t, dds::QosProfile::sensor_data());
  }
}

}  // namespace quadcosim::hosts
