#include "sweep/statistics.hpp"

#include <algorithm>
#include <cmath>

#include "analysis/percentile.hpp"

namespace quadcosim::sweep {

FigureStats figure_stats(const std::vector<std::optional<double>>& values) {
  FigureStats d;
  std::vector<double> v;
  v.reserve(values.size());
  for (const auto& x : values) {
    if (x) v.push_back(*x);
  }
  d.count = v.size();
  d.missing = values.size() - v.size();
  if (v.empty()) return d;
  double sum = 0.0;
  for (double x : v) sum += x;
  d.mean = sum / static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - d.mean) * (x - d.mean);
  d.std = v.size() > 1 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) : 0.0;
  std::sort(v.begin(), v.end());
  d.min = v.front();
  d.max = v.back();
  d.p5 = analysis::percentile_linear(v, 0.05);
  d.p25 = analysis::percentile_linear(v, 0.25);
  d.p50 = analysis::percentile_linear(v, 0.5);
  d.p75 = analysis::percentile_linear(v, 0.75);
  d.p95 = analysis::percentile_linear(v, 0.95);
  return d;
}

}  // namespace quadcosim::sweep
