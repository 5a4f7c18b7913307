// fmi/isolated_instance.hpp: one child process per FMU instance, a SOCK_SEQPACKET socket pair between
// them, one datagram per request and per answer.
#include "fmi/isolated_instance.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <vector>

namespace quadcosim::fmi {

namespace {

std::atomic<bool (*)()> g_stop_check{nullptr};

enum class Op : std::uint8_t {
  kEnterInitialization = 1,
  kExitInitialization,
  kDoStep,
  kTerminate,
  kReset,
  kGetReal,
  kSetReal,
  kGetInteger,
  kSetInteger,
  kGetBoolean,
  kSetBoolean,
  kSetString,
  kFree,
};
constexpr std::uint8_t kLog = 'L', kAnswer = 'A', kFailed = 'F';

/// Bytes of a message: values appended as they are in memory (both ends are the same program).
class Writer {
 public:
  template <class T>
  Writer& put(const T& v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
    return *this;
  }
  template <class T>
  Writer& span(std::span<const T> v) {
    put(static_cast<std::uint64_t>(v.size()));
    const auto* p = reinterpret_cast<const std::uint8_t*>(v.data());
    bytes.insert(bytes.end(), p, p + v.size_bytes());
    return *this;
  }
  Writer& text(std::string_view s) {
    put(static_cast<std::uint64_t>(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
    return *this;
  }
  std::vector<std::uint8_t> bytes;
};

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> b) : b_(b) {}
  template <class T>
  T get() {
    T v{};
    take(&v, sizeof(T));
    return v;
  }
  template <class T>
  std::vector<T> vec() {
    std::vector<T> v(static_cast<std::size_t>(get<std::uint64_t>()));
    take(v.data(), v.size() * sizeof(T));
    return v;
  }
  std::string text() {
    std::string s(static_cast<std::size_t>(get<std::uint64_t>()), '\0');
    take(s.data(), s.size());
    return s;
  }

 private:
  void take(void* to, std::size_t n) {
    if (n > b_.size() - at_) throw FmuError("isolated FMU instance: a message ended early");
    if (n > 0) std::memcpy(to, b_.data() + at_, n);
    at_ += n;
  }
  std::span<const std::uint8_t> b_;
  std::size_t at_ = 0;
};

bool send_all(int fd, const std::vector<std::uint8_t>& bytes) {
  for (;;) {
    const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n >= 0) return static_cast<std::size_t>(n) == bytes.size();
    if (errno != EINTR) return false;
  }
}

/// One datagram; false at the end of the stream (the other side closed or died).
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
  if (WIFEXITED(status)) return fmt::format("exited with status {} inside the call", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* name = strsignal(sig);
    return fmt::format(
        "was killed by signal {} ({}){}", sig, name != nullptr ? name : "?",
        sig == SIGSEGV || sig == SIGBUS || sig == SIGABRT || sig == SIGFPE || sig == SIGILL ? ": the FMU crashed" : "");
  }
  return fmt::format("ended (wait status {})", status);
}

// ---- the child: serves calls on `fd` until kFree or the parent's end ------------------------------

