#include "sweep/statistics.hpp"

#include <algorithm>
#include <cmath>

namespace quadcosim::sweep {

double percentile(const std::vector<double>& sorted, double q) {
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

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
  d.p5 = percentile(v, 0.05);
  d.p25 = percentile(v, 0.25);
  d.p50 = percentile(v, 0.5);
  d.p75 = percentile(v, 0.75);
  d.p95 = percentile(v, 0.95);
  return d;
}

}  // namespace quadcosim::sweep
