#include "sitl/firmware_process.hpp"

#include <arpa/inet.h>
#include <dirent.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <thread>

#include "isolation/child.hpp"

extern char** environ;

namespace quadcosim::sitl {

FirmwareProcess::FirmwareProcess(const std::vector<std::string>& argv, const std::string& work_dir,
                                 const std::string& log_path, const std::vector<std::string>& env, int cpu)
    : log_path_(log_path) {
  if (argv.empty()) throw std::runtime_error("firmware: no program to start");
  // Everything the child needs is made before fork(): between fork and exec only async-signal-safe calls.
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<char*> envp;
  auto name_of = [](std::string_view e) { return e.substr(0, e.find('=') + 1); };
  for (char** e = environ; *e; ++e) {
    const std::string_view name = name_of(*e);
    if (std::none_of(env.begin(), env.end(), [&](const std::string& x) { return name_of(x) == name; })) {
      envp.push_back(*e);
    }
  }
  for (const std::string& e : env) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);
  const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log < 0) throw std::runtime_error("firmware: cannot write its log " + log_path + ": " + std::strerror(errno));
  cpu_set_t one_cpu;
  CPU_ZERO(&one_cpu);
  if (cpu >= 0) CPU_SET(cpu, &one_cpu);
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0) {
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    if (cpu >= 0 && ::sched_setaffinity(0, sizeof(one_cpu), &one_cpu) != 0) ::_exit(125);
    ::signal(SIGINT, SIG_IGN);  // Ctrl-C is the parent's to handle: it ends the group
    if (::chdir(work_dir.c_str()) != 0) ::_exit(126);
    ::dup2(log, STDOUT_FILENO);
    ::dup2(log, STDERR_FILENO);
    const int null_in = ::open("/dev/null", O_RDONLY);
    if (null_in >= 0) ::dup2(null_in, STDIN_FILENO);
    ::execve(args[0], args.data(), envp.data());
    ::_exit(127);
  }
  const int fork_errno = errno;
  ::close(log);
  if (pid_ < 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(fork_errno));
  ::setpgid(pid_, pid_);  // also from this side: no race with a kill of the group right after fork
}

FirmwareProcess::~FirmwareProcess() {
  stop();
  for (const auto& [tid, fd] : thread_stat_fds_) ::close(fd);
}

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

namespace {

// The state letter and the process group of /proc/.../stat ("pid (comm) S ppid pgrp ..."); the name
// may hold spaces and parentheses: read after the last ')'.
bool read_stat(const std::string& path, char& state, long& pgrp) {
  char buf[512];
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const ssize_t n = ::read(fd, buf, sizeof(buf) - 1);
  ::close(fd);
  if (n <= 0) return false;
  buf[n] = '\0';
  const char* close = std::strrchr(buf, ')');
  if (!close) return false;
  long ppid = 0;
  return std::sscanf(close + 1, " %c %ld %ld", &state, &ppid, &pgrp) == 3;
}

// True when no thread of process `pid` runs (R) or waits on the disk (D).
bool threads_idle(long pid) {
  const std::string dir = "/proc/" + std::to_string(pid) + "/task";
  DIR* d = ::opendir(dir.c_str());
  if (!d) return true;  // gone
  bool idle = true;
  while (const dirent* e = ::readdir(d)) {
    if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
    char state = 0;
    long pgrp = 0;
    if (read_stat(dir + "/" + e->d_name + "/stat", state, pgrp) && (state == 'R' || state == 'D')) {
      idle = false;
      break;
    }
  }
  ::closedir(d);
  return idle;
}

}  // namespace

bool FirmwareProcess::idle(bool whole_group, int* processes) const {
  if (pid_ <= 0 || end_) return true;
  if (!whole_group) {
    // Its threads' stat files stay open and are read again from the start (one system call each); the
    // list of threads is read again every call (new threads, gone ones).
    if (processes) *processes = 1;
    const std::string dir = "/proc/" + std::to_string(pid_) + "/task";
    DIR* d = ::opendir(dir.c_str());
    if (!d) return true;
    std::map<long, int> now;
    while (const dirent* e = ::readdir(d)) {
      if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
      const long tid = std::atol(e->d_name);
      auto it = thread_stat_fds_.find(tid);
      if (it != thread_stat_fds_.end()) {
        now.emplace(tid, it->second);
        thread_stat_fds_.erase(it);
      } else {
        const int fd = ::open((dir + "/" + e->d_name + "/stat").c_str(), O_RDONLY | O_CLOEXEC);
        if (fd >= 0) now.emplace(tid, fd);
      }
    }
    ::closedir(d);
    for (const auto& [tid, fd] : thread_stat_fds_) ::close(fd);
    thread_stat_fds_ = std::move(now);
    for (const auto& [tid, fd] : thread_stat_fds_) {
      char buf[512];
      const ssize_t n = ::pread(fd, buf, sizeof(buf) - 1, 0);
      if (n <= 0) continue;
      buf[n] = '\0';
      const char* close = std::strrchr(buf, ')');
      if (close && close[1] == ' ' && (close[2] == 'R' || close[2] == 'D')) return false;
    }
    return true;
  }
  DIR* d = ::opendir("/proc");
  if (!d) return threads_idle(pid_);
  bool idle = true;
  int seen = 0;
  while (const dirent* e = ::readdir(d)) {
    if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
    char state = 0;
    long pgrp = 0;
    if (!read_stat(std::string("/proc/") + e->d_name + "/stat", state, pgrp) || pgrp != pid_) continue;
    ++seen;
    if (state == 'Z') continue;
    if (idle && !threads_idle(std::atol(e->d_name))) idle = false;
  }
  ::closedir(d);
  if (processes) *processes = seen;
  return idle;
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

sockaddr_in loopback_address(int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  return a;
}

int bind_loopback(int type, int port) {
  const int fd = ::socket(AF_INET, type | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  const sockaddr_in a = loopback_address(port);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof(a)) != 0) {
    const int e = errno;
    ::close(fd);
    errno = e;
    return -1;
  }
  return fd;
}

int loopback_socket(int type, int& port) {
  const int fd = bind_loopback(type, 0);
  if (fd < 0) throw std::runtime_error(std::string("bind on 127.0.0.1: ") + std::strerror(errno));
  sockaddr_in a{};
  socklen_t len = sizeof(a);
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    const int e = errno;
    ::close(fd);
    throw std::runtime_error(std::string("getsockname on 127.0.0.1: ") + std::strerror(e));
  }
  port = ntohs(a.sin_port);
  return fd;
}

double wall_clock_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace quadcosim::sitl
