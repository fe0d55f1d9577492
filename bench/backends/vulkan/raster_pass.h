// RasterPass: the raster form of the Vulkan backend (PassKind::kRaster). A
// run records two passes into one command buffer, with dynamic rendering
// (the sweep has pass 1 drawn on its own first, Render, so that every
// backend reconstructs from the device's texels; Run then draws pass 2):
//
//   1. depth production, per depth slot: every sample's small triangle
//      (ShaderInputs::raster) drawn into the slot's atlas, a depth
//      attachment for the hardware formats, a G-buffer colour channel for
//      the linear and view-z ones, with an R8_UINT coverage attachment
//      beside it. The texels are copied back and compared with the batch's
//      codes (agreement());
//   2. reconstruction: (a) once per run, what the rasterizer interpolates
//      at each sample's pixel, from the frame's full-screen triangle (the
//      rays) and, where a volume_ray cell runs, the back faces of the
//      sample's light volume (its view-space position), captured as
//      float32 (shaders/raster/capture.frag); (b) per depth slot, one
//      triangle over the atlas whose fragments run the functions of the
//      slot's built-in cells (shaders/raster/raster_cells.glsl), and per
//      user's cell one whose fragments run its program
//      (shaders/raster/raster_pass.glsl or the HLSL pass around its
//      function), on the slot's texel and the captured attributes. The
//      geometry is drawn once per encoding (1) and once per run (2a), and
//      a texel is fetched once per slot (2b).
//
// Sample i of a batch is texel t = (g + i) mod the atlas's size, (t %
// kAtlasWidth, t / kAtlasWidth), of every atlas, g being the sweep's index
// of the batch's first sample, so that a sample's texel does not depend on
// the batch it is in. It is instance i of one draw per pass and slot or
// cell. Pass 1 moves its triangle by whole pixels so that its frame's
// pixel lands on that texel (shaders/raster/atlas_placement.glsl), and
// discards fragments off it; pass 2b covers the atlas. Pass 2a draws at
// the sample's real pixel, through its frame's own viewport and a
// one-pixel scissor there (a device's interpolation depends on the window
// position; shaders/raster/raster_common.glsl).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan.h>

#include "bench/backends/backend.h"
#include "bench/backends/vulkan/compute_pass.h"
#include "bench/backends/vulkan/timestamps.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/status.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/shader_inputs.h"

namespace depthbench {

// Ok when a device with `features` can draw the raster form of `cells`;
// otherwise Unavailable, naming the device and everything it lacks (and,
// for VK_EXT_depth_clip_control, the cells' conventions that need it).
Status CheckRasterFeatures(const RasterFeatures& features, std::span<const CellPlan> cells,
                           const std::string& device_name);

class RasterPass {
 public:
  // Texels per atlas row: a power of two, so that a sample's texel is a
  // shift and a mask away, and narrow enough that a small batch is a few
  // rows of lavapipe's 64-texel tiles.
  static constexpr std::uint32_t kAtlasWidth = 256;

  // Compiles the programs of `cells` from `shader_dir` with
  // `arithmetic_probes` applied to each (the text of every source goes to
  // `sources`) and builds their pipelines.
  static Expected<std::unique_ptr<RasterPass>> Create(std::shared_ptr<VulkanContext> context,
                                                      std::span<const CellPlan> cells,
                                                      const std::filesystem::path& shader_dir,
                                                      std::uint32_t arithmetic_probes,
                                                      std::vector<std::string>& sources);
  ~RasterPass();
  RasterPass(const RasterPass&) = delete;
  RasterPass& operator=(const RasterPass&) = delete;

  // Pass 1 alone, for every depth slot of the prepared cells
  // (Backend::RenderDepths): returns the texel bits and what a texel fetch
  // returns for them, laid out as ShaderInputs::codes (the batch's own for
  // a sample without geometry), valid until the next call. A Run on the
  // same batch then reads the atlases rendered here.
  Expected<RenderedDepths> Render(const ShaderInputs& batch);
  // Pass 2 for the prepared cells listed in `which` (count > 0, at least
  // one cell), after pass 1 in the same command buffer unless Render drew
  // this batch last. Returns their positions as the compute form lays
  // them out (cell k's component c of sample i at (k * 3 + c) * count + i),
  // in mapped memory valid until the next Run. Every position starts as
  // `unwritten_bits`; a sample with no geometry gets quiet NaNs (nothing
  // was drawn for it), so whatever else still holds `unwritten_bits` is a
  // sample the program did not write.
  Expected<const float*> Run(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                             std::uint32_t unwritten_bits);

