#include "bench/device_judge/device_judge.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <limits>
#include <numeric>
#include <optional>
#include <tuple>
#include <vector>

#include <fmt/format.h>

#include "bench/backends/vulkan/compute_pass.h"
#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/backends/vulkan/timestamps.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/base/resources.h"
#include "bench/device_judge/judge_groups.h"

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
              L::DB_JUDGE_STATUS_OUTSIDE == static_cast<unsigned>(ReferenceStatus::kOutside) &&
              L::DB_JUDGE_STATUS_UNDRAWN == static_cast<unsigned>(ReferenceStatus::kUndrawn));
static_assert(static_cast<int>(Coverage::kNatural) == 0 && CoverageBand(Coverage::kStoredZero) == 0);
static_assert(sizeof(L::JudgePass) == 64);
static_assert(L::DB_JUDGE_FRAME_DRAWS == 7 + 9 + 2);  // shared/draw.h's DrawFrame, its rotation's nine
static_assert(L::DB_JUDGE_TEXEL_UNORM == static_cast<unsigned>(TexelKind::kUnorm) &&
              L::DB_JUDGE_TEXEL_FLOAT32 == static_cast<unsigned>(TexelKind::kFloat32) &&
              L::DB_JUDGE_TEXEL_FLOAT16 == static_cast<unsigned>(TexelKind::kFloat16));
static_assert(L::DB_JUDGE_HARDWARE_CONVENTIONS == kHardwareConventionCount &&
              L::DB_JUDGE_FRAME_WORDS == 2 + 2 * L::DB_JUDGE_HARDWARE_CONVENTIONS);
static_assert(L::DB_JUDGE_DEPTH_BANDS == kDepthBands && L::DB_JUDGE_INFINITE_RATIO_BAND == kInfiniteRatioBand);
static_assert(kSamplesPerFrame == 64);  // bindings.glsl's frame_of
static_assert(L::DB_JUDGE_STORES_WINDOW_DEPTH == static_cast<unsigned>(DepthInput::kHardware) &&
              L::DB_JUDGE_STORES_LINEAR == static_cast<unsigned>(DepthInput::kLinear) &&
              L::DB_JUDGE_STORES_VIEW_Z == static_cast<unsigned>(DepthInput::kViewZ));
// The host's values fit their fields of judge.h's words: a depth slot's
// convention bits and hardware index in four bits each, a joint band in a
// byte; coverage kinds, depth picks and statuses are bytes already.
static_assert((f32::DB_CONVENTION_REVERSED | f32::DB_CONVENTION_INFINITE | f32::DB_CONVENTION_CLIP_MINUS_ONE) <= 0xfu &&
              L::DB_JUDGE_HARDWARE_CONVENTIONS <= 16 && L::DB_JUDGE_JOINT_SLOTS <= 256);
static_assert(sizeof(Coverage) == 1 && sizeof(DepthPick) == 1 && sizeof(ReferenceStatus) == 1);

// The metrics the device records, in its order, as the host numbers them:
// a cell's, and a depth slot's (its third is unused).
constexpr std::array<Metric, L::DB_JUDGE_METRICS> kCellMetrics = {Metric::kTotal, Metric::kArith, Metric::kAbsolute};
constexpr std::array<Metric, 2> kEncodingMetrics = {Metric::kStorage, Metric::kProduction};
constexpr std::uint32_t kWorkgroupSize = 64;  // store.comp's and reference.comp's local_size_x
constexpr std::size_t kUploadChunk = 16384;   // samples per job of the uploads
constexpr std::uint32_t kNoDepthSlot = 0xffffffffu;  // bindings.glsl's: the end of a pipeline's slots

// The storage buffers of the three passes, by binding number
// (shaders/judge/bindings.glsl says what each holds).
enum Binding : std::uint32_t {
  kLayout,
  kPositions,  // the backend's
  kFrames,
  kRays,
  kCoverage,
  kFrameDepths,
  kFrameConstants,
  kEyeDepths,
  kPipelineFloats,
  kTexels,  // the backend's
  kReference,
  kReferenceInfo,
  kCounts,
  kFirstNonFinite,
  kMaxima,
  kUnwritten,
  kEdgeTexels,
  kFrameDraws,
  kPixels,  // the backend's
  kCandidates,
  kCandidateCounts,
  // The fused pass's copies of the backend's frame constants and pixels.
  kFrameParams,
  kDepthParams,
  kFusedPixels,
  kTexelStatus,  // the backend's, where its rasterizer drew the texels
  kBindingCount,
};
// The reference and the counters live in device memory alone (atomics
// across the bus would cost the device its speed); transfers copy them
// into host-readable buffers: each batch's maxima and the unwritten counts
// after the batch, the histograms and counts at a flush.
bool DeviceOnly(Binding b) { return (b >= kReference && b <= kUnwritten) || b >= kCandidates; }
// The bindings whose buffers the backend owns (DeviceRunBuffers).
bool Backends(Binding b) { return b == kPositions || b == kTexels || b == kPixels || b == kTexelStatus; }
// What the host writes for every batch: one buffer per lane (below), so
// that it writes the next batch's while the device reads the last's.
bool PerBatch(Binding b) { return b != kLayout && !Backends(b) && !DeviceOnly(b); }

// Two batches in flight: while the device runs one lane's passes, the host
// writes the other's inputs. Each lane has its own uploads, descriptor
// set, maxima readback, and two submission slots of the pass (the storage
// pass, queued before the backend's, and the reference and judge after).
constexpr std::uint32_t kLanes = 2;
constexpr std::uint32_t StoreSlot(std::uint32_t lane) { return 2 * lane; }
constexpr std::uint32_t JudgeSlot(std::uint32_t lane) { return 2 * lane + 1; }

// What the reference and storage passes need of a depth slot's encoding
// (judge.h's db_encoding_word): what the format stores, the convention's
// bits and hardware index, whether its far plane is at infinity, and the
// slot's pipeline.
std::uint32_t EncodingWord(Encoding encoding, std::uint32_t pipeline) {
  const ConventionInfo& convention = Info(encoding.convention);
  const auto hardware = convention.hardware ? DepthSlot(encoding.convention) : 0u;
  // As reference.cc's ReferencesBody reads a far plane at infinity.
  const bool infinite_far = convention.hardware && (convention.bits & f32::DB_CONVENTION_INFINITE) != 0u;
  return L::db_encoding_word(static_cast<std::uint32_t>(Info(encoding.format).stores), convention.bits, hardware,
                             infinite_far, pipeline);
}
// What the storage pass needs of a depth slot's format (judge.h's
// db_texel_word): how it keeps a value, and a unorm's bits.
std::uint32_t TexelWord(Format format) {
  const FormatInfo& info = Info(format);
  return L::db_texel_word(static_cast<std::uint32_t>(info.texel),
                          info.texel == TexelKind::kUnorm ? static_cast<std::uint32_t>(info.bits) : 0u);
}

}  // namespace

