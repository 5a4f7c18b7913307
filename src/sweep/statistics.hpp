// Summary statistics of one figure over a sweep's runs.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace quadcosim::sweep {

/// Count, missing runs and, when count > 0, min, max, mean, sample standard deviation (n - 1; 0 for a
/// single value) and the 5/25/50/75/95th percentiles of the values a figure took
/// (analysis::percentile_linear).
struct FigureStats {
  std::size_t count = 0;
  std::size_t missing = 0;  ///< runs that produced no value (figure absent, run failed)
  double min = 0.0, max = 0.0, mean = 0.0, std = 0.0;
  double p5 = 0.0, p25 = 0.0, p50 = 0.0, p75 = 0.0, p95 = 0.0;
};

/// The distribution of `values` (each run's value, nullopt where the run has none).
FigureStats figure_stats(const std::vector<std::optional<double>>& values);

}  // namespace quadcosim::sweep