  // A run whose outputs stay in device memory, for a judge there
  // (DeviceResidentRuns, through the backend): uploads `batch` and returns
  // the buffers the run writes: the positions of `which` (starting as
  // `unwritten_bits`), laid out as Run's, and per depth slot and sample the
  // fetched texel and its DB_RASTER_TEXEL_* status. QueueResident then
  // queues pass 1 for every depth slot, the fetch, and pass 2, and returns
  // at once. The batch's codes (the host's model) are kept:
  // FinishResident, or the next StageResident, waits for the run and
  // counts its texels into agreement().
  // `pool`, where given, copies and compares on its threads.
  Expected<DeviceRunBuffers> StageResident(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                           std::uint32_t unwritten_bits, ThreadPool* pool);
  Status QueueResident();
  Status FinishResident(ThreadPool* pool = nullptr);

  // The device seconds of each part of the resident runs finished since
  // Create, in the order a submission runs them (the depth passes, the
  // fetch, the attributes, the reconstruction, the NaNs of samples without
  // geometry); empty where the device cannot time its queue.
  std::vector<std::pair<std::string, double>> part_seconds() const;

  // Per depth slot, since Create: RasterAgreement (raster_model.h).
  const std::vector<RasterAgreement>& agreement() const { return agreement_; }
  // The texel bits pass 1 produced in the last Render or Run, laid out as
  // ShaderInputs::codes: the batch's own where it drew nothing (a sample
  // without geometry, a slot the run did not need). A resident run keeps
  // none.
  const std::vector<std::uint32_t>& texels() const { return texels_; }
  // The most samples the atlas holds.
  std::uint64_t MaxBatchSamples() const;

 private:
  struct Slot;  // what pass 1 draws for one depth slot
  // What recording a submission needs of its batch (ShapeOf): its samples,
  // where its first lies in its frame and in the atlas, and the atlas rows
  // its texels lie in.
  struct RunShape {
    std::uint32_t count = 0;
    std::uint32_t first_offset = 0;
    std::uint32_t first_texel = 0;  // the sweep's index of the first sample, modulo the atlas's texels
    std::uint32_t first_row = 0;
    std::uint32_t rows = 0;
    // Sample i's texel, row by row, in an atlas of `atlas_rows` rows
    // (shaders/raster/atlas.inc's texel_of).
    std::uint32_t TexelOf(std::uint32_t i, std::uint32_t atlas_rows) const {
      return (first_texel + i) % (kAtlasWidth * atlas_rows);
    }
    VkRect2D Area() const { return {{0, static_cast<std::int32_t>(first_row)}, {kAtlasWidth, rows}}; }
  };
  RunShape ShapeOf(const ShaderInputs& batch) const;
  // Rows of every atlas: as many as the device allows, up to kMostAtlasRows.
  std::uint32_t AtlasRows() const;
  // Per depth slot, whether a prepared cell reads it (it has an atlas):
  // what a whole pass 1 draws.
  std::vector<bool> EverySlot() const;
  // A resident run staged or queued: what recording it and then comparing
  // its texels with the host's model need.
  struct ResidentRun {
    RunShape shape;
    std::vector<std::uint32_t> which;
    std::uint32_t unwritten_bits = 0;
    std::vector<std::uint32_t> codes;   // the batch's, laid out as ShaderInputs::codes
    std::vector<std::uint8_t> geometry;  // per sample, 1 where the host gave it something to draw
    ThreadPool* pool = nullptr;          // where given, records pass 2a on its threads
  };
  // The parts of a submission, each timed apart (part_seconds).
  enum Part : std::uint32_t { kDepthPart, kFetchPart, kAttributesPart, kReconstructionPart, kNoGeometryPart, kRasterParts };
  struct Atlas {
    VulkanImage value;     // the depth attachment or the G-buffer channel
    VulkanImage coverage;  // R8_UINT: 1 where pass 1 drew
  };

  explicit RasterPass(std::shared_ptr<VulkanContext> context);
  VkDevice device() const { return context_->device(); }

