#include "bench/device_judge/device_judge.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "bench/backends/vulkan/compute_pass.h"
#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/base/resources.h"

namespace depthbench {
namespace judge_layout {
using uint = std::uint32_t;
#include "shared/judge.h"
}  // namespace judge_layout

namespace {

namespace L = judge_layout;

// The shader's layout is the accumulator's.
static_assert(L::DB_JUDGE_BINS == kDenseBins);
static_assert(L::DB_JUDGE_SLOTS == CellAccumulator::kSlotCount);
static_assert(L::DB_JUDGE_DISTANCE_SLOTS == kDistanceBands && L::DB_JUDGE_JOINT_SLOTS == kJointBands);
static_assert(L::DB_JUDGE_SLOT_UINTS == L::DB_JUDGE_METRICS * L::DB_JUDGE_BINS + L::DB_JUDGE_COUNTS);
static_assert(L::DB_JUDGE_STATUS_JUDGED == static_cast<unsigned>(ReferenceStatus::kJudged) &&
              L::DB_JUDGE_STATUS_DEGENERATE == static_cast<unsigned>(ReferenceStatus::kDegenerate) &&
              L::DB_JUDGE_STATUS_OUTSIDE == static_cast<unsigned>(ReferenceStatus::kOutside));
static_assert(static_cast<int>(Coverage::kNatural) == 0 && CoverageBand(Coverage::kStoredZero) == 0);
static_assert(sizeof(L::JudgePass) == 48);

// The metrics the device records, in its order, as the host numbers them:
// a cell's, and a depth slot's (its third is unused).
constexpr std::array<Metric, L::DB_JUDGE_METRICS> kCellMetrics = {Metric::kTotal, Metric::kArith, Metric::kAbsolute};
constexpr std::array<Metric, 2> kEncodingMetrics = {Metric::kStorage, Metric::kProduction};
constexpr std::uint32_t kWorkgroupSize = 64;  // judge.comp's local_size_x

// judge.comp's storage buffers, by binding number.
enum Binding : std::uint32_t {
  kCellSlots,
  kPositions,  // the backend's
  kFrames,
  kRays,
  kCoverage,
  kReference,
  kReferenceInfo,
  kCounts,
  kFirstNonFinite,
  kMaxima,
  kUnwritten,
  kBindingCount,
};
// The counters live in device memory alone (atomics across the bus would
// cost the device its speed); transfers copy them into host-readable
// buffers: each batch's maxima and the unwritten counts after the batch,
// the histograms and counts at a flush.
bool Counter(Binding b) { return b >= kCounts; }

}  // namespace

struct DeviceJudge::State {
  Backend* backend = nullptr;
  std::shared_ptr<VulkanContext> context;
  std::unique_ptr<ComputePass> pass;
  DeviceObject<VkPipeline> pipeline;
  std::array<VulkanBuffer, kBindingCount> buffers;  // (kPositions unused: the backend owns it)
  VulkanBuffer batch_readback;  // the maxima, then the unwritten counts
  VulkanBuffer flush_readback;  // the counts, then the first non-finite indices
  std::vector<std::uint32_t> every_cell;
  std::vector<Cell> run_cells;
  std::size_t depth_slots = 0;
  bool record_distances = true;

  std::size_t cell_count() const { return every_cell.size(); }
  // The cells' accumulators, then the depth slots'.
  std::size_t accumulators() const { return cell_count() + depth_slots; }
  std::size_t counted_slots() const { return accumulators() * L::DB_JUDGE_SLOTS; }
  std::size_t maxima() const { return counted_slots() * L::DB_JUDGE_METRICS; }

  VkDeviceSize counts_bytes() const { return counted_slots() * L::DB_JUDGE_SLOT_UINTS * sizeof(std::uint32_t); }
  VkDeviceSize first_bytes() const { return counted_slots() * sizeof(std::uint64_t); }
  VkDeviceSize maxima_bytes() const { return 2 * maxima() * sizeof(std::uint64_t); }
  VkDeviceSize unwritten_bytes() const { return cell_count() * sizeof(std::uint32_t); }

