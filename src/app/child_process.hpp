// Child processes that are always ended: a ChildProcess kills (SIGTERM, then SIGKILL) and reaps its
// process when it goes out of scope, whatever path the parent takes.
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace quadcosim::app {

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

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
};

/// Runs a plant and a controller process side by side until the plant ends (the controller is then
/// stopped): 0 when the plant succeeded, 2 when it refused its input, 4 when it failed otherwise or
/// the controller exited first, 130 on Ctrl-C (both stopped). Messages go to stderr prefixed "run:".
int run_plant_and_controller(const std::vector<std::string>& plant_argv,
                             const std::vector<std::string>& controller_argv);

/// Path of the running executable (/proc/self/exe).
std::string self_executable();

}  // namespace quadcosim::app
