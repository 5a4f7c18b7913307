// isolation/child.hpp: a child process per instance of foreign code, a SOCK_SEQPACKET socket pair.
#include "isolation/child.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <iostream>

namespace quadcosim::isolation {

namespace {
std::atomic<bool (*)()> g_stop_check{nullptr};

bool stop_asked() {
  const auto stop = g_stop_check.load();
  return stop != nullptr && stop();
}

int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}
}  // namespace

bool send_all(int fd, const std::vector<std::uint8_t>& bytes) {
  for (;;) {
    const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n >= 0) return static_cast<std::size_t>(n) == bytes.size();
    if (errno != EINTR) return false;
  }
}

bool receive(int fd, std::vector<std::uint8_t>& into) {
  for (;;) {
    const ssize_t size = ::recv(fd, nullptr, 0, MSG_PEEK | MSG_TRUNC);
    if (size < 0 && errno == EINTR) continue;
    if (size <= 0) return false;
    into.resize(static_cast<std::size_t>(size));
    const ssize_t n = ::recv(fd, into.data(), into.size(), 0);
    if (n < 0 && errno == EINTR) continue;
    return n == size;
  }
}

std::string describe_end(int status) {
  if (WIFEXITED(status)) return fmt::format("exited with status {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* name = strsignal(sig);
    const bool crash = sig == SIGSEGV || sig == SIGBUS || sig == SIGABRT || sig == SIGFPE || sig == SIGILL;
    return fmt::format("was killed by signal {} ({}){}", sig, name != nullptr ? name : "?",
                       crash ? ": it crashed" : "");
  }
  return fmt::format("ended (wait status {})", status);
}

void set_stop_check(bool (*stop_requested)()) { g_stop_check.store(stop_requested); }

bool stop_requested() { return stop_asked(); }

std::int64_t Child::now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

Child::Child(const std::string& who, const std::function<void(int fd)>& serve) {
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) != 0) {
    throw std::runtime_error(
        fmt::format("{}: cannot make a socket pair for its process: {}", who, std::strerror(errno)));
  }
  // What this process buffered must not be written twice (once more by the child at its exit).
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error(fmt::format("{}: cannot start its process: {}", who, std::strerror(err)));
  }
  if (pid_ == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) _exit(0);  // the parent died before prctl took effect
    ::signal(SIGINT, SIG_IGN);
    ::signal(SIGTERM, SIG_DFL);
    ::signal(SIGPIPE, SIG_IGN);
    ::close(fds[0]);
    serve(fds[1]);
    _exit(0);
  }
  ::close(fds[1]);
  fd_ = fds[0];
}

Child::~Child() {
  if (fd_ >= 0) ::close(fd_);
  if (pid_ > 0 && !reaped_) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) != pid_) {
      ::kill(pid_, SIGKILL);
      wait_for(pid_);
    }
  }
}

Child::Wait Child::next(std::vector<std::uint8_t>& into, std::int64_t deadline_ns) {
  if (reaped_) return Wait::kEnded;
  pollfd p{fd_, POLLIN, 0};
  for (;;) {
    int wait_ms = 50;
    if (deadline_ns > 0) {
      const std::int64_t left = deadline_ns - now_ns();
      if (left <= 0) return Wait::kTimedOut;
      wait_ms = static_cast<int>(std::min<std::int64_t>(50, (left + 999'999) / 1'000'000));
    }
    const int ready = ::poll(&p, 1, wait_ms);
    if (ready < 0 && errno != EINTR) return Wait::kEnded;
    if (ready <= 0) {
      if (stop_asked()) return Wait::kStopped;
      continue;
    }
    return receive(fd_, into) ? Wait::kMessage : Wait::kEnded;
  }
}

std::string Child::reap() {
  if (!reaped_) {
    const int status = wait_for(pid_);
    reaped_ = true;
    end_ = describe_end(status);
  }
  return end_;
}

std::string Child::kill(const std::string& why) {
  if (!reaped_) {
    ::kill(pid_, SIGKILL);
    wait_for(pid_);
    reaped_ = true;
    end_ = why;
  }
  return end_;
}

void Child::finish(int grace_ms) {
  if (reaped_) return;
  ::shutdown(fd_, SHUT_RDWR);
  for (int waited = 0; waited < grace_ms; waited += 10) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      reaped_ = true;
      end_ = describe_end(status);
      return;
    }
    if (stop_asked()) break;
    ::usleep(10'000);
  }
  kill("killed after it did not end when asked");
}

}  // namespace quadcosim::isolation
