// Timestamps a Vulkan queue writes between commands, and the nanoseconds
// between two of them. GpuPassTimer (speed/) times passes with them; the
// device judge times each pass of every batch it queues.
#pragma once

#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/status.h"

namespace depthbench {

// The nanoseconds between two timestamps of a queue whose timestamps have
// `valid_bits` significant bits (1 to 64) and advance once every
// `period_ns` nanoseconds (VkPhysicalDeviceLimits::timestampPeriod). Only
// the low valid_bits of a timestamp count, so the difference is taken
// modulo 2^valid_bits: a counter that wrapped once between the two still
// gives the right interval.
double TimestampIntervalNs(std::uint64_t begin, std::uint64_t end, std::uint32_t valid_bits, double period_ns);
// The same for a pair of raw query results, checking what the device
// reported: InvalidArgument when valid_bits is 0 (the queue cannot time) or
// above 64, or when the period is not a positive finite number.
Expected<double> CheckedTimestampIntervalNs(std::uint64_t begin, std::uint64_t end, std::uint32_t valid_bits,
                                            double period_ns);

// A pool of timestamp queries on one device's compute queue.
class TimestampQueries {
 public:
  TimestampQueries() = default;
  // Ok where the device's compute queue writes timestamps and the device
  // reports their period; otherwise Unavailable, saying which it lacks.
  static Status Supported(const VulkanContext& context);
  // `count` queries; Supported's error where it is not.
  static Expected<TimestampQueries> Create(const VulkanContext& context, std::uint32_t count);

  std::uint32_t count() const { return count_; }
  // Records the reset of queries [first, first + count), which every
  // write must follow.
  void RecordReset(VkCommandBuffer commands, std::uint32_t first, std::uint32_t count) const;
  // Records a timestamp into `query`, written once every command recorded
  // or submitted to the queue before it has finished (bottom of pipe).
  void RecordWrite(VkCommandBuffer commands, std::uint32_t query) const;
  // The timestamps of queries [first, first + count), waiting for them.
  Expected<std::vector<std::uint64_t>> Read(std::uint32_t first, std::uint32_t count) const;
  // Nanoseconds from timestamp `begin` to `end` of this queue.
  double IntervalNs(std::uint64_t begin, std::uint64_t end) const {
    return TimestampIntervalNs(begin, end, valid_bits_, period_ns_);
  }

 private:
  DeviceObject<VkQueryPool> pool_;
  VkDevice device_ = VK_NULL_HANDLE;
  std::uint32_t count_ = 0;
  std::uint32_t valid_bits_ = 0;
  double period_ns_ = 0.0;
};

}  // namespace depthbench