  Status Grow(Binding binding, VkDeviceSize bytes) {
    return context->GrowHostBuffer(
        buffers[binding], std::max<VkDeviceSize>(bytes, 16),
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
        Counter(binding) ? HostAccess::kNone : HostAccess::kUpload);
  }
  // Copies `bytes` of each source to `readback`, one after the other, and
  // makes them visible to the host.
  void RecordReadback(VkCommandBuffer commands, std::initializer_list<std::pair<Binding, VkDeviceSize>> sources,
                      const VulkanBuffer& readback) const {
    VkDeviceSize offset = 0;
    for (const auto& [binding, bytes] : sources) {
      const VkBufferCopy region{0, offset, bytes};
      vkCmdCopyBuffer(commands, buffers[binding].handle(), readback.handle(), 1, &region);
      offset += bytes;
    }
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  }
  // Empties the counts on the device: zeros, and no index for the first
  // non-finite finding.
  void RecordClear(VkCommandBuffer commands) const {
    vkCmdFillBuffer(commands, buffers[kCounts].handle(), 0, VK_WHOLE_SIZE, 0u);
    vkCmdFillBuffer(commands, buffers[kFirstNonFinite].handle(), 0, VK_WHOLE_SIZE, 0xffffffffu);
    vkCmdFillBuffer(commands, buffers[kUnwritten].handle(), 0, VK_WHOLE_SIZE, 0u);
  }
  Status Upload(const Batch& batch, ThreadPool& pool);
  void Bind(const DevicePositions& positions, const Batch& batch);
  void Record(VkCommandBuffer commands, const Batch& batch, const DevicePositions& positions, bool encodings) const;
  Status MergeMaxima(std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings) const;
  // Device accumulator k's host accumulator (null where none is kept) and
  // the host's numbers of its metrics.
  std::pair<CellAccumulator*, std::span<const Metric>> HostOf(std::size_t k, std::span<CellAccumulator> cells,
                                                              std::span<CellAccumulator> encodings) const {
    if (k < cell_count()) return {&cells[k], kCellMetrics};
    k -= cell_count();
    return {k < encodings.size() ? &encodings[k] : nullptr, kEncodingMetrics};
  }
  Status CheckSizes(std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings) const {
    if (cells.size() == cell_count() && (encodings.empty() || encodings.size() == depth_slots)) return Status::Ok();
    return InvalidArgument(fmt::format("{} and {} accumulators for {} cells and {} depth slots", cells.size(),
                                       encodings.size(), cell_count(), depth_slots));
  }
};

DeviceJudge::DeviceJudge(std::unique_ptr<State> state) : state_(std::move(state)) {}
DeviceJudge::~DeviceJudge() = default;

Expected<std::unique_ptr<DeviceJudge>> DeviceJudge::Create(Backend& backend, const RunLayout& layout,
                                                           bool record_distances) {
  std::shared_ptr<VulkanContext> context = ContextOf(backend);
  if (context == nullptr) return Unavailable("the " + backend.name() + " backend runs on no device to judge on");
  if (!context->shader_float64() || !context->int64_atomics()) {
    return Unavailable(fmt::format(
        "Vulkan device '{}' lacks float64 arithmetic or 64-bit atomics on storage buffers, which the device judge "
        "needs; judge on the host (--judge host)",
        context->properties().name));
  }
  auto state = std::make_unique<State>();
  state->backend = &backend;
  state->context = context;
  state->record_distances = record_distances;
  state->depth_slots = layout.encodings.size();
  for (std::uint32_t k = 0; k < layout.cells.size(); ++k) {
    state->every_cell.push_back(k);
    state->run_cells.push_back(layout.cells[k].cell);
  }
  const ValidationScope validation(*context);
  std::array<VkDescriptorSetLayoutBinding, kBindingCount> bindings{};
  for (std::uint32_t i = 0; i < kBindingCount; ++i) {
    bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  }
  DB_RETURN_IF_ERROR(StoreInto(ComputePass::Create(context, bindings, sizeof(L::JudgePass)), state->pass));
  DB_ASSIGN_OR_RETURN(const std::filesystem::path shaders, DataPath("shaders"));
  DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> spirv, CompileShader(shaders / "judge" / "judge.comp"));
  const VkSpecializationInfo none{};
  DB_RETURN_IF_ERROR(StoreInto(state->pass->CreatePipeline(spirv, none, "the device judge"), state->pipeline));