[[noreturn]] void serve(int fd, const std::shared_ptr<Fmu>& fmu, const std::string& name) {
  const LogSink sink = [fd](const std::string& category, const std::string& status, const std::string& message) {
    Writer w;
    w.put(kLog).text(category).text(status).text(message);
    send_all(fd, w.bytes);
  };
  const auto fail = [fd](const std::string& what) {
    Writer w;
    w.put(kFailed).text(what);
    send_all(fd, w.bytes);
  };
  std::unique_ptr<Instance> instance;
  try {
    instance = fmu->instantiate(name, sink);
  } catch (const std::exception& e) {
    fail(e.what());
    _exit(0);
  }
  {
    Writer w;
    w.put(kAnswer);
    if (!send_all(fd, w.bytes)) _exit(0);
  }
  std::vector<std::uint8_t> in;
  while (receive(fd, in)) {
    Reader r(in);
    Writer out;
    out.put(kAnswer);
    const auto op = r.get<Op>();
    try {
      switch (op) {
        case Op::kEnterInitialization: {
          const auto t = r.get<double>();
          const auto has_stop = r.get<bool>();
          const auto stop = r.get<double>();
          instance->enter_initialization(t, has_stop ? std::optional<double>(stop) : std::nullopt);
          break;
        }
        case Op::kExitInitialization: instance->exit_initialization(); break;
        case Op::kDoStep: {
          const auto t = r.get<double>();
          const auto h = r.get<double>();
          instance->do_step(t, h);
          break;
        }
        case Op::kTerminate: instance->terminate(); break;
        case Op::kReset: instance->reset(); break;
        case Op::kGetReal: {
          const auto vr = r.vec<ValueReference>();
          std::vector<double> v(vr.size());
          instance->get_real(vr, v);
          out.span<double>(v);
          break;
        }
        case Op::kSetReal: {
          const auto vr = r.vec<ValueReference>();
          const auto v = r.vec<double>();
          instance->set_real(vr, v);
          break;
        }
        case Op::kGetInteger: {
          const auto vr = r.vec<ValueReference>();
          std::vector<std::int32_t> v(vr.size());
          instance->get_integer(vr, v);
          out.span<std::int32_t>(v);
          break;
        }
        case Op::kSetInteger: {
          const auto vr = r.vec<ValueReference>();
          const auto v = r.vec<std::int32_t>();
          instance->set_integer(vr, v);
          break;
        }
        case Op::kGetBoolean: {
          const auto vr = r.vec<ValueReference>();
          std::unique_ptr<bool[]> v(new bool[vr.size()]);
          instance->get_boolean(vr, std::span<bool>(v.get(), vr.size()));
          out.span<bool>(std::span<const bool>(v.get(), vr.size()));
          break;
        }
        case Op::kSetBoolean: {
          const auto vr = r.vec<ValueReference>();
          const auto n = static_cast<std::size_t>(r.get<std::uint64_t>());
          std::unique_ptr<bool[]> v(new bool[n]);
          for (std::size_t i = 0; i < n; ++i) v[i] = r.get<bool>();
          instance->set_boolean(vr, std::span<const bool>(v.get(), n));
          break;
        }
        case Op::kSetString: {
          const auto vr = r.vec<ValueReference>();
          std::vector<std::string> v(static_cast<std::size_t>(r.get<std::uint64_t>()));
          for (auto& s : v) s = r.text();
          instance->set_string(vr, v);
          break;
        }
        case Op::kFree:
          instance.reset();  // terminate (when due) and free, here where the FMU lives
          send_all(fd, out.bytes);
          _exit(0);
      }
    } catch (const std::exception& e) {
      fail(e.what());
      continue;
    }
    if (!send_all(fd, out.bytes)) break;
  }
  _exit(0);  // the parent is gone: nothing to free for
}

// ---- the parent's side ---------------------------------------------------------------------------

