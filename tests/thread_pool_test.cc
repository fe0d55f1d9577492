// The thread pool's loops: every index once, and copies in chunks that
// put every byte where memcpy would.
#include <atomic>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "bench/base/thread_pool.h"

namespace depthbench {
namespace {

TEST(ThreadPoolTest, ParallelForVisitsEveryIndexOnce) {
  ThreadPool pool(3);
  std::vector<std::atomic<int>> visits(1001);
  pool.ParallelFor(visits.size(), [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t i = begin; i < end; ++i) ++visits[i];
  });
  for (std::size_t i = 0; i < visits.size(); ++i) ASSERT_EQ(visits[i], 1) << i;
}

// A length that is no multiple of the chunk (256 KiB), so the last chunk
// is short, and one below a chunk.
TEST(ThreadPoolTest, CopyPutsEveryByteWhereMemcpyWould) {
  ThreadPool pool(3);
  for (const std::size_t bytes : {std::size_t{(3u << 20) + 13}, std::size_t{1000}, std::size_t{0}}) {
    std::vector<std::uint8_t> from(bytes), to(bytes + 1, 0xab);
    for (std::size_t i = 0; i < bytes; ++i) from[i] = static_cast<std::uint8_t>(i * 2654435761u >> 24);
    pool.Copy(to.data(), from.data(), bytes);
    EXPECT_TRUE(std::equal(from.begin(), from.end(), to.begin())) << bytes;
    EXPECT_EQ(to[bytes], 0xab) << "wrote past the end";
  }
}

}  // namespace
}  // namespace depthbench