// With the table: as large as the device allows, up to 1024 invocations,
// 16384 samples (below 2^15, the count an entry holds) and 4096 entries
// (16 KiB), beside judge.glsl's word per (slot, metric) of the group's
// running maxima, in the shared memory the device allows a workgroup
// (16 KiB on some devices, which then get a table half as large). Larger
// groups merge more of their bins before the device's counters see them
// (reports/device-judge/lavapipe.txt, section 2). Fewer, wider groups hold
// less shared memory on each of a GPU's multiprocessors at once, and what
// they do not hold serves as cache: the widest groups are the fastest, and
// a larger table is slower at every width (reports/device-judge/h200.txt,
// section 23). Without the table (a CPU device by default, where the
// table is slower: lavapipe.txt, section 2): a sample per invocation, in
// groups of 64.
JudgeGroups ChooseJudgeGroups(const VulkanDeviceProperties& device, DeviceJudgeTuning tuning) {
  JudgeBinMerge bins = tuning.bins;
  if (bins == JudgeBinMerge::kAuto) {
    bins = device.type == VK_PHYSICAL_DEVICE_TYPE_CPU ? JudgeBinMerge::kDeviceCounters : JudgeBinMerge::kWorkgroupTable;
  }
  if (bins == JudgeBinMerge::kDeviceCounters) {
    return {.invocations = 64,
            .samples = 64,
            .table_entries = 1,
            .use_table = VK_FALSE,
            .candidates_per_row = tuning.candidates_per_row};
  }
  const VkPhysicalDeviceLimits& limits = device.limits;
  JudgeGroups groups{
      .invocations = std::min({1024u, limits.maxComputeWorkGroupInvocations, limits.maxComputeWorkGroupSize[0]}),
      .samples = 16384,
      .table_entries = 4096,
      .use_table = VK_TRUE,
      .candidates_per_row = tuning.candidates_per_row};
  while (JudgeSharedWords(groups) * sizeof(std::uint32_t) > limits.maxComputeSharedMemorySize) {
    groups.table_entries /= 2;
  }
  return groups;
}

std::uint32_t JudgeSharedWords(const JudgeGroups& groups) {
  return groups.table_entries + L::DB_JUDGE_SLOTS * L::DB_JUDGE_METRICS;  // judge.glsl's table and group_high
}

