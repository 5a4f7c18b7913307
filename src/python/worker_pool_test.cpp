// quadcosim.Batch's worker pool (worker_pool.hpp): every chunk once per job, whatever the thread count
// and however jobs follow each other (back to back while the workers poll, or after they slept);
// a thread held up has its chunks taken by the others; a chunk's exception reaches the caller.
#include "python/worker_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace quadcosim::python {
namespace {

TEST(WorkerPool, EveryChunkRunsOncePerJob) {
  for (int threads : {1, 2, 3}) {
    WorkerPool pool(threads);
    for (std::uint32_t chunks = 0; chunks < 70; ++chunks) {
      std::vector<std::atomic<int>> runs(chunks);
      pool.run(chunks, [&](std::uint32_t c) { runs[c].fetch_add(1); });
      for (std::uint32_t c = 0; c < chunks; ++c) ASSERT_EQ(runs[c].load(), 1) << threads << " threads, chunk " << c;
    }
  }
}

TEST(WorkerPool, JobsAfterTheWorkersSleptStillRunEveryChunk) {
  WorkerPool pool(2);
  for (int job = 0; job < 3; ++job) {
    // Longer than the workers poll: they are asleep when the next job comes.
    std::this_thread::sleep_for(WorkerPool::kSpin * 3);
    std::atomic<int> sum{0};
    pool.run(10, [&](std::uint32_t c) { sum += static_cast<int>(c) + 1; });
    EXPECT_EQ(sum.load(), 55);
  }
}

TEST(WorkerPool, AHeldUpThreadsChunksAreTakenByTheOthers) {
  // The first chunk of the second thread's range waits until every other chunk has run: the pool
  // finishes only if the other thread takes the rest of that range (a pool without it would wait
  // here for ever; the wait gives up after 10 s and the test fails).
  WorkerPool pool(2);
  constexpr std::uint32_t kChunks = 8;  // ranges [0, 4) and [4, 8)
  std::atomic<std::uint32_t> done{0};
  std::atomic<bool> gave_up{false};
  pool.run(kChunks, [&](std::uint32_t c) {
    if (c == kChunks / 2) {
      const auto limit = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (done.load() < kChunks - 1) {
        if (std::chrono::steady_clock::now() > limit) {
          gave_up = true;
          break;
        }
        std::this_thread::yield();
      }
    }
    ++done;
  });
  EXPECT_FALSE(gave_up.load());
  EXPECT_EQ(done.load(), kChunks);
}

TEST(WorkerPool, AChunksExceptionReachesTheCallerAfterTheOthersRan) {
  WorkerPool pool(2);
  std::atomic<int> ran{0};
  EXPECT_THROW(pool.run(20,
                        [&](std::uint32_t c) {
                          ++ran;
                          if (c == 13) throw std::runtime_error("chunk 13");
                        }),
               std::runtime_error);
  EXPECT_EQ(ran.load(), 20);
  ran = 0;
  pool.run(20, [&](std::uint32_t) { ++ran; });  // the pool goes on
  EXPECT_EQ(ran.load(), 20);
}

}  // namespace
}  // namespace quadcosim::python