  Status BuildPipelines(std::span<const CellPlan> cells, const std::filesystem::path& shader_dir,
                        std::uint32_t arithmetic_probes, std::vector<std::string>& sources);
  // `drawn`: per depth slot, whether the submission draws it (pass 1).
  Status CheckRun(const ShaderInputs& batch, const std::vector<bool>& drawn) const;
  // Into lane `lane`. `outputs`: where the positions and fetched texels go
  // (kReadback: the host reads them; kNone: a judge on the device does).
  // `pool`, where given, uploads on its threads.
  Status Stage(const ShaderInputs& batch, std::span<const std::uint32_t> which, const std::vector<bool>& drawn,
               HostAccess outputs, std::uint32_t lane, ThreadPool* pool = nullptr);
  Status EnsureAtlases();
  Status Upload(const ShaderInputs& batch, std::uint32_t lane, ThreadPool* pool);
  // Records a submission of lane `lane`. `drawn`: per depth slot, whether
  // pass 1 draws it and, where `fetch`, the fetch reads it; pass 2 draws
  // `which` (none: pass 1 alone).
  // `captures`: pass 2a's blocks recorded in secondary command buffers
  // (RecordCapturesInParallel), run in this order; none: recorded here.
  void Record(VkCommandBuffer commands, std::uint32_t lane, RunShape shape, std::span<const std::uint32_t> which,
              const std::vector<bool>& drawn, bool fetch, std::uint32_t unwritten_bits,
              std::span<const VkCommandBuffer> captures = {}) const;
  f32::RasterConstants PassTwoConstants(RunShape shape, std::size_t listed) const;
  // Whether pass 2a draws the full-screen triangles, and the light
  // volumes, for the cells `which`.
  std::array<bool, 2> CapturedPrimitives(std::span<const std::uint32_t> which) const;
  // Pass 2a: capture_blocks_[begin, end), a render pass instance each.
  void RecordCaptures(VkCommandBuffer commands, std::uint32_t lane, const f32::RasterConstants& constants,
                      std::array<bool, 2> captured, std::size_t begin, std::size_t end) const;
  // Pass 2a of `run`, staged in `lane`, recorded on the threads of its
  // pool into the lane's secondary command buffers, in block order; none
  // where it has no pool or too few blocks to share.
  Expected<std::vector<VkCommandBuffer>> RecordCapturesInParallel(std::uint32_t lane, const ResidentRun& run);
  void RecordProduction(VkCommandBuffer commands, std::uint32_t lane, RunShape shape, std::size_t slot) const;
  void RecordFetch(VkCommandBuffer commands, std::uint32_t lane, RunShape shape, const std::vector<bool>& drawn) const;
  // The descriptor set of `atlas` in `lane`.
  std::uint32_t SetOf(std::uint32_t lane, std::uint32_t atlas) const {
    return lane * static_cast<std::uint32_t>(std::max<std::size_t>(atlases_.size(), 1)) + atlas;
  }
  // Waits for the resident run queued in `lane`, if any, and counts its
  // texels (CompareTexels) and times its parts.
  Status FinishLane(std::uint32_t lane, ThreadPool* pool);
  void RecordDraws(VkCommandBuffer commands, RunShape shape, std::uint32_t vertices) const;
  // Pass 2a's draw order: a render pass instance over each block of the
  // window that holds samples' pixels, and its samples
  // [first, first + samples) of draw_order_ (OrderCaptures).
  struct CaptureBlock {
    VkRect2D area;
    std::uint32_t first;
    std::uint32_t samples;
  };
  void OrderCaptures(const ShaderInputs& batch, ThreadPool* pool);
  void RecordSampleDraws(VkCommandBuffer commands, const CaptureBlock& block, bool cubes) const;
  // Counts the texels pass 1 copied back into agreement_ against `codes`
  // (the host's model), for the samples `geometry` marks, and, where `keep`,
  // keeps them in texels_ and texel_drawn_ (a resident run's reader is the
  // device); each slot on a thread of `pool`, if given. Reads lane `lane`'s
  // readback.
  void CompareTexels(std::uint32_t lane, RunShape shape, std::span<const std::uint32_t> codes,
                     std::span<const std::uint8_t> geometry, const std::vector<bool>& drawn, bool keep,
                     ThreadPool* pool);

