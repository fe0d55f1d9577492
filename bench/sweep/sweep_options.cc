#include "bench/sweep/sweep_options.h"

#include <algorithm>

#include <fmt/format.h>

#include "bench/base/text_table.h"

namespace depthbench {

double SweepProgress::fraction() const {
  return samples_total == 0 ? 1.0 : static_cast<double>(samples_done) / static_cast<double>(samples_total);
}

std::string SweepProgress::Describe() const {
  return fmt::format("{}/{} samples, {} reconstructions/s", ShortCount(static_cast<double>(samples_done)),
                     ShortCount(static_cast<double>(samples_total)),
                     ShortCount(static_cast<double>(reconstructions_done) / std::max(seconds, 1e-9)));
}

Status SweepOptions::Validate() const {
  if (samples < 1) return ViolatedConstraint(fmt::format("SweepOptions::samples >= 1 (it is {})", samples));
  if (shard.count < 1 || shard.index < 1 || shard.index > shard.count) {
    return ViolatedConstraint(
        fmt::format("1 <= SweepOptions::shard.index <= shard.count (it is {})", shard.ToString()));
  }
  if (batch_size != 0 && (batch_size < kMinBatch || batch_size > kMaxBatch)) {
    return ViolatedConstraint(
        fmt::format("SweepOptions::batch_size == 0 or in [{}, {}] (it is {})", kMinBatch, kMaxBatch, batch_size));
  }
  if (flush_every < 1 || flush_every > kMaxFlushEvery) {
    return ViolatedConstraint(fmt::format("SweepOptions::flush_every in [1, 2^31] (it is {})", flush_every));
  }
  DB_RETURN_IF_ERROR(domain.Validate());
  if (!ProcessorRuns(isa)) return Unavailable("this processor does not run the requested instruction set");
  return Status::Ok();
}

}  // namespace depthbench