  // What stays the same for the whole run: which depth slot each cell
  // reads, and the counters, empty.
  DB_RETURN_IF_ERROR(state->Grow(kCellSlots, state->cell_count() * sizeof(std::uint32_t)));
  auto* slots = static_cast<std::uint32_t*>(state->buffers[kCellSlots].mapped());
  for (std::size_t k = 0; k < layout.cells.size(); ++k) slots[k] = layout.cells[k].depth_slot;
  DB_RETURN_IF_ERROR(state->buffers[kCellSlots].FlushHostWrites());
  DB_RETURN_IF_ERROR(state->Grow(kCounts, state->counts_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kFirstNonFinite, state->first_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kMaxima, state->maxima_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kUnwritten, state->unwritten_bytes()));
  DB_RETURN_IF_ERROR(StoreInto(context->CreateHostBuffer(state->maxima_bytes() + state->unwritten_bytes(),
                                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT, HostAccess::kReadback),
                               state->batch_readback));
  DB_RETURN_IF_ERROR(StoreInto(context->CreateHostBuffer(state->counts_bytes() + state->first_bytes(),
                                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT, HostAccess::kReadback),
                               state->flush_readback));
  const State& s = *state;
  DB_RETURN_IF_ERROR(state->pass->Submit([&s](VkCommandBuffer commands) {
    s.RecordClear(commands);
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  }));
  DB_RETURN_IF_ERROR(validation.Check("creating the device judge"));
  return std::unique_ptr<DeviceJudge>(new DeviceJudge(std::move(state)));
}

// The batch's reference, written into the upload buffers on every thread:
// at a GPU's rate one thread's copies would leave the device waiting.
Status DeviceJudge::State::Upload(const Batch& batch, ThreadPool& pool) {
  const std::size_t count = batch.count, frames = batch.frames.size();
  const std::size_t slot_samples = batch.reference.true_depth.size();
  DB_RETURN_IF_ERROR(Grow(kFrames, frames * 4 * sizeof(std::uint32_t)));
  DB_RETURN_IF_ERROR(Grow(kRays, 3 * count * sizeof(double)));
  DB_RETURN_IF_ERROR(Grow(kCoverage, count * sizeof(std::uint32_t)));
  DB_RETURN_IF_ERROR(Grow(kReference, 5 * slot_samples * sizeof(double)));
  DB_RETURN_IF_ERROR(Grow(kReferenceInfo, slot_samples * sizeof(std::uint32_t)));

  auto* frame_words = static_cast<std::uint32_t*>(buffers[kFrames].mapped());
  for (std::size_t f = 0; f < frames; ++f) {
    const glm::dvec3& camera = batch.frames[f].camera_position;  // float32 values (sampler.h)
    for (int c = 0; c < 3; ++c) frame_words[4 * f + c] = std::bit_cast<std::uint32_t>(static_cast<float>(camera[c]));
    frame_words[4 * f + 3] = batch.distance_bands[f];
  }
  const ReferenceArrays& ref = batch.reference;
  auto* rays = static_cast<double*>(buffers[kRays].mapped());
  auto* coverage = static_cast<std::uint32_t*>(buffers[kCoverage].mapped());
  auto* reference = static_cast<double*>(buffers[kReference].mapped());
  auto* info = static_cast<std::uint32_t*>(buffers[kReferenceInfo].mapped());
  // Per sample, then per (slot, sample): chunks of both, in one loop.
  constexpr std::size_t kChunk = 16384;
  const std::size_t sample_chunks = (count + kChunk - 1) / kChunk;
  const std::size_t slot_chunks = (slot_samples + kChunk - 1) / kChunk;
  pool.ParallelFor(sample_chunks + slot_chunks, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t job = begin; job < end; ++job) {
      const bool per_sample = job < sample_chunks;
      const std::size_t lo = (per_sample ? job : job - sample_chunks) * kChunk;
      const std::size_t n = std::min(kChunk, (per_sample ? count : slot_samples) - lo);
      if (per_sample) {
        std::memcpy(rays + lo, batch.ray_x.data() + lo, n * sizeof(double));
        std::memcpy(rays + count + lo, batch.ray_y.data() + lo, n * sizeof(double));
        std::memcpy(rays + 2 * count + lo, batch.ray_z.data() + lo, n * sizeof(double));
        for (std::size_t i = lo; i < lo + n; ++i) coverage[i] = static_cast<std::uint32_t>(batch.samples.coverage[i]);
        continue;
      }
      std::memcpy(reference + lo, ref.true_depth.data() + lo, n * sizeof(double));
      std::memcpy(reference + slot_samples + lo, ref.denoted_depth.data() + lo, n * sizeof(double));
      std::memcpy(reference + 2 * slot_samples + lo, ref.inverse_distance_sq.data() + lo, n * sizeof(double));
      std::memcpy(reference + 3 * slot_samples + lo, ref.storage_square.data() + lo, n * sizeof(double));
      std::memcpy(reference + 4 * slot_samples + lo, ref.production_square.data() + lo, n * sizeof(double));
      for (std::size_t r = lo; r < lo + n; ++r) {
        info[r] = ref.joint_band[r] | static_cast<std::uint32_t>(ref.status[r]) << 8 |
                  static_cast<std::uint32_t>(ref.stored_holdable[r] != 0) << 16;
      }
    }
  });
  for (Binding b : {kFrames, kRays, kCoverage, kReference, kReferenceInfo}) {
    DB_RETURN_IF_ERROR(buffers[b].FlushHostWrites());
  }
  return Status::Ok();
}