namespace {

// Where each batch's timestamps are written: at the start of the storage
// submission (once everything queued before has finished), after the
// sample pass, at its end, at the start of the judge's submission, after
// the reference, after each judge phase. The passes' times are the
// intervals between them, named by kPassNames: the reconstruction's is the
// backend's pass, queued between the two submissions, with any time the
// device waits for the judge's submission; "idle" is the time from the
// batch before's end to this one's start.
// Where the judge is fused, the reconstruction runs in the judge's phase
// 0, and the interval between the submissions is the wait alone.
enum Mark : std::uint32_t { kStoreStart, kSampled, kStored, kJudgeStart, kReferenced, kJudged, kMaximaFound, kMarks };
constexpr std::array<const char*, kMarks> kPassNames = {"idle",      "sample", "store", "reconstruction",
                                                        "reference", "judge",  "maxima"};
constexpr std::array<const char*, kMarks> kFusedPassNames = {"idle",      "sample",
                                                             "store",     "wait",
                                                             "reference", "reconstruction+judge",
                                                             "maxima"};

// The steps of Judge on the host (DeviceJudge::host_seconds).
enum HostStep : std::uint32_t { kFinishStep, kUploadStep, kStageStep, kQueueStep, kHostSteps };
constexpr std::array<const char*, kHostSteps> kHostStepNames = {"finish", "upload", "stage", "queue"};
// Adds the time since the last lap to a step.
class Laps {
 public:
  explicit Laps(std::array<double, kHostSteps>& into) : into_(into) {}
  void Lap(HostStep step) {
    const auto now = std::chrono::steady_clock::now();
    into_[step] += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  std::array<double, kHostSteps>& into_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

struct DeviceJudge::State {
  DeviceResidentRuns* runs = nullptr;  // the backend's
  std::shared_ptr<VulkanContext> context;
  std::unique_ptr<ComputePass> pass;
  DeviceObject<VkPipeline> sample_pipeline;
  DeviceObject<VkPipeline> store_pipeline;
  DeviceObject<VkPipeline> reference_pipeline;
  DeviceObject<VkPipeline> judge_pipeline;
  // Where the judge is fused (JudgeFusion): per variant of the run, its
  // program, and its rows: `rows` cells from `first_row` of the fused row
  // order. Empty where it is not.
  struct FusedVariant {
    DeviceObject<VkPipeline> pipeline;
    std::uint32_t first_row = 0, rows = 0;
  };
  std::vector<FusedVariant> fused;
  // [lane][binding]: lane 0 holds the bindings every lane shares (kPositions
  // and kTexels unused: the backend owns them); PerBatch ones are per lane.
  std::array<std::array<VulkanBuffer, kBindingCount>, kLanes> lane_buffers;
  std::array<VulkanBuffer, kLanes> batch_readbacks;  // the maxima, then the unwritten counts
  // A lane's batch queued on the device and not yet joined to the
  // accumulators: its samples, where its maxima go, and its order.
  struct Pending {
    bool queued = false;
    std::uint32_t count = 0;
    std::span<CellAccumulator> cells, encodings;
    std::uint64_t order = 0;
  };
  std::array<Pending, kLanes> pending;
  std::uint32_t lane = 0;       // the lane of the batch being uploaded
  std::uint64_t batches = 0;    // queued so far
  VulkanBuffer flush_readback;  // the counts, then the first non-finite indices
  std::vector<std::uint32_t> every_cell;
  std::vector<Cell> run_cells;
  std::size_t depth_slots = 0;
  std::size_t pipelines = 0;
  std::uint32_t last_count = 0;  // samples of the last batch judged
  DeviceRunBuffers last_run;     // the backend's buffers for it
  ProductionModel production = ProductionModel::kFloat32;
  bool record_distances = true;
  JudgeGroups judge_groups;
  double waited = 0.0;  // seconds Judge spent waiting for the device's passes
  // The host's seconds in each step of Judge (host_seconds), named by
  // kHostStepNames.
  std::array<double, kHostSteps> host_steps{};
  // Each lane's batch writes kMarks timestamps (Mark), where the device's
  // queue writes them; Finish adds the intervals into pass_seconds.
  TimestampQueries clock;
  std::array<double, kMarks> pass_seconds{};
  std::optional<std::uint64_t> last_end;  // the timestamp the last finished batch ended at
  std::uint32_t Query(std::uint32_t lane_of, std::uint32_t mark) const { return lane_of * kMarks + mark; }
  void RecordMark(VkCommandBuffer commands, Mark mark) const {
    if (clock.count() > 0) clock.RecordWrite(commands, Query(lane, mark));
  }
  Status AddPassSeconds(std::uint32_t lane_of);

  std::size_t cell_count() const { return every_cell.size(); }
  // The cells' accumulators, then the depth slots'.
  std::size_t accumulators() const { return cell_count() + depth_slots; }
  std::size_t counted_slots() const { return accumulators() * L::DB_JUDGE_SLOTS; }
  std::size_t row_order_at() const { return cell_count() + 3 * depth_slots + pipelines; }
  // The fused passes' rows: the cells grouped by variant.
  std::size_t fused_rows_at() const { return row_order_at() + accumulators(); }
  // Per cell, its convention slot within a frame's DepthParams.
  std::size_t cell_conventions_at() const { return fused_rows_at() + cell_count(); }
  std::size_t layout_words() const { return cell_conventions_at() + cell_count(); }
  // Whether the storage pass produces the pipelines' floats (float32
  // production) or the host uploads them (exact production, which rounds
  // with MPFR where a tie needs it; the raster form, whose floats are the
  // host's model of a rasterizer).
  bool device_produces() const { return production == ProductionModel::kFloat32; }
  // Whether the backend's rasterizer stores the texels (the raster form),
  // rather than the storage pass.
  bool rasterized() const { return production == ProductionModel::kRaster; }
  std::size_t maxima() const { return counted_slots() * L::DB_JUDGE_METRICS; }

  VkDeviceSize counts_bytes() const { return counted_slots() * L::DB_JUDGE_SLOT_UINTS * sizeof(std::uint32_t); }
  VkDeviceSize first_bytes() const { return counted_slots() * sizeof(std::uint64_t); }
  VkDeviceSize maxima_bytes() const { return 2 * maxima() * sizeof(std::uint64_t); }
  VkDeviceSize unwritten_bytes() const { return cell_count() * sizeof(std::uint32_t); }
  VkDeviceSize candidates_bytes() const {
    return accumulators() * judge_groups.candidates_per_row * 4 * sizeof(std::uint32_t);
  }
  VkDeviceSize candidate_counts_bytes() const { return accumulators() * sizeof(std::uint32_t); }

  VulkanBuffer& Buffer(Binding b) { return lane_buffers[PerBatch(b) ? lane : 0][b]; }
  const VulkanBuffer& Buffer(Binding b) const { return lane_buffers[PerBatch(b) ? lane : 0][b]; }
  Status Grow(Binding binding, VkDeviceSize bytes) {
    bytes = std::max<VkDeviceSize>(bytes, 16);
    // A buffer every lane shares is replaced only with nothing in flight.
    if (!PerBatch(binding) && Buffer(binding).size() < bytes) DB_RETURN_IF_ERROR(FinishAll());
    return context->GrowHostBuffer(
        Buffer(binding), bytes,
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
        DeviceOnly(binding) ? HostAccess::kNone : HostAccess::kUpload);
  }
  // Copies `bytes` of each source to `readback`, one after the other, and
  // makes them visible to the host.
  void RecordReadback(VkCommandBuffer commands, std::initializer_list<std::pair<Binding, VkDeviceSize>> sources,
                      const VulkanBuffer& readback) const {
    VkDeviceSize offset = 0;
    for (const auto& [binding, bytes] : sources) {
      const VkBufferCopy region{0, offset, bytes};
      vkCmdCopyBuffer(commands, Buffer(binding).handle(), readback.handle(), 1, &region);
      offset += bytes;
    }
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  }
  // Empties the counts on the device: zeros, and no index for the first
  // non-finite finding.
  void RecordClear(VkCommandBuffer commands) const {
    vkCmdFillBuffer(commands, Buffer(kCounts).handle(), 0, VK_WHOLE_SIZE, 0u);
    vkCmdFillBuffer(commands, Buffer(kFirstNonFinite).handle(), 0, VK_WHOLE_SIZE, 0xffffffffu);
    vkCmdFillBuffer(commands, Buffer(kUnwritten).handle(), 0, VK_WHOLE_SIZE, 0u);
  }
  Status UploadForStorage(const Batch& batch, const DeviceJudgeInputs& device, ThreadPool& pool);
  Status UploadForReference(const Batch& batch, const DeviceJudgeInputs& device, ThreadPool& pool);
  void Bind(const DeviceRunBuffers& run, const Batch& batch);
  L::JudgePass PassConstants(const Batch& batch, const DeviceJudgeInputs& device, const DeviceRunBuffers& run) const;
  // The fused pass's copies of the backend's frame constants and pixels,
  // by binding, and their bytes (none where the judge is not fused).
  std::array<std::pair<Binding, VkDeviceSize>, 3> FusedCopies(const DeviceRunBuffers& run) const {
    const bool copies = !fused.empty();
    return {{{kFrameParams, copies ? run.frame_param_bytes : 0},
             {kDepthParams, copies ? run.depth_param_bytes : 0},
             {kFusedPixels, copies ? run.pixel_bytes : 0}}};
  }
  // The sample pass where the device draws (`draws`); fused, the copies of
  // the backend's frame constants and pixels (FusedCopies); the storage pass.
  void RecordStore(VkCommandBuffer commands, L::JudgePass constants, bool draws, const DeviceRunBuffers& run) const;
  // The reference and judge passes, and the copy of the maxima.
  void Record(VkCommandBuffer commands, L::JudgePass constants, bool encodings) const;
  Status MergeMaxima(std::uint32_t lane, std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings) const;
  // Waits for `lane`'s batch, if one is queued, and joins its maxima and
  // samples to the accumulators it was given.
  Status Finish(std::uint32_t lane);
  // Finishes every lane's batch, the earlier first (an equal maximum keeps
  // the earlier batch's index).
  Status FinishAll() {
    const std::uint32_t first = pending[0].order <= pending[1].order ? 0 : 1;
    DB_RETURN_IF_ERROR(Finish(first));
    return Finish(1 - first);
  }
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
                                                           ProductionModel production, bool record_distances,
                                                           DeviceJudgeTuning tuning) {
  DeviceResidentRuns* runs = backend.device_resident();
  if (runs == nullptr) return Unavailable("the " + backend.name() + " backend runs on no device to judge on");
  const std::shared_ptr<VulkanContext>& context = runs->context();
  if (production == ProductionModel::kRaster && tuning.fusion == JudgeFusion::kFused) {
    return Unavailable("the raster form reconstructs in a fragment pass, which the device judge cannot fuse with its "
                       "own (--judge-fusion separate)");
  }
  for (const Encoding& encoding : layout.encodings) {
    if (Info(encoding.convention).orthographic()) {
      return Unavailable("the device judge's reference follows rays through a perspective frustum; orthographic "
                         "projections are judged on the host (--judge host)");
    }
  }
  if (!context->shader_float64() || !context->int64_atomics()) {
    return Unavailable(fmt::format(
        "Vulkan device '{}' lacks float64 arithmetic or 64-bit atomics on storage buffers, which the device judge "
        "needs; judge on the host (--judge host)",
        context->properties().name));
  }
  auto state = std::make_unique<State>();
  state->runs = runs;
  state->context = context;
  state->record_distances = record_distances;
  state->production = production;
  state->depth_slots = layout.encodings.size();
  const std::vector<std::uint32_t> pipeline_of_slot = PipelineOfSlots(layout.encodings);
  for (std::uint32_t p : pipeline_of_slot) state->pipelines = std::max<std::size_t>(state->pipelines, p + 1);
  for (std::uint32_t k = 0; k < layout.cells.size(); ++k) {
    state->every_cell.push_back(k);
    state->run_cells.push_back(layout.cells[k].cell);
  }
  const ValidationScope validation(*context);
  std::array<VkDescriptorSetLayoutBinding, kBindingCount> bindings{};
  for (std::uint32_t i = 0; i < kBindingCount; ++i) {
    bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  }
  DB_RETURN_IF_ERROR(StoreInto(
      ComputePass::Create(context, bindings, sizeof(L::JudgePass), VK_SHADER_STAGE_COMPUTE_BIT, kLanes, 2 * kLanes),
      state->pass));
  // Where the queue writes no timestamps, the passes go untimed.
  if (TimestampQueries::Supported(*context).ok()) {
    DB_ASSIGN_OR_RETURN(state->clock, TimestampQueries::Create(*context, kLanes * kMarks));
  }
  DB_ASSIGN_OR_RETURN(const std::filesystem::path shaders, DataPath("shaders"));
  state->judge_groups = ChooseJudgeGroups(context->properties(), tuning);
  static_assert(sizeof(JudgeGroups) == 5 * sizeof(std::uint32_t));
  const std::array<VkSpecializationMapEntry, 5> group_entries = {{
      {0, offsetof(JudgeGroups, invocations), sizeof(std::uint32_t)},
      {1, offsetof(JudgeGroups, samples), sizeof(std::uint32_t)},
      {2, offsetof(JudgeGroups, table_entries), sizeof(std::uint32_t)},
      {3, offsetof(JudgeGroups, use_table), sizeof(VkBool32)},
      {4, offsetof(JudgeGroups, candidates_per_row), sizeof(std::uint32_t)},
  }};
  const VkSpecializationInfo judge_shape{static_cast<std::uint32_t>(group_entries.size()), group_entries.data(),
                                         sizeof(JudgeGroups), &state->judge_groups};
  for (auto [name, pipeline, specialization] :
       {std::tuple{"sample.comp", &state->sample_pipeline, VkSpecializationInfo{}},
        std::tuple{"store.comp", &state->store_pipeline, VkSpecializationInfo{}},
        std::tuple{"reference.comp", &state->reference_pipeline, VkSpecializationInfo{}},
        std::tuple{"judge.comp", &state->judge_pipeline, judge_shape}}) {
    DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> spirv, CompileShader(shaders / "judge" / name));
    DB_RETURN_IF_ERROR(StoreInto(state->pass->CreatePipeline(spirv, specialization, "the device judge"), *pipeline));
  }
  // The fused programs: one per variant of the run, whose rows are its
  // cells (grouped by variant in the fused row order, each group's by
  // depth slot as below).
  std::vector<std::uint32_t> fused_rows(layout.cells.size());
  std::iota(fused_rows.begin(), fused_rows.end(), 0u);
  const auto variant_of = [&](std::uint32_t k) { return static_cast<int>(layout.cells[k].cell.variant); };
  std::stable_sort(fused_rows.begin(), fused_rows.end(), [&](std::uint32_t a, std::uint32_t b) {
    return std::pair(variant_of(a), layout.cells[a].depth_slot) < std::pair(variant_of(b), layout.cells[b].depth_slot);
  });
  // Auto fuses on a GPU. On a CPU device (lavapipe) the separate passes
  // are the faster: there each invocation of the fused pass loads its
  // frame's constants lane by lane, where compute_pass.glsl loads them once
  // for several samples (7 times slower over 2e4 samples on 2 cores).
  const bool fuse = tuning.fusion == JudgeFusion::kFused ||
                    (tuning.fusion == JudgeFusion::kAuto && context->properties().type != VK_PHYSICAL_DEVICE_TYPE_CPU &&
                     production != ProductionModel::kRaster);
  if (fuse) {
    Status fusing = Status::Ok();
    for (std::uint32_t row = 0; row < fused_rows.size() && fusing.ok();) {
      std::uint32_t end = row;
      while (end < fused_rows.size() && variant_of(fused_rows[end]) == variant_of(fused_rows[row])) ++end;
      const VariantInfo& variant = layout.cells[fused_rows[row]].cell.variant_info();
      State::FusedVariant fused{.pipeline = {}, .first_row = row, .rows = end - row};
      Expected<std::vector<std::uint32_t>> spirv = runs->CompileJudged(variant);
      fusing = spirv.ok() ? StoreInto(state->pass->CreatePipeline(
                                          *spirv, judge_shape, fmt::format("{}'s fused judge", variant.name)),
                                      fused.pipeline)
                          : spirv.status();
      if (fusing.ok()) state->fused.push_back(std::move(fused));
      row = end;
    }
    if (!fusing.ok()) {
      // Auto falls back to the separate passes: the run is judged the same.
      if (tuning.fusion == JudgeFusion::kFused) return fusing;
      state->fused.clear();
    }
  }

  // What stays the same for the whole run: which depth slot each cell
  // reads, each slot's encoding and texel, and the counters, empty.
  DB_RETURN_IF_ERROR(state->Grow(kLayout, state->layout_words() * sizeof(std::uint32_t)));
  auto* words = static_cast<std::uint32_t*>(state->Buffer(kLayout).mapped());
  for (std::size_t k = 0; k < layout.cells.size(); ++k) words[k] = layout.cells[k].depth_slot;
  for (std::size_t s = 0; s < state->depth_slots; ++s) {
    words[state->cell_count() + s] = EncodingWord(layout.encodings[s], pipeline_of_slot[s]);
    words[state->accumulators() + s] = TexelWord(layout.encodings[s].format);
  }
  // Each pipeline's slots as a list: its first, and each one's next.
  std::uint32_t* next_slot = words + state->accumulators() + state->depth_slots;
  std::uint32_t* first_slot = next_slot + state->depth_slots;
  std::fill_n(first_slot, state->pipelines, kNoDepthSlot);
  for (std::uint32_t s = static_cast<std::uint32_t>(state->depth_slots); s-- > 0;) {
    next_slot[s] = first_slot[pipeline_of_slot[s]];
    first_slot[pipeline_of_slot[s]] = s;
  }
  // The judge's rows: the cells that read one depth slot one after the
  // other, so that the workgroups running at once share the slot's
  // reference in the device's cache; then the depth slots' own
  // accumulators, in order (a run that does not record them dispatches
  // the cells' rows alone).
  std::uint32_t* row_order = words + state->row_order_at();
  std::iota(row_order, row_order + state->accumulators(), 0u);
  std::stable_sort(row_order, row_order + state->cell_count(), [&](std::uint32_t a, std::uint32_t b) {
    return layout.cells[a].depth_slot < layout.cells[b].depth_slot;
  });
  std::copy(fused_rows.begin(), fused_rows.end(), words + state->fused_rows_at());
  for (std::size_t k = 0; k < layout.cells.size(); ++k) {
    words[state->cell_conventions_at() + k] = layout.cells[k].convention_slot;
  }
  DB_RETURN_IF_ERROR(state->Buffer(kLayout).FlushHostWrites());
  DB_RETURN_IF_ERROR(state->Grow(kCounts, state->counts_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kFirstNonFinite, state->first_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kMaxima, state->maxima_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kUnwritten, state->unwritten_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kCandidates, state->candidates_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kCandidateCounts, state->candidate_counts_bytes()));
  DB_RETURN_IF_ERROR(state->Grow(kTexelStatus, 16));  // bound, unread, where the backend has none
  for (VulkanBuffer& readback : state->batch_readbacks) {
    DB_RETURN_IF_ERROR(StoreInto(context->CreateHostBuffer(state->maxima_bytes() + state->unwritten_bytes(),
                                                           VK_BUFFER_USAGE_TRANSFER_DST_BIT, HostAccess::kReadback),
                                 readback));
  }
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

// What the device starts from, written into the upload buffers on every
// thread (at a GPU's rate one thread's copies would leave the device
// waiting), in two parts: what the storage pass reads, before it is
// queued, and what only the reference reads, while the reconstruction
// pass runs.
Status DeviceJudge::State::UploadForStorage(const Batch& batch, const DeviceJudgeInputs& device, ThreadPool& pool) {
  const std::size_t count = batch.count, frames = batch.frames.size();
  const std::size_t slot_samples = depth_slots * count, pipeline_samples = pipelines * count;
  if (!device_produces() && batch.pipeline_floats.size() != pipeline_samples) {
    return InvalidArgument(fmt::format("a batch of {} samples with {} pipeline values, for {} pipelines", count,
                                       batch.pipeline_floats.size(), pipelines));
  }
  for (const auto& [binding, bytes] : std::initializer_list<std::pair<Binding, std::size_t>>{
           {kFrames, frames * 4 * sizeof(std::uint32_t)},
           {kFrameDraws, frames * L::DB_JUDGE_FRAME_DRAWS * sizeof(double)},
           {kEdgeTexels, frames * depth_slots * 4 * sizeof(float)},
           {kFrameDepths, frames * L::DB_JUDGE_FRAME_DEPTHS * sizeof(double)},
           {kFrameConstants, frames * L::DB_JUDGE_FRAME_WORDS * sizeof(std::uint32_t)},
           {kRays, 3 * count * sizeof(double)},
           {kCoverage, count * sizeof(std::uint32_t)},
           {kEyeDepths, count * sizeof(double)},
           {kPipelineFloats, pipeline_samples * sizeof(float)},
           {kReference, 5 * slot_samples * sizeof(double)},
           {kReferenceInfo, slot_samples * sizeof(std::uint32_t)}}) {
    DB_RETURN_IF_ERROR(Grow(binding, bytes));
  }

  // What each frame and slot stores for the stored-value picks.
  const SampleArrays& samples = batch.samples;
  const std::size_t drawn = device.draw_seed ? 0 : count;
  if (device.edge_texels.size() != frames * depth_slots * 4 || samples.pick.size() != drawn) {
    return InvalidArgument(
        fmt::format("a batch of {} samples in {} frames with {} drawn samples and {} edge texels, for {} depth slots",
                    count, frames, samples.pick.size(), device.edge_texels.size(), depth_slots));
  }
  pool.Copy(Buffer(kEdgeTexels).mapped(), device.edge_texels.data(), device.edge_texels.size() * sizeof(float));
  // Per frame. The frame's planes are those the host's reference reads
  // for each of its samples (PlanesOf); what the sample pass draws from
  // is the host sampler's (DrawFrameOf). On the pool's threads, as the
  // copies are.
  auto* frame_draws = static_cast<double*>(Buffer(kFrameDraws).mapped());
  auto* frame_words = static_cast<std::uint32_t*>(Buffer(kFrames).mapped());
  auto* frame_depths = static_cast<double*>(Buffer(kFrameDepths).mapped());
  auto* frame_constants = static_cast<std::uint32_t*>(Buffer(kFrameConstants).mapped());
  const auto write_frame = [&](std::size_t f) {
    const glm::dvec3& camera = batch.frames[f].camera_position;  // float32 values (sampler.h)
    for (int c = 0; c < 3; ++c) frame_words[4 * f + c] = std::bit_cast<std::uint32_t>(static_cast<float>(camera[c]));
    frame_words[4 * f + 3] = batch.distance_bands[f];
    const FramePlanes planes = PlanesOf(batch.frames[f]);
    double* depths = frame_depths + f * L::DB_JUDGE_FRAME_DEPTHS;
    depths[0] = planes.near;
    depths[1] = planes.far;
    depths[2] = planes.depth_limit;
    depths[3] = planes.interest_min;
    depths[4] = planes.interest_max;
    const draw::DrawFrame draw = DrawFrameOf(batch.frames[f]);
    double* draws = frame_draws + f * L::DB_JUDGE_FRAME_DRAWS;
    for (const double value : {draw.eye_depth_min, draw.eye_depth_max, draw.log2_eye_depth_span, draw.tan_x, draw.tan_y,
                               static_cast<double>(draw.width), static_cast<double>(draw.height)}) {
      *draws++ = value;
    }
    for (int column = 0; column < 3; ++column) {
      for (int row = 0; row < 3; ++row) *draws++ = draw.rotation[column][row];
    }
    *draws++ = draw.centre_x;
    *draws++ = draw.centre_y;
    std::uint32_t* words = frame_constants + f * L::DB_JUDGE_FRAME_WORDS;
    words[0] = planes.ratio_band;
    words[1] = std::bit_cast<std::uint32_t>(batch.frame_params[f].camera_position.w);
    for (int c = 0; c < kHardwareConventionCount; ++c) {
      const f32::DepthParams& depth = batch.depth_params[f * kHardwareConventionCount + c];
      words[2 + 2 * c] = std::bit_cast<std::uint32_t>(depth.coefficients.x);
      words[3 + 2 * c] = std::bit_cast<std::uint32_t>(depth.coefficients.y);
    }
  };
  pool.ParallelFor(
      frames,
      [&](std::size_t begin, std::size_t end, unsigned) {
        for (std::size_t f = begin; f < end; ++f) write_frame(f);
      },
      256);
  auto* coverage = static_cast<std::uint32_t*>(Buffer(kCoverage).mapped());
  auto* eye_depths = static_cast<double*>(Buffer(kEyeDepths).mapped());
  auto* pipeline_floats = static_cast<float*>(Buffer(kPipelineFloats).mapped());
  // Chunks of the per-sample and per-(pipeline, sample) values, in one loop.
  const std::size_t sample_chunks = (drawn + kUploadChunk - 1) / kUploadChunk;
  const std::size_t pipeline_chunks = device_produces() ? 0 : (pipeline_samples + kUploadChunk - 1) / kUploadChunk;
  pool.ParallelFor(sample_chunks + pipeline_chunks, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t job = begin; job < end; ++job) {
      if (job < sample_chunks) {
        const std::size_t lo = job * kUploadChunk, n = std::min(kUploadChunk, count - lo);
        std::memcpy(eye_depths + lo, samples.eye_depth.data() + lo, n * sizeof(double));
        for (std::size_t i = lo; i < lo + n; ++i) {
          coverage[i] = L::db_coverage_word(static_cast<std::uint32_t>(samples.coverage[i]),
                                            static_cast<std::uint32_t>(samples.pick[i]));
        }
      } else {
        const std::size_t lo = (job - sample_chunks) * kUploadChunk;
        std::memcpy(pipeline_floats + lo, batch.pipeline_floats.data() + lo,
                    std::min(kUploadChunk, pipeline_samples - lo) * sizeof(float));
      }
    }
  });
  for (Binding b :
       {kFrames, kFrameDepths, kFrameConstants, kCoverage, kEyeDepths, kPipelineFloats, kEdgeTexels, kFrameDraws}) {
    DB_RETURN_IF_ERROR(Buffer(b).FlushHostWrites());
  }
  return Status::Ok();
}

Status DeviceJudge::State::UploadForReference(const Batch& batch, const DeviceJudgeInputs& device, ThreadPool& pool) {
  if (device.draw_seed) return Status::Ok();  // the sample pass wrote the rays
  const std::size_t count = batch.count;
  auto* rays = static_cast<double*>(Buffer(kRays).mapped());
  pool.ParallelFor((count + kUploadChunk - 1) / kUploadChunk, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t job = begin; job < end; ++job) {
      const std::size_t lo = job * kUploadChunk, n = std::min(kUploadChunk, count - lo);
      std::memcpy(rays + lo, batch.ray_x.data() + lo, n * sizeof(double));
      std::memcpy(rays + count + lo, batch.ray_y.data() + lo, n * sizeof(double));
      std::memcpy(rays + 2 * count + lo, batch.ray_z.data() + lo, n * sizeof(double));
    }
  });
  DB_RETURN_IF_ERROR(Buffer(kRays).FlushHostWrites());
  return Status::Ok();
}

