// The nearest known name to a misspelt one, for "unknown key" errors ("simulaton: unknown key; did
// you mean 'simulation'?"). Header-only and below every layer, so that control, controllers, fmi
// and io use it without linking each other; Debian packages no small C++ edit-distance library, and
// the few lines here are all it takes.
#pragma once

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::util {

/// Edits (insert, delete, replace, swap of two neighbours) turning `a` into `b`, letters compared
/// without case: a swap counts one, as typing `q_angel` for `q_angle` is one slip.
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  const auto same = [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  };
  // Three rows of the distance table: two back (for swaps), one back, this one.
  std::vector<std::size_t> before(b.size() + 1), last(b.size() + 1), row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) last[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t replace = last[j - 1] + (same(a[i - 1], b[j - 1]) ? 0 : 1);
      row[j] = std::min({last[j] + 1, row[j - 1] + 1, replace});
      if (i > 1 && j > 1 && same(a[i - 1], b[j - 2]) && same(a[i - 2], b[j - 1])) {
        row[j] = std::min(row[j], before[j - 2] + 1);
      }
    }
    std::swap(before, last);
    std::swap(last, row);
  }
  return last[b.size()];
}

/// The candidate closest to `given` when one is close: at most one edit per three letters (at least
/// one edit), or `given` with its unit left off (`duration` for `duration_s`). Ties go to the first
/// in `candidates`; "" when none is close.
inline std::string nearest_name(std::string_view given, const std::vector<std::string>& candidates) {
  const std::size_t allowed = std::max<std::size_t>(1, given.size() / 3);
  std::string best;
  std::size_t best_distance = allowed + 1;
  for (const std::string& c : candidates) {
    if (c == given) continue;
    std::size_t d = edit_distance(given, c);
    if (d > allowed && given.size() >= 3 && c.size() > given.size() && c.compare(0, given.size(), given) == 0 &&
        c[given.size()] == '_') {
      d = allowed;  // a unit suffix left off
    }
    if (d < best_distance && d < std::max(given.size(), c.size())) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

/// "; did you mean 'simulation'?" when a candidate is close to `given`, else "".
inline std::string did_you_mean(std::string_view given, const std::vector<std::string>& candidates) {
  const std::string near = nearest_name(given, candidates);
  return near.empty() ? std::string() : "; did you mean '" + near + "'?";
}

}  // namespace quadcosim::util
