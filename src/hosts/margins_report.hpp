// The report of `quadcosim margins` (docs/margins.md): gain, phase and delay margins of every loop of
// a scenario's controller about level hover. The paper controller's are analytic: linearised, sampled
// at the controller's rate with the scenario's command delay and sensor latencies
// (analysis/hover_loops.hpp). Any other controller's (registered, Python, FMU), and the paper's too
// when asked, are measured in the closed-loop simulation by injecting sinusoids where the loop is
// broken (analysis/measured_margins.hpp). The report is a JSON document, a table and the response
// CSVs; the front end prints and writes them.
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "analysis/hover_loops.hpp"
#include "analysis/measured_margins.hpp"
#include "hosts/margins_setup.hpp"

namespace quadcosim::hosts {

/// What the margins of a scenario will be: its setup, and whether they are analytic (the paper
/// controller: its loops about hover), measured, or both.
struct MarginsPlan {
  MarginsSetup setup;
  std::vector<analysis::HoverLoop> loops;  ///< the analytic loops (empty unless analytic)
  bool analytic = false;
  bool measured = false;
};

/// The plan for the scenario at `path` (the defaults when empty; `controller_type`, when not empty,
/// replaces its controller.type); `measure` measures the paper controller's margins too. Throws
/// io::ConfigError (bad file), control::CareError (a failed LQR design) and std::invalid_argument
/// naming the scenario when the vehicle cannot be linearised about hover.
MarginsPlan plan_margins(const std::string& path, const std::string& controller_type, bool measure,
                         const io::ScenarioResolvers& resolvers);

struct MarginsReport {
  nlohmann::json doc;  ///< margins.json
  std::string table;   ///< margins.txt, and what is printed without --json
  /// frequency_response.csv with its header (analytic, when asked for), else empty
  std::string frequency_response_csv;
  /// measured_response.csv with its header (measured), else empty
  std::string measured_response_csv;
  bool all_stable = true;  ///< every analytic loop closed-loop stable and every measured one stayed in hover
};

/// Computes the margins `plan` says, the measured ones with `measurement` (its progress, a line a loop,
/// on `log`); `response_csv` also samples the analytic loops' frequency response for its CSV.
MarginsReport margins_report(const MarginsPlan& plan, const analysis::MeasurementOptions& measurement,
                             bool response_csv, std::ostream& log);

}  // namespace quadcosim::hosts
