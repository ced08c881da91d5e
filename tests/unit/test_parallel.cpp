// SPDX-License-Identifier: GPL-3.0-or-later
// common/parallel.hpp: the loops over the DEs give each thread the same DEs (docs/performance.md#one-owner).
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "common/parallel.hpp"
#include "support/omp_threads.hpp"

namespace arlequin {
namespace {

TEST(ThreadShare, EveryLoopOverTheDesGivesAThreadTheSameWholeChunks) {
#ifndef _OPENMP
  GTEST_SKIP() << "built without OpenMP: one thread runs every loop";
#else
  const int threads = 3;
  const test::OmpThreads team(threads);
  // 1000 items: OpenMP's static schedule would give 334, 333, 333; the shares are whole chunks.
  for (const long n : {1000L, 10127L, 20000L}) {
    std::vector<int> by_item(static_cast<std::size_t>(n), -1), by_chunk(static_cast<std::size_t>(n), -1);
    for_each_index(n, true, [&](long i) { by_item[static_cast<std::size_t>(i)] = thread_index(); });
    std::vector<int> partial;
    scan_fixed_chunks(n, 0, partial, [&](long begin, long end) {
      for (long i = begin; i < end; ++i) by_chunk[static_cast<std::size_t>(i)] = thread_index();
      return 0;
    });
    EXPECT_EQ(by_item, by_chunk) << n << " items";
    // Thread t's items are one run after thread t - 1's, starting on a chunk boundary, and the
    // shares differ by at most one chunk.
    std::vector<long> count(threads, 0);
    for (long i = 0; i < n; ++i) {
      const int t = by_item[static_cast<std::size_t>(i)];
      ASSERT_GE(t, 0) << "item " << i << " of " << n << " not visited";
      ++count[static_cast<std::size_t>(t)];
      if (i > 0 && t != by_item[static_cast<std::size_t>(i - 1)]) {
        EXPECT_EQ(t, by_item[static_cast<std::size_t>(i - 1)] + 1) << n << " items, item " << i;
        EXPECT_EQ(i % share_chunk, 0) << n << " items: a share starts inside a chunk at " << i;
      }
    }
    const long chunks = (n + share_chunk - 1) / share_chunk;
    EXPECT_LE(*std::max_element(count.begin(), count.end()), (chunks + threads - 1) / threads * share_chunk) << n;
    EXPECT_GE(*std::min_element(count.begin(), count.end()), chunks / threads * share_chunk - share_chunk) << n;
  }
#endif
}

TEST(ThreadShare, OutsideAParallelRegionOneThreadTakesEverything) {
  const IndexRange all = thread_share(1000);
  EXPECT_EQ(all.begin, 0);
  EXPECT_EQ(all.end, 1000);
}

}  // namespace
}  // namespace arlequin
