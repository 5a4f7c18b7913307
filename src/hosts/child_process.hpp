// Child processes that are always ended: a ChildProcess kills (SIGTERM, then SIGKILL) and reaps its
// process when it goes out of scope, whatever path the parent takes, and the child dies with its
// parent even when the parent cannot clean up (SIGKILL): PR_SET_PDEATHSIG (SIGKILL) is set between
// fork and exec, and a child whose parent is already gone then does not start.
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace quadcosim::hosts {

class ChildProcess {
 public:
  /// Starts `argv` (argv[0] is the program path) with the parent's environment and stdio.
  /// Throws std::runtime_error when it cannot.
  /// `output_path` (when not empty) receives the child's stdout and stderr instead.
  explicit ChildProcess(const std::vector<std::string>& argv, const std::string& output_path = "");
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  /// Waits up to timeout_s for the process to end; its exit status (128 + signal when killed), or
  /// nothing when it is still running.
  std::optional<int> wait(double timeout_s);
  /// SIGTERM, a grace period, then SIGKILL; returns the exit status.
  int stop(double grace_s = 3.0);
  /// The grace run gives its children on Ctrl-C: a node that is not stuck finishes its files in far
  /// less; one stuck in a foreign step is killed after it.
  static constexpr double kStopGraceS = 1.0;

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
};

/// Runs a plant and a controller process side by side until the plant ends (the controller is then
/// stopped): 0 when the plant succeeded; otherwise the plant's own exit code (2 bad input, 3 an output
/// not written, 4 no controller, 6 its FMU failed), or 4 when it was killed by a signal; when the
/// controller ends first, its own code (5: its step failed), or 4 when it exited 0 or was killed; 130
/// on Ctrl-C or SIGTERM (both stopped, within about kStopGraceS). Messages go to stderr prefixed "run:".
int run_plant_and_controller(const std::vector<std::string>& plant_argv,
                             const std::vector<std::string>& controller_argv);

/// Path of the running executable (/proc/self/exe).
std::string self_executable();

}  // namespace quadcosim::hosts
