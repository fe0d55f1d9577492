// A fixed set of worker threads for data-parallel loops. ParallelFor splits
// [0, n) into contiguous chunks, runs them on the workers and the calling
// thread, and returns when all are done.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace depthbench {

class ThreadPool {
 public:
  // threads == 0: one per hardware thread (ThreadCount).
  explicit ThreadPool(unsigned threads = 0);
  // What a pool asked for `threads` runs: threads, or where 0, one per
  // hardware thread.
  static unsigned ThreadCount(unsigned threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return static_cast<unsigned>(workers_.size()) + 1; }

  // Calls fn(begin, end, worker) over chunks of [0, n); `worker` is in
  // [0, size()) and no two concurrent calls share it. `grain` is the
  // smallest chunk worth a thread.
  void ParallelFor(std::size_t n, const std::function<void(std::size_t, std::size_t, unsigned)>& fn,
                   std::size_t grain = 1);
  // memcpy in chunks on every thread: where `to` is memory a device reads
  // across the bus, one thread's writes are slower than the bus.
  void Copy(void* to, const void* from, std::size_t bytes);

 private:
  void WorkerLoop(unsigned worker);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(std::size_t, std::size_t, unsigned)>* job_ = nullptr;
  std::size_t job_size_ = 0;
  std::size_t next_chunk_ = 0;
  std::size_t chunk_ = 1;
  std::size_t chunks_left_ = 0;
  std::uint64_t generation_ = 0;
  bool stopping_ = false;
};

}  // namespace depthbench