  std::shared_ptr<VulkanContext> context_;  // first: everything below belongs to its device
  std::vector<CellPlan> cells_;
  std::vector<Slot> slots_;
  // The descriptor sets of both passes, one per atlas: the batch's buffers,
  // the atlas (sampled by pass 2) and the positions.
  std::unique_ptr<ComputePass> pass_;
  DeviceObject<VkSampler> sampler_;
  std::array<DeviceObject<VkPipeline>, 2> capture_;  // pass 2a: the full-screen triangle, the light volume
  // Pass 2b of the users' variants, indexed by Variant; null where no cell uses it (the
  // built-in cells run in their slot's program, Slot::reconstruction).
  std::vector<DeviceObject<VkPipeline>> reconstruction_;
  DeviceObject<VkPipeline> fetch_;        // shaders/raster/fetch.comp
  DeviceObject<VkPipeline> no_geometry_;  // shaders/raster/no_geometry.comp

  std::vector<Atlas> atlases_;  // per depth slot the cells read (Slot::atlas), AtlasRows() rows each
  bool atlases_made_ = false;
  // What one submission reads and writes beyond the atlases. Resident
  // runs take the lanes in turn, so that the host stages a batch into one
  // while the device draws the batch before from the other; the other
  // runs use lane 0 once every resident run has finished.
  struct Lane {
    VulkanBuffer frames, depth_params, pixels, geometry, positions;
    VulkanBuffer draw_order;   // draw_order_, for pass 2a's vertex stage
    VulkanBuffer cell_slices;  // per prepared cell, its positions' slice in the run (kCellSlices)
    VulkanBuffer readback;  // pass 1's texels and coverage, for the host
    // Per (depth slot, sample): what a fetch returns, and its
    // DB_RASTER_TEXEL_* status (shaders/raster/fetch.comp).
    VulkanBuffer fetched_texels, texel_status;
    HostAccess outputs = HostAccess::kReadback;  // what positions and fetched_texels are now
    VulkanBuffer attributes;  // pass 2a's output: shaders/raster/capture.frag
    // Pass 2a recorded on a pool's threads: per thread a command pool
    // (command pools are not thread-safe) and its secondary command buffer.
    struct Recorder {
      DeviceObject<VkCommandPool> pool;
      VkCommandBuffer commands = VK_NULL_HANDLE;  // freed with the pool
    };
    std::vector<Recorder> recorders;
    std::optional<ResidentRun> queued;  // the resident run queued here and not yet finished
    std::optional<ResidentRun> finished;  // the last finished, whose storage the next reuses
    std::uint64_t order = 0;            // when it was queued, counted over the resident runs
  };
  static constexpr std::uint32_t kLanes = 2;
  std::array<Lane, kLanes> lanes_;
  std::uint64_t resident_runs_ = 0;  // queued since Create
  std::uint32_t staged_lane_ = 0;    // the lane of staged_resident_
  VulkanBuffer cube_indices_;  // kCubeIndices, for the light volumes
  // Pass 2a's, per primitive (OrderCaptures): the sample it draws, its
  // viewport and scissor; and the blocks.
  std::vector<std::uint32_t> draw_order_;
  std::vector<VkViewport> viewports_;
  std::vector<VkRect2D> scissors_;
  std::vector<CaptureBlock> capture_blocks_;
  std::vector<VkDeviceSize> texel_offsets_, coverage_offsets_;  // per depth slot, into readback_

  // The batch whose every depth slot the atlases hold (Render), if any.
  struct RenderedBatch {
    std::uint64_t first_index;
    std::uint32_t count;
  };
  std::optional<RenderedBatch> rendered_;
  std::optional<ResidentRun> staged_resident_;
  // Per lane, a timestamp before each part of a submission and one after
  // the last (Record); part_seconds_ sums a resident run's parts when it
  // finishes.
  TimestampQueries clock_;
  std::array<double, kRasterParts> part_seconds_{};
  std::vector<RasterAgreement> agreement_;
  std::vector<std::uint32_t> texels_;
  std::vector<float> fetched_;
  std::vector<std::uint8_t> texel_drawn_;  // RenderedDepths::drawn of the last Render
};

}  // namespace depthbench