class IsolatedInstance final : public Instance {
 public:
  IsolatedInstance(const std::shared_ptr<Fmu>& fmu, const std::string& name, LogSink log)
      : Instance(fmu),
        name_(name),
        log_(std::move(log)),
        prefix_(fmu->description().version == FmiVersion::k2 ? "fmi2" : "fmi3") {
    int fds[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) != 0) {
      throw FmuError(fmt::format("FMU '{}': cannot make a socket pair for its process: {}",
                                 fmu->description().model_name, std::strerror(errno)));
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
      throw FmuError(
          fmt::format("FMU '{}': cannot start its process: {}", fmu->description().model_name, std::strerror(err)));
    }
    if (pid_ == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) _exit(0);  // the parent died before prctl took effect
      ::signal(SIGINT, SIG_IGN);
      ::signal(SIGTERM, SIG_DFL);
      ::signal(SIGPIPE, SIG_IGN);
      ::close(fds[0]);
      serve(fds[1], fmu, name);
    }
    ::close(fds[1]);
    fd_ = fds[0];
    call([] { return std::string("instantiate"); }, [](Writer&) {}, /*instantiate=*/true);
  }

  ~IsolatedInstance() override {
    if (pid_ > 0 && !ended_) {
      Writer w;
      w.put(Op::kFree);
      if (send_all(fd_, w.bytes)) {
        // Terminate and free get a while to answer; a child that hangs in them is killed.
        pollfd p{fd_, POLLIN, 0};
        std::vector<std::uint8_t> in;
        for (int waited = 0; waited < 2000; waited += 50) {
          if (::poll(&p, 1, 50) > 0) {
            if (!receive(fd_, in)) break;
            if (!in.empty() && in[0] == kLog) {
              forward_log(in);
              continue;
            }
            break;
          }
          const auto stop = g_stop_check.load();
          if (stop != nullptr && stop()) break;
        }
      }
    }
    if (fd_ >= 0) ::close(fd_);
    if (pid_ > 0 && !reaped_) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) != pid_) {
        ::kill(pid_, SIGKILL);
        while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
        }
      }
    }
  }

  void enter_initialization(double start_time_s, std::optional<double> stop_time_s) override {
    call(
        [&] { return fmt::format("{}EnterInitializationMode(t = {:g})", prefix_, start_time_s); },
        [&](Writer& w) {
          w.put(Op::kEnterInitialization).put(start_time_s).put(stop_time_s.has_value()).put(stop_time_s.value_or(0.0));
        });
  }
  void exit_initialization() override {
    call([&] { return prefix_ + "ExitInitializationMode"; }, [](Writer& w) { w.put(Op::kExitInitialization); });
  }
  void do_step(double t_s, double h_s) override {
    call([&] { return fmt::format("{}DoStep(t = {:g}, h = {:g})", prefix_, t_s, h_s); },
         [&](Writer& w) { w.put(Op::kDoStep).put(t_s).put(h_s); });
  }
  void terminate() override {
    call([&] { return prefix_ + "Terminate"; }, [](Writer& w) { w.put(Op::kTerminate); });
  }
  void reset() override {
    call([&] { return prefix_ + "Reset"; }, [](Writer& w) { w.put(Op::kReset); });
  }
  void get_real(std::span<const ValueReference> vr, std::span<double> values) override {
    Reader r = call([&] { return prefix_ + (prefix_ == "fmi2" ? "GetReal" : "GetFloat64"); },
                    [&](Writer& w) { w.put(Op::kGetReal).span(vr); });
    copy_into(r.vec<double>(), values);
  }
  void set_real(std::span<const ValueReference> vr, std::span<const double> values) override {
    call([&] { return prefix_ + (prefix_ == "fmi2" ? "SetReal" : "SetFloat64"); },
         [&](Writer& w) { w.put(Op::kSetReal).span(vr).span(values); });
  }
  void get_integer(std::span<const ValueReference> vr, std::span<std::int32_t> values) override {
    Reader r = call([&] { return prefix_ + (prefix_ == "fmi2" ? "GetInteger" : "GetInt32"); },
                    [&](Writer& w) { w.put(Op::kGetInteger).span(vr); });
    copy_into(r.vec<std::int32_t>(), values);
  }
  void set_integer(std::span<const ValueReference> vr, std::span<const std::int32_t> values) override {
    call([&] { return prefix_ + (prefix_ == "fmi2" ? "SetInteger" : "SetInt32"); },
         [&](Writer& w) { w.put(Op::kSetInteger).span(vr).span(values); });
  }
  void get_boolean(std::span<const ValueReference> vr, std::span<bool> values) override {
    Reader r = call([&] { return prefix_ + "GetBoolean"; }, [&](Writer& w) { w.put(Op::kGetBoolean).span(vr); });
    const auto n = static_cast<std::size_t>(r.get<std::uint64_t>());
    if (n != values.size()) throw FmuError("isolated FMU instance: a Boolean answer of the wrong length");
    for (std::size_t i = 0; i < n; ++i) values[i] = r.get<bool>();
  }
  void set_boolean(std::span<const ValueReference> vr, std::span<const bool> values) override {
    call([&] { return prefix_ + "SetBoolean"; },
         [&](Writer& w) {
           w.put(Op::kSetBoolean).span(vr).put(static_cast<std::uint64_t>(values.size()));
           for (const bool b : values) w.put(b);
         });
  }
  void set_string(std::span<const ValueReference> vr, std::span<const std::string> values) override {
    call([&] { return prefix_ + "SetString"; },
         [&](Writer& w) {
           w.put(Op::kSetString).span(vr).put(static_cast<std::uint64_t>(values.size()));
           for (const auto& s : values) w.text(s);
         });
  }

 private:
  template <class T>
  static void copy_into(const std::vector<T>& from, std::span<T> to) {
    if (from.size() != to.size()) throw FmuError("isolated FMU instance: an answer of the wrong length");
    std::copy(from.begin(), from.end(), to.begin());
  }

  std::string who() const {
    return fmt::format("FMU '{}' ({}) instance '{}'", description().model_name, fmu_->path(), name_);
  }

  void forward_log(const std::vector<std::uint8_t>& in) {
    Reader r(std::span<const std::uint8_t>(in).subspan(1));
    const std::string category = r.text(), status = r.text(), message = r.text();
    last_logged_ = fmt::format("[{}] {}", status, message);
    if (log_) {
      try {
        log_(category, status, message);
      } catch (...) {
      }
    } else {
      std::fprintf(stderr, "[FMU %s] %s %s: %s\n", name_.c_str(), status.c_str(), category.c_str(), message.c_str());
    }
  }

  /// Sends the request `fill` writes, forwards what the FMU logs meanwhile and returns the answer's
  /// payload (kept in answer_). Throws FmuError with the child's message when the call failed there,
  /// naming `call_text()` when the child ended, InstanceInterrupted when asked to stop.
  template <class Text, class Fill>
  Reader call(Text&& call_text, Fill&& fill, bool instantiate = false) {
    if (ended_) {
      throw FmuError(fmt::format("{} of {}: refused, the FMU's process has ended ({})", call_text(), who(), end_));
    }
    if (!instantiate) {
      Writer w;
      fill(w);
      if (!send_all(fd_, w.bytes)) return child_ended(call_text());
    }
    pollfd p{fd_, POLLIN, 0};
    for (;;) {
      const int ready = ::poll(&p, 1, 50);
      if (ready < 0 && errno != EINTR) return child_ended(call_text());
      if (ready <= 0) {
        const auto stop = g_stop_check.load();
        if (stop != nullptr && stop()) {
          ::kill(pid_, SIGKILL);
          int status = 0;
          while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
          }
          reaped_ = ended_ = true;
          end_ = "killed on a stop request";
          throw InstanceInterrupted(
              fmt::format("{} of {}: interrupted (Ctrl-C or SIGTERM) while the FMU was inside the call; its "
                          "process was killed",
                          call_text(), who()));
        }
        continue;
      }
      if (!receive(fd_, answer_)) return child_ended(call_text());
      if (answer_.empty()) continue;
      if (answer_[0] == kLog) {
        forward_log(answer_);
        continue;
      }
      if (answer_[0] == kFailed) {
        Reader r(std::span<const std::uint8_t>(answer_).subspan(1));
        throw FmuError(r.text());
      }
      return Reader(std::span<const std::uint8_t>(answer_).subspan(1));
    }
  }

  [[noreturn]] Reader child_ended(const std::string& call_text) {
    int status = 0;
    pid_t r;
    while ((r = ::waitpid(pid_, &status, 0)) < 0 && errno == EINTR) {
    }
    reaped_ = ended_ = true;
    end_ = r == pid_ ? describe_end(status) : "ended";
    throw FmuError(
        fmt::format("{} of {}: the FMU's process {}{}", call_text, who(), end_,
                    last_logged_.empty() ? "; the FMU logged nothing" : "; it logged last: " + last_logged_));
  }

  std::string name_;
  LogSink log_;
  std::string prefix_;
  pid_t pid_ = -1;
  int fd_ = -1;
  bool ended_ = false, reaped_ = false;
  std::string end_;
  std::string last_logged_;
  std::vector<std::uint8_t> answer_;
};

}  // namespace

std::unique_ptr<Instance> instantiate_isolated(const std::shared_ptr<Fmu>& fmu, const std::string& instance_name,
                                               LogSink log) {
  return std::make_unique<IsolatedInstance>(fmu, instance_name, std::move(log));
}

void set_stop_check(bool (*stop_requested)()) { g_stop_check.store(stop_requested); }

}  // namespace quadcosim::fmi