// Points every binding at the bytes this batch uses.
void DeviceJudge::State::Bind(const DeviceRunBuffers& run, const Batch& batch) {
  const std::size_t count = batch.count, frames = batch.frames.size(), slot_samples = depth_slots * count;
  const auto copies = FusedCopies(run);
  const std::array<VkDeviceSize, kBindingCount> bytes = {
      layout_words() * sizeof(std::uint32_t),
      run.position_bytes,
      frames * 4 * sizeof(std::uint32_t),
      3 * count * sizeof(double),
      count * sizeof(std::uint32_t),
      frames * L::DB_JUDGE_FRAME_DEPTHS * sizeof(double),
      frames * L::DB_JUDGE_FRAME_WORDS * sizeof(std::uint32_t),
      count * sizeof(double),
      pipelines * count * sizeof(float),
      run.texel_bytes,
      5 * slot_samples * sizeof(double),
      slot_samples * sizeof(std::uint32_t),
      counts_bytes(),
      first_bytes(),
      maxima_bytes(),
      unwritten_bytes(),
      std::max<VkDeviceSize>(frames * depth_slots * 4 * sizeof(float), 16),
      std::max<VkDeviceSize>(frames * L::DB_JUDGE_FRAME_DRAWS * sizeof(double), 16),
      run.pixel_bytes,
      std::max<VkDeviceSize>(candidates_bytes(), 16),
      candidate_counts_bytes(),
      std::max<VkDeviceSize>(copies[0].second, 16),
      std::max<VkDeviceSize>(copies[1].second, 16),
      std::max<VkDeviceSize>(copies[2].second, 16),
      std::max<VkDeviceSize>(run.texel_status_bytes, 16)};
  std::array<VkDescriptorBufferInfo, kBindingCount> infos{};
  std::array<VkWriteDescriptorSet, kBindingCount> writes{};
  for (std::uint32_t b = 0; b < kBindingCount; ++b) {
    const VkBuffer backends = b == kPositions     ? run.positions
                              : b == kTexels      ? run.texels
                              : b == kPixels      ? run.pixels
                              : b == kTexelStatus ? run.texel_status
                                                  : VK_NULL_HANDLE;
    infos[b] = {backends != VK_NULL_HANDLE ? backends : Buffer(static_cast<Binding>(b)).handle(), 0, bytes[b]};
    writes[b].dstBinding = b;
    writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &infos[b];
  }
  pass->WriteDescriptors(writes, lane);
}

