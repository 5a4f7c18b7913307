#include "hosts/child_process.hpp"

#include "hosts/signals.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace quadcosim::hosts {

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::string& output_path) {
  // Everything the child needs is made before fork(): between fork and exec only async-signal-safe
  // calls are allowed (this process may have threads).
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int out_fd = -1;
  if (!output_path.empty()) {
    out_fd = ::open(output_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (out_fd < 0) throw std::runtime_error("cannot open " + output_path + ": " + std::strerror(errno));
  }
  // A pipe that exec closes: the child writes errno into it when exec fails.
  int status_pipe[2];
  if (::pipe2(status_pipe, O_CLOEXEC) != 0) {
    if (out_fd >= 0) ::close(out_fd);
    throw std::runtime_error(std::string("cannot start ") + argv[0] + ": " + std::strerror(errno));
  }
  std::cout.flush();
  std::cerr.flush();
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0) {
    // Die with the parent, however it ends (SIGKILL included); if it is already gone, do not start.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) _exit(127);
    // The parent's SIGINT/SIGTERM handlers do not survive exec; dispositions and the mask reset.
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    if (out_fd >= 0) {
      ::dup2(out_fd, STDOUT_FILENO);
      ::dup2(out_fd, STDERR_FILENO);
    }
    ::execve(args[0], args.data(), environ);
    const int err = errno;
    [[maybe_unused]] const ssize_t n = ::write(status_pipe[1], &err, sizeof err);
    _exit(127);
  }
  const int fork_errno = errno;
  ::close(status_pipe[1]);
  if (out_fd >= 0) ::close(out_fd);
  if (pid_ < 0) {
    ::close(status_pipe[0]);
    throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(fork_errno));
  }
  int exec_errno = 0;
  ssize_t n;
  while ((n = ::read(status_pipe[0], &exec_errno, sizeof exec_errno)) < 0 && errno == EINTR) {
  }
  ::close(status_pipe[0]);
  if (n == static_cast<ssize_t>(sizeof exec_errno)) {
    wait(10.0);
    throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(exec_errno));
  }
}

ChildProcess::~ChildProcess() {
  if (!status_) stop(1.0);
}

std::optional<int> ChildProcess::wait(double timeout_s) {
  if (status_) return status_;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    int st = 0;
    const pid_t r = waitpid(pid_, &st, WNOHANG);
    if (r == pid_) {
      status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
      return status_;
    }
    if (r < 0 && errno != EINTR) {
      status_ = -1;
      return status_;
    }
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    // waitpid has no timeout; poll the child's state at a coarse interval.
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

int ChildProcess::stop(double grace_s) {
  if (status_) return *status_;
  kill(pid_, SIGTERM);
  if (auto st = wait(grace_s)) return *st;
  kill(pid_, SIGKILL);
  return wait(10.0).value_or(-1);
}

std::string self_executable() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("cannot find the running executable (/proc/self/exe)");
  return std::string(buf, static_cast<std::size_t>(n));
}

namespace {
/// "exited with status 3", "was killed by signal 9 (Killed)".
std::string how_it_ended(int status) {
  if (status > 128) {
    const char* name = strsignal(status - 128);
    return "was killed by signal " + std::to_string(status - 128) + " (" + (name ? name : "?") + ")";
  }
  return "exited with status " + std::to_string(status);
}
}  // namespace

int run_plant_and_controller(const std::vector<std::string>& plant_argv,
                             const std::vector<std::string>& controller_argv) {
  ChildProcess controller(controller_argv);
  ChildProcess plant(plant_argv);
  std::optional<int> plant_status;
  while (!(plant_status = plant.wait(0.1))) {
    if (stop_requested()) {
      // Each child handles SIGTERM by finishing its outputs; one stuck in a step is killed after the
      // grace period, so a Ctrl-C ends the run within about a second.
      std::cerr << "run: interrupted; stopping plant and controller\n";
      ::kill(plant.pid(), SIGTERM);
      ::kill(controller.pid(), SIGTERM);
      plant.stop(ChildProcess::kStopGraceS);
      controller.stop(0.05);  // it had the same second to end
      return 130;
    }
    if (auto c = controller.wait(0.0)) {
      std::cerr << "run: the controller " << how_it_ended(*c) << " before the plant finished; stopping the plant\n";
      plant.stop(ChildProcess::kStopGraceS);
      // The controller's own code (5: its step failed, 2: bad input, ...) says more than "gone".
      return (*c > 0 && *c < 128) ? *c : 4;
    }
  }
  controller.stop(ChildProcess::kStopGraceS);
  if (*plant_status != 0) {
    std::cerr << "run: the plant " << how_it_ended(*plant_status) << '\n';
    // Its own code (2 bad input, 3 an output not written, 4 no controller, 6 its FMU failed, 130);
    // killed by a signal it has none: 4.
    return *plant_status < 128 || *plant_status == 130 ? *plant_status : 4;
  }
  return 0;
}

}  // namespace quadcosim::hosts
