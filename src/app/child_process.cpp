#include "app/child_process.hpp"

#include "app/signals.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace quadcosim::app {

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::string& output_path) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (!output_path.empty()) {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, output_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  }
  const int rc = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(rc));
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

int run_plant_and_controller(const std::vector<std::string>& plant_argv,
                             const std::vector<std::string>& controller_argv) {
  ChildProcess controller(controller_argv);
  ChildProcess plant(plant_argv);
  std::optional<int> plant_status;
  while (!(plant_status = plant.wait(0.1))) {
    if (stop_requested()) {
      std::cerr << "run: interrupted; stopping plant and controller\n";
      plant.stop();
      controller.stop();
      return 130;
    }
    if (auto c = controller.wait(0.0)) {
      std::cerr << "run: the controller exited early (status " << *c << "); stopping the plant\n";
      plant.stop();
      return 4;
    }
  }
  controller.stop();
  if (*plant_status != 0) {
    std::cerr << "run: the plant exited with status " << *plant_status << '\n';
    return *plant_status == 2 ? 2 : 4;
  }
  return 0;
}

}  // namespace quadcosim::app