// Points every binding at the bytes this batch uses.
void DeviceJudge::State::Bind(const DevicePositions& positions, const Batch& batch) {
  const std::size_t count = batch.count, slot_samples = batch.reference.true_depth.size();
  const std::array<VkDeviceSize, kBindingCount> bytes = {
      cell_count() * sizeof(std::uint32_t),
      positions.bytes,
      batch.frames.size() * 4 * sizeof(std::uint32_t),
      3 * count * sizeof(double),
      count * sizeof(std::uint32_t),
      5 * slot_samples * sizeof(double),
      slot_samples * sizeof(std::uint32_t),
      counts_bytes(),
      first_bytes(),
      maxima_bytes(),
      unwritten_bytes()};
  std::array<VkDescriptorBufferInfo, kBindingCount> infos{};
  std::array<VkWriteDescriptorSet, kBindingCount> writes{};
  for (std::uint32_t b = 0; b < kBindingCount; ++b) {
    infos[b] = {b == kPositions ? positions.buffer : buffers[b].handle(), 0, bytes[b]};
    writes[b].dstBinding = b;
    writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &infos[b];
  }
  pass->WriteDescriptors(writes);
}

void DeviceJudge::State::Record(VkCommandBuffer commands, const Batch& batch, const DevicePositions& positions,
                                bool encodings) const {
  // This batch's maxima start at nothing: zero squares, no index.
  const VkDeviceSize half = maxima() * sizeof(std::uint64_t);
  vkCmdFillBuffer(commands, buffers[kMaxima].handle(), 0, half, 0u);
  vkCmdFillBuffer(commands, buffers[kMaxima].handle(), half, half, 0xffffffffu);
  // Those fills, and the reconstruction pass's positions (an earlier
  // submission to the same queue), before the judge reads.
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  pass->Bind(commands, pipeline.get());
  L::JudgePass constants{.count = batch.count,
                         .lead = positions.lead,
                         .slice_length = positions.slice_length,
                         .first_offset = batch.first_offset,
                         .first_index_lo = static_cast<std::uint32_t>(batch.first_index),
                         .first_index_hi = static_cast<std::uint32_t>(batch.first_index >> 32),
                         .phase = 0,
                         .record_distances = record_distances ? 1u : 0u,
                         .cells = static_cast<std::uint32_t>(cell_count()),
                         .depth_slots = static_cast<std::uint32_t>(batch.reference.true_depth.size() / batch.count),
                         .accumulators = static_cast<std::uint32_t>(accumulators()),
                         .reserved2 = 0};
  const auto rows = static_cast<std::uint32_t>(cell_count() + (encodings ? depth_slots : 0));
  const std::uint32_t groups = (batch.count + kWorkgroupSize - 1) / kWorkgroupSize;
  for (std::uint32_t phase = 0; phase < 2; ++phase) {
    constants.phase = phase;
    pass->PushConstants(commands, &constants, sizeof(constants));
    vkCmdDispatch(commands, groups, rows, 1);
    // Phase 1 reads the maxima phase 0 raised; the copy below reads both.
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
  }
  RecordReadback(commands, {{kMaxima, maxima_bytes()}, {kUnwritten, unwritten_bytes()}}, batch_readback);
}

// A batch's maxima join the accumulators' as the host judge's Record does:
// a larger square replaces the slot's maximum and index; an equal one
// keeps the earlier batch's, whose indices are smaller.
Status DeviceJudge::State::MergeMaxima(std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings) const {
  DB_RETURN_IF_ERROR(batch_readback.InvalidateForHostReads());
  const auto* words = static_cast<const std::uint64_t*>(batch_readback.mapped());
  const auto* unwritten = reinterpret_cast<const std::uint32_t*>(words + 2 * maxima());
  for (std::size_t k = 0; k < cell_count(); ++k) {
    if (unwritten[k] == 0) continue;
    return InvalidArgument(fmt::format(
        "the {} shader did not write its output for {} samples (cell {}): it returns before writing, or writes "
        "another element; nothing it did not write is judged",
        Info(run_cells[k].variant).name, unwritten[k], run_cells[k].Name()));
  }
  for (std::size_t at = 0; at < maxima(); ++at) {
    if (words[at] == 0) continue;
    const auto [host, metrics] = HostOf(at / (L::DB_JUDGE_SLOTS * L::DB_JUDGE_METRICS), cells, encodings);
    const std::size_t device_metric = at % L::DB_JUDGE_METRICS;
    if (host == nullptr || device_metric >= metrics.size()) continue;
    const int m = static_cast<int>(metrics[device_metric]);
    CellAccumulator::Slot& to = host->At(static_cast<int>(at / L::DB_JUDGE_METRICS % L::DB_JUDGE_SLOTS));
    const double square = std::bit_cast<double>(words[at]);
    if (square > to.max_square[m]) {
      to.max_square[m] = square;
      to.worst_index[m] = words[maxima() + at];
    }
  }
  return Status::Ok();
}

