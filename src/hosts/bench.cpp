// hosts/bench.hpp: the parts of `quadcosim bench`, each measured by running the framework.
#include "hosts/bench.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "baseline/baseline_setup.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "hosts/bench_runs.hpp"
#include "hosts/node_common.hpp"
#include "io/scenario.hpp"

namespace quadcosim::hosts {

namespace fs = std::filesystem;

namespace {

void note(const std::string& s) { std::cerr << "bench: " << s << std::endl; }

double baseline_rtf(const io::Scenario& sc, double sim_s) {
  const double dt = sc.simulation.plant.clock.period_s();
  const long ticks = static_cast<long>(sim_s / dt + 0.5);
  const controllers::PaperController* paper = controllers::paper_controller(sc.controller);
  if (!paper) throw std::invalid_argument("the BASELINE loop flies the paper controller (controller.type: paper)");
  baseline::BaselineLoop loop = baseline::make_baseline(sc.controller.vehicle, paper->params(), 10.0);
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k <= ticks; ++k) loop.tick(k, dt);
  const double rtf = sim_s / seconds_since(t0);
  if (!std::isfinite(loop.state().x[2])) note("baseline loop diverged");
  return rtf;
}

/// Largest n with rate(n) >= 1: doubling from `start` (up to `cap`), then `bisections` halvings of
/// the interval between the last good and the first bad n. 0 when even `start` is too slow.
template <class Rate>
int largest_at_real_time(int start, int cap, int bisections, Rate rate) {
  int good = 0, bad = 0;
  for (int n = start; n <= cap; n *= 2) {
    const double r = rate(n);
    note(fmt::format("  {} vehicles: {:.2f}x real time", n, r));
    if (r >= 1.0) {
      good = n;
    } else {
      bad = n;
      break;
    }
  }
  if (good == 0 || bad == 0) return good;
  for (int i = 0; i < bisections && bad - good > 1; ++i) {
    const int mid = good + (bad - good) / 2;
    const double r = rate(mid);
    note(fmt::format("  {} vehicles: {:.2f}x real time", mid, r));
    (r >= 1.0 ? good : bad) = mid;
  }
  return good;
}

double ddsperf_roundtrip_us(const fs::path& tmp, double seconds) {
  const char* domain = std::getenv("ROS_DOMAIN_ID");
  const std::string d = domain && *domain ? domain : "0";
  const std::string cmd = fmt::format(
      "command -v ddsperf >/dev/null 2>&1 || exit 0; "
      "timeout {0} ddsperf -D {1} -i {2} pong >/dev/null 2>&1 & pong=$!; "
      "timeout {0} ddsperf -D {1} -i {2} ping > {3} 2>&1; kill $pong 2>/dev/null; wait $pong 2>/dev/null; true",
      static_cast<int>(seconds) + 10, static_cast<int>(seconds), d, (tmp / "ping.log").string());
  if (std::system(cmd.c_str()) != 0) return NAN;
  // ddsperf prints lines like "... mean 25.1us min ... 50% 24.3us 90% ... 99% ..."; take the last.
  std::ifstream f(tmp / "ping.log");
  double v = NAN;
  for (std::string line; std::getline(f, line);) {
    const auto at = line.find(" 50% ");
    if (at != std::string::npos) v = std::atof(line.c_str() + at + 5);
  }
  return v;
}

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) && v > 0 ? nlohmann::json(v) : nlohmann::json(nullptr);
}

}  // namespace