L::JudgePass DeviceJudge::State::PassConstants(const Batch& batch, const DeviceJudgeInputs& device,
                                               const DeviceRunBuffers& run) const {
  const std::uint64_t seed = device.draw_seed.value_or(0);  // (read by the sample pass alone)
  return L::JudgePass{.count = batch.count,
                      .lead = run.lead,
                      .slice_length = run.slice_length,
                      .first_offset = batch.first_offset,
                      .first_index_lo = static_cast<std::uint32_t>(batch.first_index),
                      .first_index_hi = static_cast<std::uint32_t>(batch.first_index >> 32),
                      .phase = 0,
                      .record_distances = record_distances ? 1u : 0u,
                      .cells = static_cast<std::uint32_t>(cell_count()),
                      .depth_slots = static_cast<std::uint32_t>(depth_slots),
                      .accumulators = static_cast<std::uint32_t>(accumulators()),
                      .production = production == ProductionModel::kExact    ? L::DB_JUDGE_PRODUCTION_EXACT
                                    : production == ProductionModel::kRaster ? L::DB_JUDGE_PRODUCTION_RASTER
                                                                             : L::DB_JUDGE_PRODUCTION_FLOAT32,
                      .seed_lo = static_cast<std::uint32_t>(seed),
                      .seed_hi = static_cast<std::uint32_t>(seed >> 32),
                      .row_order = static_cast<std::uint32_t>(row_order_at()),
                      .cell_conventions = static_cast<std::uint32_t>(cell_conventions_at())};
}

