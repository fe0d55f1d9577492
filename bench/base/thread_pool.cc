#include "bench/base/thread_pool.h"

#include <algorithm>
#include <cstring>

namespace depthbench {

unsigned ThreadPool::ThreadCount(unsigned threads) {
  return threads != 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
}

ThreadPool::ThreadPool(unsigned threads) {
  threads = ThreadCount(threads);
  for (unsigned i = 1; i < threads; ++i) workers_.emplace_back([this, i] { WorkerLoop(i); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

void ThreadPool::Copy(void* to, const void* from, std::size_t bytes) {
  constexpr std::size_t kChunk = std::size_t{256} << 10;
  ParallelFor((bytes + kChunk - 1) / kChunk, [&](std::size_t begin, std::size_t end, unsigned) {
    const std::size_t lo = begin * kChunk, hi = std::min(bytes, end * kChunk);
    std::memcpy(static_cast<std::byte*>(to) + lo, static_cast<const std::byte*>(from) + lo, hi - lo);
  });
}

void ThreadPool::ParallelFor(std::size_t n, const std::function<void(std::size_t, std::size_t, unsigned)>& fn,
                             std::size_t grain) {
  if (n == 0) return;
  const std::size_t threads = size();
  // Many chunks per thread balance uneven work (a lock per chunk costs
  // little against a grain of work); callers with few, uneven items list
  // the largest first.
  constexpr std::size_t kChunksPerThread = 16;
  const std::size_t most_chunks = threads * kChunksPerThread;
  std::size_t chunk = std::max<std::size_t>(grain, (n + most_chunks - 1) / most_chunks);
  std::size_t chunks = (n + chunk - 1) / chunk;
  if (threads == 1 || chunks == 1) {
    fn(0, n, 0);
    return;
  }
  {
    std::lock_guard lock(mutex_);
    job_ = &fn;
    job_size_ = n;
    chunk_ = chunk;
    next_chunk_ = 0;
    chunks_left_ = chunks;
    ++generation_;
  }
  wake_.notify_all();
  // The caller works too, as worker 0.
  for (;;) {
    std::size_t c;
    {
      std::lock_guard lock(mutex_);
      if (next_chunk_ * chunk_ >= job_size_) break;
      c = next_chunk_++;
    }
    fn(c * chunk, std::min(n, (c + 1) * chunk), 0);
    std::lock_guard lock(mutex_);
    if (--chunks_left_ == 0) done_.notify_all();
  }
  std::unique_lock lock(mutex_);
  done_.wait(lock, [&] { return chunks_left_ == 0; });
  job_ = nullptr;
}

void ThreadPool::WorkerLoop(unsigned worker) {
  std::uint64_t seen = 0;
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || (job_ != nullptr && generation_ != seen); });
    if (stopping_) return;
    seen = generation_;
    while (job_ != nullptr && next_chunk_ * chunk_ < job_size_) {
      std::size_t c = next_chunk_++;
      const auto* fn = job_;
      std::size_t begin = c * chunk_, end = std::min(job_size_, (c + 1) * chunk_);
      lock.unlock();
      (*fn)(begin, end, worker);
      lock.lock();
      if (--chunks_left_ == 0) done_.notify_all();
    }
  }
}

}  // namespace depthbench
