// The firmware as a child process that always ends with the run: it runs in a process group of its
// own (so its own children go with it), dies with its parent (PR_SET_PDEATHSIG, SIGKILL; a child whose
// parent is already gone does not start), and is ended (SIGTERM to the group, then SIGKILL) and reaped
// when this object goes, on every path. Its stdout and stderr go to a log file; it runs in a folder of
// its own (ArduPilot writes its eeprom and logs to the current folder).
#pragma once

#include <netinet/in.h>
#include <sys/types.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace quadcosim::sitl {

class FirmwareProcess {
 public:
  /// Starts argv (argv[0] the program) in `work_dir` with output to `log_path`, its environment this
  /// process's with the NAME=VALUE entries of `env` added (replacing any of the same name); with
  /// `cpu` >= 0 it (and what it starts) runs on that CPU only. Throws std::runtime_error naming the
  /// program when it cannot.
  FirmwareProcess(const std::vector<std::string>& argv, const std::string& work_dir, const std::string& log_path,
                  const std::vector<std::string>& env = {}, int cpu = -1);
  ~FirmwareProcess();
  FirmwareProcess(const FirmwareProcess&) = delete;
  FirmwareProcess& operator=(const FirmwareProcess&) = delete;

  pid_t pid() const { return pid_; }
  /// How the process ended, as isolation::describe_end says it ("exited with status 1", "was killed
  /// by signal 6 (Aborted): it crashed"), or nothing while it runs. Does not block.
  std::optional<std::string> ended();
  /// Ends the process group: SIGTERM, up to grace_s, then SIGKILL; reaps. Idempotent.
  void stop(double grace_s = 1.0);
  /// True when no thread of the firmware is running or waiting on the disk (every one asleep, waiting
  /// for time, input or a lock), read from /proc: its own threads, or with `whole_group` those of every
  /// process of its group (the shell of a start-up script and the commands it runs). The number of
  /// processes seen in the group, when asked. A process that is gone counts as idle.
  bool idle(bool whole_group, int* processes = nullptr) const;
  /// The last `lines` lines of the log (for error messages).
  std::string log_tail(int lines = 8) const;
  const std::string& log_path() const { return log_path_; }

 private:
  pid_t pid_ = -1;
  std::optional<std::string> end_;
  mutable std::map<long, int> thread_stat_fds_;  ///< its threads' /proc stat files, kept open (idle())
  std::string log_path_;
};

/// A socket on 127.0.0.1 at a port the system chooses (SOCK_DGRAM or SOCK_STREAM, close-on-exec);
/// `port` its number. Throws std::runtime_error naming the call that failed.
int loopback_socket(int type, int& port);
/// A socket (close-on-exec) bound to 127.0.0.1:port (0: one the system chooses), or -1 with errno
/// saying why (a port in use is an answer here, not an error: PX4's instances, Betaflight's fixed ports).
int bind_loopback(int type, int port);
/// 127.0.0.1:port.
sockaddr_in loopback_address(int port);

/// The monotonic clock [s], for wall-time limits.
double wall_clock_s();

}  // namespace quadcosim::sitl
