#include "bench/backends/vulkan/timestamps.h"

#include <cmath>

#include <fmt/format.h>

namespace depthbench {

double TimestampIntervalNs(std::uint64_t begin, std::uint64_t end, std::uint32_t valid_bits, double period_ns) {
  const std::uint64_t mask = valid_bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << valid_bits) - 1;
  // Unsigned subtraction wraps modulo 2^64; the mask reduces it modulo
  // 2^valid_bits, which is how a narrower counter wraps.
  const std::uint64_t ticks = ((end & mask) - (begin & mask)) & mask;
  return static_cast<double>(ticks) * period_ns;
}

Expected<double> CheckedTimestampIntervalNs(std::uint64_t begin, std::uint64_t end, std::uint32_t valid_bits,
                                            double period_ns) {
  if (valid_bits == 0) {
    return InvalidArgument("the queue's timestampValidBits is 0: it cannot write timestamps");
  }
  if (valid_bits > 64) {
    return InvalidArgument(fmt::format("timestampValidBits {} is above 64", valid_bits));
  }
  if (!(period_ns > 0.0) || !std::isfinite(period_ns)) {
    return InvalidArgument(fmt::format("timestampPeriod {} is not a positive number of nanoseconds", period_ns));
  }
  return TimestampIntervalNs(begin, end, valid_bits, period_ns);
}

Status TimestampQueries::Supported(const VulkanContext& context) {
  const VulkanDeviceProperties& properties = context.properties();
  if (properties.queue_timestamp_valid_bits == 0) {
    return Unavailable(
        fmt::format("Vulkan device '{}': its compute queue cannot write timestamps "
                    "(timestampValidBits 0), so passes cannot be timed on it",
                    properties.name));
  }
  if (!(properties.limits.timestampPeriod > 0.0f)) {
    return Unavailable(fmt::format("Vulkan device '{}' reports timestampPeriod {}", properties.name,
                                   properties.limits.timestampPeriod));
  }
  return Status::Ok();
}

Expected<TimestampQueries> TimestampQueries::Create(const VulkanContext& context, std::uint32_t count) {
  DB_RETURN_IF_ERROR(Supported(context));
  const VulkanDeviceProperties& properties = context.properties();
  VkQueryPoolCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = count;
  VkQueryPool pool = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateQueryPool(context.device(), &info, nullptr, &pool), "vkCreateQueryPool"));
  TimestampQueries queries;
  queries.pool_ = DeviceObject<VkQueryPool>(context.device(), pool, vkDestroyQueryPool);
  queries.device_ = context.device();
  queries.count_ = count;
  queries.valid_bits_ = properties.queue_timestamp_valid_bits;
  queries.period_ns_ = properties.limits.timestampPeriod;
  return queries;
}

void TimestampQueries::RecordReset(VkCommandBuffer commands, std::uint32_t first, std::uint32_t count) const {
  vkCmdResetQueryPool(commands, pool_.get(), first, count);
}

void TimestampQueries::RecordWrite(VkCommandBuffer commands, std::uint32_t query) const {
  vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), query);
}

Expected<std::vector<std::uint64_t>> TimestampQueries::Read(std::uint32_t first, std::uint32_t count) const {
  std::vector<std::uint64_t> stamps(count);
  DB_RETURN_IF_ERROR(CheckVk(
      vkGetQueryPoolResults(device_, pool_.get(), first, count, stamps.size() * sizeof(std::uint64_t), stamps.data(),
                            sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
      "vkGetQueryPoolResults"));
  return stamps;
}

}  // namespace depthbench