void DeviceJudge::State::RecordStore(VkCommandBuffer commands, L::JudgePass constants, bool draws,
                                     const DeviceRunBuffers& run) const {
  if (clock.count() > 0) clock.RecordReset(commands, Query(lane, 0), kMarks);
  RecordMark(commands, kStoreStart);
  // Everything queued before (the last batch's judge reading the
  // positions, texels, reference and maxima this batch rewrites, and its
  // copies) finishes first.
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                          VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
  const std::uint32_t slice_groups = (constants.slice_length + kWorkgroupSize - 1) / kWorkgroupSize;
  if (draws) {
    // The samples first: every later pass reads them.
    pass->Bind(commands, sample_pipeline.get(), VK_PIPELINE_BIND_POINT_COMPUTE, lane);
    pass->PushConstants(commands, &constants, sizeof(constants));
    vkCmdDispatch(commands, slice_groups, 1, 1);
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  }
  if (!fused.empty()) {
    // After the sample pass wrote the pixels; the fused pass reads the copies.
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    const std::array<VkBuffer, 3> from = {run.frame_params, run.depth_params, run.pixels};
    const auto copies = FusedCopies(run);
    for (std::size_t c = 0; c < copies.size(); ++c) {
      const VkBufferCopy region{0, 0, copies[c].second};
      vkCmdCopyBuffer(commands, from[c], Buffer(copies[c].first).handle(), 1, &region);
    }
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  }
  RecordMark(commands, kSampled);
  // Every slice whole, a row per pipeline, but where the backend's
  // rasterizer stores them; the pipelines' floats made first where the
  // device produces them.
  if (!rasterized()) {
    pass->Bind(commands, store_pipeline.get(), VK_PIPELINE_BIND_POINT_COMPUTE, lane);
    constants.phase = device_produces() ? 0 : 1;
    pass->PushConstants(commands, &constants, sizeof(constants));
    vkCmdDispatch(commands, slice_groups, static_cast<std::uint32_t>(pipelines), 1);
    // The reconstruction pass (the backend's, queued next) and the reference read them.
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  }
  RecordMark(commands, kStored);
}

