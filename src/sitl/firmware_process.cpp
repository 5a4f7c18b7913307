#include "sitl/firmware_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "isolation/child.hpp"

extern char** environ;

namespace quadcosim::sitl {

FirmwareProcess::FirmwareProcess(const std::vector<std::string>& argv, const std::string& work_dir,
                                 const std::string& log_path)
    : log_path_(log_path) {
  if (argv.empty()) throw std::runtime_error("firmware: no program to start");
  // Everything the child needs is made before fork(): between fork and exec only async-signal-safe calls.
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log < 0) throw std::runtime_error("firmware: cannot write its log " + log_path + ": " + std::strerror(errno));
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0) {
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    ::signal(SIGINT, SIG_IGN);  // Ctrl-C is the parent's to handle: it ends the group
    if (::chdir(work_dir.c_str()) != 0) ::_exit(126);
    ::dup2(log, STDOUT_FILENO);
    ::dup2(log, STDERR_FILENO);
    const int null_in = ::open("/dev/null", O_RDONLY);
    if (null_in >= 0) ::dup2(null_in, STDIN_FILENO);
    ::execve(args[0], args.data(), environ);
    ::_exit(127);
  }
  const int fork_errno = errno;
  ::close(log);
  if (pid_ < 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(fork_errno));
  ::setpgid(pid_, pid_);  // also from this side: no race with a kill of the group right after fork
}

FirmwareProcess::~FirmwareProcess() { stop(); }

std::optional<std::string> FirmwareProcess::ended() {
  if (end_ || pid_ <= 0) return end_;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    end_ = isolation::describe_end(status);
    ::kill(-pid_, SIGKILL);  // whatever it started goes with it
  }
  return end_;
}

void FirmwareProcess::stop(double grace_s) {
  if (pid_ <= 0 || end_) return;
  ::kill(-pid_, SIGTERM);
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
  while (std::chrono::steady_clock::now() < until) {
    if (ended()) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(-pid_, SIGKILL);
  int status = 0;
  ::waitpid(pid_, &status, 0);
  end_ = isolation::describe_end(status);
}

std::string FirmwareProcess::log_tail(int lines) const {
  std::ifstream in(log_path_);
  std::deque<std::string> tail;
  for (std::string line; std::getline(in, line);) {
    tail.push_back(line);
    if (static_cast<int>(tail.size()) > lines) tail.pop_front();
  }
  std::string out;
  for (const std::string& l : tail) out += "\n  | " + l;
  return out;
}

}  // namespace quadcosim::sitl
