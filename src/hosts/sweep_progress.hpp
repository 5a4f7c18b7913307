// `quadcosim sweep`'s progress line on stderr (hosts/sweep_runs.cpp).
#pragma once

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <string>
#include <utility>

namespace quadcosim::hosts {

/// Progress of the runs on stderr: on a terminal one line rewritten in place (at most 5 times a second),
/// else a line every `every_s` seconds (each run with 0); always the last count. Only stderr: what
/// the sweep writes does not depend on it. Called from run_many's `finished`, one call at a time.
class SweepProgress {
 public:
  SweepProgress(std::string name, int total, int done_before, int passed_before, double every_s)
      : name_(std::move(name)),
        total_(total),
        done_(done_before),
        passed_(passed_before),
        done_before_(done_before),
        tty_(isatty(STDERR_FILENO) == 1),
        every_s_(tty_ ? 0.2 : every_s),
        start_(std::chrono::steady_clock::now()),
        last_(start_) {}

  void finished(bool passed) {
    ++done_;
    passed_ += passed ? 1 : 0;
    const auto now = std::chrono::steady_clock::now();
    if (done_ < total_ && std::chrono::duration<double>(now - last_).count() < every_s_) return;
    last_ = now;
    print(now);
  }

  // The last count, and the end of the line on a terminal (before anything else is printed).
  void end() {
    if (done_ == printed_) {
      if (tty_ && printed_ >= 0) std::cerr << '\n';
      return;
    }
    print(std::chrono::steady_clock::now());
    if (tty_) std::cerr << '\n';
  }

 private:
  void print(std::chrono::steady_clock::time_point now) {
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const int flown = done_ - done_before_;  // this command's runs: what the time left is estimated from
    const std::string left = done_ >= total_ ? "done"
                             : flown > 0 ? fmt::format("about {} left", duration(elapsed / flown * (total_ - done_)))
                                         : "time left unknown";
    const std::string line =
        fmt::format("sweep {}: {}/{} runs done, {} passed ({:.1f} %), {} elapsed, {}", name_, done_, total_, passed_,
                    done_ > 0 ? 100.0 * passed_ / done_ : 0.0, duration(elapsed), left);
    if (tty_) {
      std::cerr << "\r\033[K" << line << std::flush;  // the line rewritten in place
    } else {
      std::cerr << line << std::endl;
    }
    printed_ = done_;
  }

  static std::string duration(double s) {
    if (s < 60.0) return fmt::format("{:.1f} s", s);
    const auto whole = static_cast<long long>(std::llround(s));
    if (whole < 3600) return fmt::format("{}:{:02d} min", whole / 60, whole % 60);
    return fmt::format("{}:{:02d}:{:02d} h", whole / 3600, (whole / 60) % 60, whole % 60);
  }

  std::string name_;
  int total_, done_, passed_, done_before_;
  int printed_ = -1;  ///< the count last printed
  bool tty_;
  double every_s_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace quadcosim::hosts
