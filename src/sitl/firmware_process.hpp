// The firmware as a child process that always ends with the run: it runs in a process group of its
// own (so its own children go with it), dies with its parent (PR_SET_PDEATHSIG, SIGKILL; a child whose
// parent is already gone does not start), and is ended (SIGTERM to the group, then SIGKILL) and reaped
// when this object goes, on every path. Its stdout and stderr go to a log file; it runs in a folder of
// its own (ArduPilot writes its eeprom and logs to the current folder).
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace quadcosim::sitl {

class FirmwareProcess {
 public:
  /// Starts argv (argv[0] the program) in `work_dir` with output to `log_path`. Throws
  /// std::runtime_error naming the program when it cannot.
  FirmwareProcess(const std::vector<std::string>& argv, const std::string& work_dir, const std::string& log_path);
  ~FirmwareProcess();
  FirmwareProcess(const FirmwareProcess&) = delete;
  FirmwareProcess& operator=(const FirmwareProcess&) = delete;

  pid_t pid() const { return pid_; }
  /// How the process ended, as isolation::describe_end says it ("exited with status 1", "was killed
  /// by signal 6 (Aborted): it crashed"), or nothing while it runs. Does not block.
  std::optional<std::string> ended();
  /// Ends the process group: SIGTERM, up to grace_s, then SIGKILL; reaps. Idempotent.
  void stop(double grace_s = 1.0);
  /// The last `lines` lines of the log (for error messages).
  std::string log_tail(int lines = 8) const;
  const std::string& log_path() const { return log_path_; }

 private:
  pid_t pid_ = -1;
  std::optional<std::string> end_;
  std::string log_path_;
};

}  // namespace quadcosim::sitl
