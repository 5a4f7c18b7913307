// Foreign code in a child process: what FMI tools do for FMUs they do not trust, and what the CLI
// does for Python controllers. The parent forks once per instance, after the code is loaded; the child
// serves requests on its end of a SOCK_SEQPACKET socket pair (one datagram per request, per answer
// and per log line) and the parent waits for each answer. Code that crashes, aborts or calls exit()
// ends only the child: the parent sees the end of the stream, reaps the child and says how it ended
// ("was killed by signal 11 (Segmentation fault)", "exited with status 0"). A wait polls the stop
// check (set_stop_check: Ctrl-C, SIGTERM) every 50 ms and can have a deadline, so a call that never
// returns costs a kill, not the run.
//
// The child dies with its parent (PR_SET_PDEATHSIG, SIGKILL) and ignores SIGINT: a Ctrl-C is the
// parent's to handle. "Parent" is the thread that forked: a host must keep the thread that first steps
// an isolated controller alive for the whole run (sim::Swarm keeps its threads through the run).
// Values travel as their bytes (both ends are the same program): results are bit for bit those of
// the same calls in-process.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::isolation {

/// A wait on a child was ended by the stop check (Ctrl-C, SIGTERM); the child was killed.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A message's bytes: values appended as they are in memory.
class Writer {
 public:
  template <class T>
  Writer& put(const T& v) {
    return append(&v, sizeof(T));
  }
  template <class T>
  Writer& span(std::span<const T> v) {
    put(static_cast<std::uint64_t>(v.size()));
    return append(v.data(), v.size_bytes());
  }
  Writer& text(std::string_view s) {
    put(static_cast<std::uint64_t>(s.size()));
    return append(s.data(), s.size());
  }
  std::vector<std::uint8_t> bytes;

 private:
  /// n bytes from `from` at the end (resize and copy: GCC 12 warns, -Wstringop-overflow, on the
  /// inlined vector::insert of a few bytes).
  Writer& append(const void* from, std::size_t n) {
    const std::size_t at = bytes.size();
    bytes.resize(at + n);
    if (n > 0) std::memcpy(bytes.data() + at, from, n);
    return *this;
  }
};

/// Reads what a Writer wrote, in the same order. A message shorter than what is read from it throws
/// std::runtime_error.
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
    std::vector<T> v(checked_count(sizeof(T)));
    take(v.data(), v.size() * sizeof(T));
    return v;
  }
  std::string text() {
    std::string s(checked_count(1), '\0');
    take(s.data(), s.size());
    return s;
  }

 private:
  std::size_t checked_count(std::size_t element) {
    const auto n = get<std::uint64_t>();
    if (element != 0 && n > (b_.size() - at_) / element)
      throw std::runtime_error("isolated call: a message ended early");
    return static_cast<std::size_t>(n);
  }
  void take(void* to, std::size_t n) {
    if (n > b_.size() - at_) throw std::runtime_error("isolated call: a message ended early");
    if (n > 0) std::memcpy(to, b_.data() + at_, n);
    at_ += n;
  }
  std::span<const std::uint8_t> b_;
  std::size_t at_ = 0;
};

/// Sends one datagram; false when the other side is gone.
bool send_all(int fd, const std::vector<std::uint8_t>& bytes);
/// Receives one datagram into `into`; false at the end of the stream (the other side closed or died).
bool receive(int fd, std::vector<std::uint8_t>& into);

/// How a child ended, from its wait status: "exited with status N", "was killed by signal 11
/// (Segmentation fault): it crashed".
std::string describe_end(int wait_status);

/// What every wait on a child asks, every 50 ms, whether to give up (e.g. a SIGINT flag). One per
/// process (signals are per process); null (the default) waits until the answer or the child's end.
void set_stop_check(bool (*stop_requested)());
/// What the stop check says now (false without one): for other waits on foreign processes (a SITL
/// firmware) to give up on Ctrl-C as these do.
bool stop_requested();

class Child {
 public:
  /// Forks. The child closes the parent's end, sets PR_SET_PDEATHSIG, ignores SIGINT and SIGPIPE and
  /// calls serve(fd) with its end of the socket pair; serve must not return (it ends with _exit).
  /// Throws std::runtime_error, prefixed with `who`, when the socket pair or the fork fails.
  Child(const std::string& who, const std::function<void(int fd)>& serve);
  /// Kills the child (SIGKILL) when it still runs, and reaps it.
  ~Child();
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  int fd() const { return fd_; }
  bool send(const std::vector<std::uint8_t>& bytes) const { return send_all(fd_, bytes); }

  enum class Wait { kMessage, kEnded, kStopped, kTimedOut };
  /// The next datagram into `into` (kMessage); kEnded when the child closed its end or died (then
  /// reap() says how); kStopped when the stop check asked to stop; kTimedOut at `deadline_ns` on
  /// the steady clock (0: none). kStopped and kTimedOut leave the child running (kill() ends it).
  Wait next(std::vector<std::uint8_t>& into, std::int64_t deadline_ns = 0);

  /// Waits for the child's end (after kEnded); returns describe_end of it.
  std::string reap();
  /// Kills and reaps the child; returns `why`, remembered as how it ended.
  std::string kill(const std::string& why);
  /// Asks the child to end by closing the socket, gives it `grace_ms` to exit, then kills it.
  void finish(int grace_ms);

  bool ended() const { return reaped_; }
  const std::string& end() const { return end_; }

  /// Now on the steady clock [ns], for deadlines.
  static std::int64_t now_ns();

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
  bool reaped_ = false;
  std::string end_;
};

}  // namespace quadcosim::isolation