void DeviceJudge::State::Record(VkCommandBuffer commands, L::JudgePass constants, bool encodings) const {
  RecordMark(commands, kJudgeStart);
  // This batch's maxima start at nothing: zero squares, no index, no
  // candidate for one.
  const VkDeviceSize half = maxima() * sizeof(std::uint64_t);
  vkCmdFillBuffer(commands, Buffer(kMaxima).handle(), 0, half, 0u);
  vkCmdFillBuffer(commands, Buffer(kMaxima).handle(), half, half, 0xffffffffu);
  vkCmdFillBuffer(commands, Buffer(kCandidateCounts).handle(), 0, VK_WHOLE_SIZE, 0u);
  const std::uint32_t groups = (constants.count + kWorkgroupSize - 1) / kWorkgroupSize;
  // The reference of every (depth slot, sample), a row per pipeline.
  pass->Bind(commands, reference_pipeline.get(), VK_PIPELINE_BIND_POINT_COMPUTE, lane);
  pass->PushConstants(commands, &constants, sizeof(constants));
  vkCmdDispatch(commands, groups, static_cast<std::uint32_t>(pipelines), 1);
  RecordMark(commands, kReferenced);
  // The fills, the reference, and the reconstruction pass's positions (an
  // earlier submission to the same queue), before the judge reads.
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  const std::uint32_t groups_per_row = (constants.count + judge_groups.samples - 1) / judge_groups.samples;
  // A dispatch of `pipeline` over `rows` accumulators of the row order
  // that starts at layout word `row_order`.
  const auto dispatch = [&](VkPipeline pipeline, std::size_t row_order, std::size_t rows) {
    if (rows == 0) return;
    pass->Bind(commands, pipeline, VK_PIPELINE_BIND_POINT_COMPUTE, lane);
    constants.row_order = static_cast<std::uint32_t>(row_order);
    pass->PushConstants(commands, &constants, sizeof(constants));
    vkCmdDispatch(commands, groups_per_row, static_cast<std::uint32_t>(rows), 1);
  };
  for (std::uint32_t phase = 0; phase < 2; ++phase) {
    constants.phase = phase;
    if (fused.empty()) {
      dispatch(judge_pipeline.get(), row_order_at(), cell_count() + (encodings ? depth_slots : 0));
    } else {
      // Each variant's cells in its own program; the depth slots' rows
      // (after the cells' in the row order) in judge.comp's.
      for (const FusedVariant& variant : fused) {
        dispatch(variant.pipeline.get(), fused_rows_at() + variant.first_row, variant.rows);
      }
      dispatch(judge_pipeline.get(), row_order_at() + cell_count(), encodings ? depth_slots : 0);
    }
    RecordMark(commands, phase == 0 ? kJudged : kMaximaFound);
    // Phase 1 reads the maxima and candidates phase 0 left; the copy below
    // reads both phases' maxima.
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
  }
  RecordReadback(commands, {{kMaxima, maxima_bytes()}, {kUnwritten, unwritten_bytes()}}, batch_readbacks[lane]);
}

