// Work items on a few threads: each once, on the threads asked for, and the first failure stops
// the hand-out and reaches the caller.

#include "common/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace airtwin {
namespace {

TEST(ParallelFor, EveryItemOnceOnTheThreadsAskedFor) {
  std::vector<std::atomic<int>> calls(1000);
  std::mutex mutex;
  std::set<std::thread::id> threads;
  parallel_for(calls.size(), 3, [&](size_t k) {
    ++calls[k];
    const std::lock_guard lock(mutex);
    threads.insert(std::this_thread::get_id());
  });
  for (const auto& c : calls) EXPECT_EQ(c, 1);
  EXPECT_LE(threads.size(), 3u);
  // One thread: the caller's; no items: no call.
  const std::thread::id caller = std::this_thread::get_id();
  parallel_for(4, 1, [&](size_t) { EXPECT_EQ(std::this_thread::get_id(), caller); });
  bool called = false;
  parallel_for(0, 4, [&](size_t) { called = true; });
  EXPECT_FALSE(called);
}

TEST(ParallelFor, TheFirstFailureStopsTheRestAndIsRethrown) {
  // Items after 10 wait until item 10 has thrown and then take a millisecond each, so the test
  // does not depend on how the threads are scheduled: a thread preempted while it holds item 10
  // cannot watch the other thread run all 10000 items first. After the throw, a correct pool
  // runs at most one more item per thread before it stops; a pool that ignored the failure
  // would run every item (ten seconds).
  std::atomic<int> started{0};
  std::atomic<bool> thrown{false};
  try {
    parallel_for(10000, 2, [&](size_t k) {
      ++started;
      if (k == 10) {
        thrown = true;
        thrown.notify_all();
        throw std::runtime_error("item 10");
      }
      if (k > 10) {
        thrown.wait(false);  // item 10 was handed out before this one: it wakes us
        std::this_thread::sleep_for(std::chrono::milliseconds(1));  // an item's work
      }
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "item 10");
  }
  EXPECT_LT(started, 1000);  // about 12 in practice
}

}  // namespace
}  // namespace airtwin