nlohmann::json run_bench(const BenchOptions& o, const io::ScenarioResolvers& resolvers) {
  const io::Scenario paper = io::load_scenario(o.scenario, resolvers);
  const io::Scenario swarm = io::load_scenario(o.swarm_scenario, resolvers);
  const bool q = o.quick;
  const auto all_start = std::chrono::steady_clock::now();
  auto want = [&](const char* part) { return o.only.empty() || o.only == part; };
  const fs::path tmp = fs::temp_directory_path() / fmt::format("quadcosim-bench-{}", ::getpid());
  fs::create_directories(tmp);
  nlohmann::json j;
  j["quick"] = q;

  if (want("inproc")) {
    const double s = o.seconds > 0 ? o.seconds : (q ? 20.0 : 600.0);
    note(fmt::format("in-process, one vehicle, {} s simulated", s));
    if (o.only.empty() || !o.seconds) {
      // Interleaved, best of each: a slow minute of the host (seen here: the same binary 30 %
      // slower for a few minutes) then slows both rather than one side of the ratio.
      // The BASELINE loop is the paper controller written out by hand: with another controller
      // there is nothing to compare against, so its figures are null.
      const bool baseline = controllers::paper_controller(paper.controller) != nullptr;
      if (!baseline) {
        note(fmt::format("baseline_rtf skipped: the BASELINE loop flies the paper controller, {} flies '{}'",
                         o.scenario, paper.controller.type()));
      }
      double r = 0.0, b = 0.0;
      for (int rep = 0; rep < (q ? 1 : 9); ++rep) {
        r = std::max(r, inproc_rtf(paper, s));
        if (baseline) b = std::max(b, baseline_rtf(paper, s));
      }
      j["inproc_rtf"] = r;
      j["baseline_rtf"] = baseline ? nlohmann::json(b) : nlohmann::json(nullptr);
      j["inproc_vs_baseline"] = baseline ? nlohmann::json(r / b) : nlohmann::json(nullptr);
    } else {
      j["inproc_rtf"] = inproc_rtf(paper, s);  // one run of exactly --seconds (for callgrind)
    }
  }
  // The DDS parts again with the plant and the controller each on its own CPU (--cpus).
  const std::vector<int> pin = two_cpus();
  j["pinned_cpus"] = pin.empty() ? nlohmann::json(nullptr) : nlohmann::json(pin);
  if (want("dds")) {
    const double s = o.seconds > 0 ? o.seconds : (q ? 4.0 : 120.0);
    for (const bool pinned : {false, true}) {
      if (pinned && pin.empty()) break;
      const std::string suffix = pinned ? "_pinned" : "";
      note(fmt::format("DDS lockstep, one vehicle, {} s simulated{}", s,
                       pinned ? fmt::format(", plant on CPU {}, controller on CPU {}", pin[0], pin[1]) : ""));
      const NodeRun r = run_nodes(tmp, o.scenario, s, 0, false, 0, pinned);
      j["dds_lockstep_rtf" + suffix] = r.plant.is_object() ? r.plant.value("real_time_factor", 0.0) : 0.0;
      j["dds_cmd_roundtrip_us_p50" + suffix] = r.plant.is_object() ? r.plant.value("roundtrip_us_p50", 0.0) : 0.0;
      j["dds_cmd_roundtrip_us_p99" + suffix] = r.plant.is_object() ? r.plant.value("roundtrip_us_p99", 0.0) : 0.0;
    }
    if (!q) {
      note("ddsperf ping/pong, 5 s");
      j["ddsperf_roundtrip_us_p50"] = number_or_null(ddsperf_roundtrip_us(tmp, 5.0));
    }
  }
  if (want("realtime")) {
    // The controller's 50 Hz loop under normal scheduling, then (the real-time setup) under
    // SCHED_FIFO when the machine allows it.
    const double s = q ? 2.0 : 20.0;
    auto measure = [&](int priority, const std::string& suffix) {
      note(fmt::format("real time, one vehicle, {} s{}", s,
                       priority > 0 ? fmt::format(", SCHED_FIFO {}", priority) : ""));
      const NodeRun r = run_nodes(tmp, o.scenario, s, 0, true, priority);
      for (const char* k : {"p50", "p99", "max"}) {
        const std::string key = std::string("period_jitter_us_") + k;
        j["realtime_" + key + suffix] = r.controller.is_object() ? r.controller.value(key, 0.0) : 0.0;
      }
    };
    measure(0, "_normal");
    if (o.rt_priority > 0) {
      measure(o.rt_priority, "");
      j["realtime_rt_priority"] = o.rt_priority;
    } else {
      for (const char* k : {"p50", "p99", "max"}) {
        j[std::string("realtime_period_jitter_us_") + k] = j[std::string("realtime_period_jitter_us_") + k + "_normal"];
      }
      j["realtime_rt_priority"] = 0;
    }
  }
  if (want("swarm_inproc")) {
    const double s = q ? 0.5 : 2.0;
    note(fmt::format("in-process swarm, {} s simulated per trial", s));
    j["swarm_inproc_vehicles_at_rt"] = largest_at_real_time(q ? 256 : 4096, q ? 1024 : 1 << 20, q ? 0 : 5,
                                                            [&](int n) { return swarm_inproc_rtf(swarm, n, s); });
    j["swarm_inproc_trial_s"] = s;
  }
  if (want("swarm_dds")) {
    const double s = q ? 1.0 : 4.0;
    for (const bool pinned : {false, true}) {
      if (pinned && pin.empty()) break;
      note(fmt::format("DDS swarm, {} s simulated per trial{}", s, pinned ? ", plant and controller pinned" : ""));
      j[pinned ? "swarm_dds_vehicles_at_rt_pinned" : "swarm_dds_vehicles_at_rt"] =
          largest_at_real_time(q ? 4 : 32, q ? 8 : 8192, q ? 0 : 4, [&](int n) {
            const NodeRun r = run_nodes(tmp, o.swarm_scenario, s, n, false, 0, pinned);
            return r.plant.is_object() ? r.plant.value("real_time_factor", 0.0) : 0.0;
          });
    }
    j["swarm_dds_trial_s"] = s;
  }
  j["bench_wall_s"] = seconds_since(all_start);
  std::error_code ec;
  fs::remove_all(tmp, ec);
  return j;
}

}  // namespace quadcosim::hosts