// A batch's maxima join the accumulators' as the host judge's Record does:
// a larger square replaces the slot's maximum and index; an equal one
// keeps the earlier batch's, whose indices are smaller.
Status DeviceJudge::State::MergeMaxima(std::uint32_t from, std::span<CellAccumulator> cells,
                                       std::span<CellAccumulator> encodings) const {
  const VulkanBuffer& readback = batch_readbacks[from];
  DB_RETURN_IF_ERROR(readback.InvalidateForHostReads());
  const auto* words = static_cast<const std::uint64_t*>(readback.mapped());
  const auto* unwritten = reinterpret_cast<const std::uint32_t*>(words + 2 * maxima());
  for (std::size_t k = 0; k < cell_count(); ++k) {
    if (unwritten[k] == 0) continue;
    return UnwrittenOutputs(run_cells[k], std::to_string(unwritten[k]));
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

Status DeviceJudge::State::Finish(std::uint32_t which) {
  Pending& batch = pending[which];
  if (!batch.queued) return Status::Ok();
  batch.queued = false;
  const auto waiting = std::chrono::steady_clock::now();
  DB_RETURN_IF_ERROR(pass->Wait(JudgeSlot(which)));
  waited += std::chrono::duration<double>(std::chrono::steady_clock::now() - waiting).count();
  DB_RETURN_IF_ERROR(AddPassSeconds(which));
  DB_RETURN_IF_ERROR(MergeMaxima(which, batch.cells, batch.encodings));
  for (CellAccumulator& a : batch.cells) a.Count(batch.count);
  for (CellAccumulator& a : batch.encodings) a.Count(batch.count);
  return Status::Ok();
}

Status DeviceJudge::State::AddPassSeconds(std::uint32_t lane_of) {
  if (clock.count() == 0) return Status::Ok();
  DB_ASSIGN_OR_RETURN(const std::vector<std::uint64_t> stamps, clock.Read(Query(lane_of, 0), kMarks));
  // Pass k is the interval that ends at mark k; idle, the first, begins
  // where the batch before ended.
  if (last_end) pass_seconds[0] += clock.IntervalNs(*last_end, stamps[kStoreStart]) * 1e-9;
  for (std::uint32_t k = 1; k < kMarks; ++k) pass_seconds[k] += clock.IntervalNs(stamps[k - 1], stamps[k]) * 1e-9;
  last_end = stamps[kMaximaFound];
  return Status::Ok();
}

std::uint64_t DeviceJudge::MaxBatchSamples() const {
  const State& s = *state_;
  // Per sample: five doubles per depth slot (the reference), three (the ray).
  const std::uint64_t widest = sizeof(double) * std::max<std::uint64_t>(5 * s.depth_slots, 3);
  return std::max<std::uint64_t>(s.context->properties().limits.maxStorageBufferRange / widest, kWorkgroupSize);
}

Status DeviceJudge::Judge(const Batch& batch, const DeviceJudgeInputs& device, std::span<CellAccumulator> cells,
                          std::span<CellAccumulator> encodings, ThreadPool& pool) {
  State& s = *state_;
  DB_RETURN_IF_ERROR(s.CheckSizes(cells, encodings));
  if (batch.count == 0) return Status::Ok();
  const ValidationScope validation(*s.context);
  // This batch goes to the lane the batch before last used, whose work is
  // long done; the last batch's may still run on the device meanwhile.
  s.lane = static_cast<std::uint32_t>(s.batches % kLanes);
  Laps laps(s.host_steps);
  DB_RETURN_IF_ERROR(s.Finish(s.lane));
  laps.Lap(kFinishStep);
  // On the device's queue, in this order: the sample and storage passes,
  // which write what the backend's reconstruction reads beyond what the
  // host uploads to it (the texels, and the pixels where the device
  // draws); the reconstruction; the reference and judge passes, which
  // read its positions. The storage pass's inputs go up first, the
  // backend's next, the reference's while the first two passes run.
  DB_RETURN_IF_ERROR(s.UploadForStorage(batch, device, pool));
  laps.Lap(kUploadStep);
  // Fused, the last batch reads the backend's frame constants and pixels
  // until its storage submission has copied them.
  if (!s.fused.empty()) DB_RETURN_IF_ERROR(s.pass->Wait(StoreSlot(1 - s.lane)));
  laps.Lap(kFinishStep);
  DB_ASSIGN_OR_RETURN(const DeviceRunBuffers run, s.runs->Stage(batch, s.every_cell, &pool));
  for (const auto& [binding, bytes] : s.FusedCopies(run)) DB_RETURN_IF_ERROR(s.Grow(binding, bytes));
  s.Bind(run, batch);
  const L::JudgePass constants = s.PassConstants(batch, device, run);
  const bool draws = device.draw_seed.has_value();
  laps.Lap(kStageStep);
  DB_RETURN_IF_ERROR(s.pass->SubmitWithoutWaiting(
      [&](VkCommandBuffer commands) { s.RecordStore(commands, constants, draws, run); }, StoreSlot(s.lane)));
  // Fused, the judge's own programs reconstruct (from what Stage staged).
  if (s.fused.empty()) DB_RETURN_IF_ERROR(s.runs->QueueStaged());
  laps.Lap(kQueueStep);
  DB_RETURN_IF_ERROR(s.UploadForReference(batch, device, pool));
  laps.Lap(kUploadStep);
  // This batch joins the accumulators once the next one is queued (or at
  // Flush).
  DB_RETURN_IF_ERROR(s.pass->SubmitWithoutWaiting(
      [&](VkCommandBuffer commands) { s.Record(commands, constants, !encodings.empty()); }, JudgeSlot(s.lane)));
  laps.Lap(kQueueStep);
  s.pending[s.lane] = {
      .queued = true, .count = batch.count, .cells = cells, .encodings = encodings, .order = s.batches++};
  s.last_count = batch.count;
  s.last_run = run;
  DB_RETURN_IF_ERROR(s.Finish(1 - s.lane));
  laps.Lap(kFinishStep);
  return validation.Check("judging on the device");
}

double DeviceJudge::waited_seconds() const { return state_->waited; }

std::vector<std::pair<std::string, double>> DeviceJudge::host_seconds() const {
  std::vector<std::pair<std::string, double>> out;
  for (std::uint32_t k = 0; k < kHostSteps; ++k) out.emplace_back(kHostStepNames[k], state_->host_steps[k]);
  return out;
}

std::vector<std::pair<std::string, double>> DeviceJudge::pass_seconds() const {
  std::vector<std::pair<std::string, double>> out;
  if (state_->clock.count() == 0) return out;
  std::array<const char*, kMarks> names = state_->fused.empty() ? kPassNames : kFusedPassNames;
  // The raster form's depth, fetch and reconstruction passes, in one
  // submission between the judge's: its parts where the backend times
  // them, and what is left of the interval ("raster idle": the device
  // waiting for the submission, or between its parts).
  if (state_->rasterized()) names[kJudgeStart] = "raster";
  const std::vector<std::pair<std::string, double>> parts =
      state_->rasterized() ? state_->runs->part_seconds() : std::vector<std::pair<std::string, double>>{};
  for (std::uint32_t k = 0; k < kMarks; ++k) {
    if (k != kJudgeStart || parts.empty()) {
      out.emplace_back(names[k], state_->pass_seconds[k]);
      continue;
    }
    double rest = state_->pass_seconds[k];
    for (const auto& part : parts) rest -= part.second;
    out.insert(out.end(), parts.begin(), parts.end());
    out.emplace_back("raster idle", std::max(rest, 0.0));
  }
  return out;
}

Expected<ReferenceArrays> DeviceJudge::LastReference() const {
  State& s = *state_;
  DB_RETURN_IF_ERROR(s.FinishAll());
  const std::size_t slot_samples = s.depth_slots * s.last_count;
  const VkDeviceSize doubles = 5 * slot_samples * sizeof(double), words = slot_samples * sizeof(std::uint32_t);
  DB_ASSIGN_OR_RETURN(
      VulkanBuffer readback,
      s.context->CreateHostBuffer(doubles + words + 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT, HostAccess::kReadback));
  if (slot_samples > 0) {
    DB_RETURN_IF_ERROR(s.pass->Submit([&](VkCommandBuffer commands) {
      s.RecordReadback(commands, {{kReference, doubles}, {kReferenceInfo, words}}, readback);
    }));
  }
  DB_RETURN_IF_ERROR(readback.InvalidateForHostReads());
  const auto* values = static_cast<const double*>(readback.mapped());
  const auto* info = reinterpret_cast<const std::uint32_t*>(values + 5 * slot_samples);
  ReferenceArrays out;
  out.Resize(slot_samples);
  std::vector<double>* columns[] = {&out.true_depth, &out.denoted_depth, &out.inverse_distance_sq, &out.storage_square,
                                    &out.production_square};
  for (std::size_t c = 0; c < 5; ++c) std::copy_n(values + c * slot_samples, slot_samples, columns[c]->begin());
  for (std::size_t r = 0; r < slot_samples; ++r) {
    out.joint_band[r] = static_cast<std::uint8_t>(L::db_reference_info_joint_band(info[r]));
    out.status[r] = static_cast<ReferenceStatus>(L::db_reference_info_status(info[r]));
    out.stored_holdable[r] = L::db_reference_info_stored_holdable(info[r]) ? 1 : 0;
  }
  return out;
}

Expected<std::vector<float>> DeviceJudge::LastTexels() const {
  State& s = *state_;
  DB_RETURN_IF_ERROR(s.FinishAll());
  const std::size_t count = s.last_count, slots = count == 0 ? 0 : s.depth_slots;
  DB_ASSIGN_OR_RETURN(VulkanBuffer readback,
                      s.context->CreateHostBuffer(std::max<std::size_t>(slots * count * sizeof(float), 16),
                                                  VK_BUFFER_USAGE_TRANSFER_DST_BIT, HostAccess::kReadback));
  if (slots > 0) {
    DB_RETURN_IF_ERROR(s.pass->Submit([&](VkCommandBuffer commands) {
      std::vector<VkBufferCopy> regions;
      for (std::size_t slot = 0; slot < slots; ++slot) {
        regions.push_back({(slot * s.last_run.slice_length + s.last_run.lead) * sizeof(float),
                           slot * count * sizeof(float), count * sizeof(float)});
      }
      vkCmdCopyBuffer(commands, s.last_run.texels, readback.handle(), static_cast<std::uint32_t>(regions.size()),
                      regions.data());
      RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    }));
  }
  DB_RETURN_IF_ERROR(readback.InvalidateForHostReads());
  const auto* texels = static_cast<const float*>(readback.mapped());
  return std::vector<float>(texels, texels + slots * count);
}

Status DeviceJudge::Flush(std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings) {
  State& s = *state_;
  DB_RETURN_IF_ERROR(s.CheckSizes(cells, encodings));
  DB_RETURN_IF_ERROR(s.FinishAll());
  DB_RETURN_IF_ERROR(s.runs->FinishQueued());
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
    to.undrawn += tally[5];
  }
  return Status::Ok();
}

}  // namespace depthbench