std::uint64_t DeviceJudge::MaxBatchSamples() const {
  const State& s = *state_;
  // Per sample: five doubles per depth slot (the reference), three (the ray).
  const std::uint64_t widest = sizeof(double) * std::max<std::uint64_t>(5 * s.depth_slots, 3);
  return std::max<std::uint64_t>(s.context->properties().limits.maxStorageBufferRange / widest, kWorkgroupSize);
}

Status DeviceJudge::Judge(const Batch& batch, std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings,
                          ThreadPool& pool) {
  State& s = *state_;
  DB_RETURN_IF_ERROR(s.CheckSizes(cells, encodings));
  if (batch.count == 0) return Status::Ok();
  DB_ASSIGN_OR_RETURN(const DevicePositions positions, RunLeavingOnDevice(*s.backend, batch, s.every_cell));
  const ValidationScope validation(*s.context);
  DB_RETURN_IF_ERROR(s.Upload(batch, pool));
  s.Bind(positions, batch);
  DB_RETURN_IF_ERROR(s.pass->Submit(
      [&](VkCommandBuffer commands) { s.Record(commands, batch, positions, !encodings.empty()); }));
  DB_RETURN_IF_ERROR(validation.Check("judging on the device"));
  DB_RETURN_IF_ERROR(s.MergeMaxima(cells, encodings));
  for (CellAccumulator& a : cells) a.Count(batch.count);
  for (CellAccumulator& a : encodings) a.Count(batch.count);
  return Status::Ok();
}

Status DeviceJudge::Flush(std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings) {
  State& s = *state_;
  DB_RETURN_IF_ERROR(s.CheckSizes(cells, encodings));
  // The counts come back and are cleared on the device in one submission.
  const ValidationScope validation(*s.context);
  DB_RETURN_IF_ERROR(s.pass->Submit([&s](VkCommandBuffer commands) {
    s.RecordReadback(commands, {{kCounts, s.counts_bytes()}, {kFirstNonFinite, s.first_bytes()}}, s.flush_readback);
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                        VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    s.RecordClear(commands);
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  }));
  DB_RETURN_IF_ERROR(validation.Check("reading back the device judge's counts"));
  DB_RETURN_IF_ERROR(s.flush_readback.InvalidateForHostReads());
  const auto* counts = static_cast<const std::uint32_t*>(s.flush_readback.mapped());
  const auto* first = reinterpret_cast<const std::uint64_t*>(counts + s.counted_slots() * L::DB_JUDGE_SLOT_UINTS);
  for (std::size_t at = 0; at < s.counted_slots(); ++at) {
    const std::uint32_t* from = counts + at * L::DB_JUDGE_SLOT_UINTS;
    const std::uint32_t* tally = from + L::DB_JUDGE_METRICS * L::DB_JUDGE_BINS;
    if (std::all_of(from, from + L::DB_JUDGE_SLOT_UINTS, [](std::uint32_t n) { return n == 0; })) continue;
    const auto [host, metrics] = s.HostOf(at / L::DB_JUDGE_SLOTS, cells, encodings);
    if (host == nullptr) continue;
    CellAccumulator::Slot& to = host->At(static_cast<int>(at % L::DB_JUDGE_SLOTS));
    for (std::size_t m = 0; m < metrics.size(); ++m) {
      auto& bins = to.bins[static_cast<int>(metrics[m])];
      for (std::size_t b = 0; b < L::DB_JUDGE_BINS; ++b) bins[b] += from[m * L::DB_JUDGE_BINS + b];
    }
    if (tally[0] + tally[1] > 0 && (to.nan + to.inf == 0 || first[at] < to.first_nonfinite_index)) {
      to.first_nonfinite_index = first[at];
    }
    to.nan += tally[0];
    to.inf += tally[1];
    to.stored_nonfinite += tally[2];
    to.degenerate += tally[3];
    to.outside += tally[4];
  }
  return Status::Ok();
}

}  // namespace depthbench
