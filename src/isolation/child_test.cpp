// isolation/child.hpp with real child processes: answers, crashes, exits, hangs, stop requests.
#include "isolation/child.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace quadcosim::isolation {
namespace {

/// A child that doubles each number it is sent, and on 0 does `fault` instead of answering.
void serve_doubling(int fd, char fault) {
  std::vector<std::uint8_t> in;
  while (receive(fd, in)) {
    Reader r(in);
    const auto x = r.get<double>();
    if (x == 0.0) {
      switch (fault) {
        case 's':
          ::signal(SIGSEGV, SIG_DFL);  // no sanitizer's handler: the default death by the signal
          ::raise(SIGSEGV);
          break;
        case 'e': _exit(3); break;
        case 'h': ::pause(); break;
        default: break;
      }
    }
    Writer w;
    w.put(2.0 * x).text("ok");
    send_all(fd, w.bytes);
  }
  _exit(0);
}

double ask(Child& c, double x, Child::Wait& got, std::int64_t deadline_ns = 0) {
  Writer w;
  w.put(x);
  EXPECT_TRUE(c.send(w.bytes));
  std::vector<std::uint8_t> answer;
  got = c.next(answer, deadline_ns);
  if (got != Child::Wait::kMessage) return -1.0;
  Reader r(answer);
  const auto y = r.get<double>();
  EXPECT_EQ(r.text(), "ok");
  return y;
}

TEST(ChildTest, AnswersComeFromAnotherProcessBitForBit) {
  Child c("doubler", [](int fd) { serve_doubling(fd, ' '); });
  Child::Wait got{};
  EXPECT_EQ(ask(c, 0.1, got), 0.2);  // 2 x 0.1 in the child: the same double as here
  EXPECT_EQ(got, Child::Wait::kMessage);
  EXPECT_EQ(ask(c, -3.5, got), -7.0);
  EXPECT_FALSE(c.ended());
}

TEST(ChildTest, ACrashEndsOnlyTheChildAndSaysHow) {
  Child c("crasher", [](int fd) { serve_doubling(fd, 's'); });
  Child::Wait got{};
  EXPECT_EQ(ask(c, 1.0, got), 2.0);
  ask(c, 0.0, got);
  EXPECT_EQ(got, Child::Wait::kEnded);
  EXPECT_EQ(c.reap(), "was killed by signal 11 (Segmentation fault): it crashed");
  EXPECT_TRUE(c.ended());
  std::vector<std::uint8_t> more;
  EXPECT_EQ(c.next(more), Child::Wait::kEnded);  // and stays ended
}

TEST(ChildTest, AnExitInsideACallIsAnEndNotAnAnswer) {
  Child c("exiter", [](int fd) { serve_doubling(fd, 'e'); });
  Child::Wait got{};
  ask(c, 0.0, got);
  EXPECT_EQ(got, Child::Wait::kEnded);
  EXPECT_EQ(c.reap(), "exited with status 3");
}

TEST(ChildTest, AHungCallTimesOutAtItsDeadlineAndIsKilled) {
  Child c("hanger", [](int fd) { serve_doubling(fd, 'h'); });
  Child::Wait got{};
  const std::int64_t start = Child::now_ns();
  ask(c, 0.0, got, start + 200'000'000);
  const std::int64_t waited = Child::now_ns() - start;
  EXPECT_EQ(got, Child::Wait::kTimedOut);
  EXPECT_GE(waited, 200'000'000);
  EXPECT_EQ(c.kill("killed: too slow"), "killed: too slow");
  EXPECT_TRUE(c.ended());
}

std::atomic<bool> g_stop{false};

TEST(ChildTest, AStopRequestEndsTheWait) {
  Child c("hanger", [](int fd) { serve_doubling(fd, 'h'); });
  set_stop_check([] { return g_stop.load(); });
  Child::Wait got{};
  EXPECT_EQ(ask(c, 4.0, got), 8.0);  // not asked to stop: answered
  g_stop = true;
  ask(c, 0.0, got);
  EXPECT_EQ(got, Child::Wait::kStopped);
  set_stop_check(nullptr);
  g_stop = false;
}

TEST(ChildTest, ARunningChildIsEndedWithItsOwner) {
  pid_t pid = 0;
  {
    Child c("sleeper", [](int fd) {
      Writer w;
      w.put(::getpid());
      send_all(fd, w.bytes);
      ::pause();
    });
    std::vector<std::uint8_t> answer;
    ASSERT_EQ(c.next(answer, Child::now_ns() + 5'000'000'000), Child::Wait::kMessage);
    pid = Reader(answer).get<pid_t>();
    EXPECT_NE(pid, ::getpid());
    EXPECT_EQ(::kill(pid, 0), 0);  // running
  }
  EXPECT_EQ(::kill(pid, 0), -1);  // killed and reaped: no such process
}

TEST(ReaderTest, AShortMessageIsAnErrorNotAnOverread) {
  Writer w;
  w.put(std::uint64_t{1'000'000});  // claims a million doubles, holds none
  Reader r(w.bytes);
  EXPECT_THROW(r.vec<double>(), std::runtime_error);
  Reader s(w.bytes);
  EXPECT_THROW(s.text(), std::runtime_error);
}

}  // namespace
}  // namespace quadcosim::isolation
