#include "bench/backends/vulkan/raster_pass.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "bench/backends/vulkan/arithmetic_probe.h"
#include "bench/backends/vulkan/graphics_pipeline.h"
#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/backends/vulkan/variant_program.h"
#include "bench/backends/vulkan/vulkan_formats.h"
#include "bench/pipeline/encode.h"

namespace depthbench {

struct RasterPass::Slot {
  Encoding encoding{};
  std::uint32_t convention_slot = 0;
  std::optional<std::uint32_t> atlas;  // none when no prepared cell reads the slot
  DeviceObject<VkPipeline> production;
  // Pass 2b of the built-in cells that read the slot, in one program
  // (shaders/raster/raster_cells.glsl), and their indices among the
  // prepared cells.
  DeviceObject<VkPipeline> reconstruction;
  std::vector<std::uint32_t> built_in_cells;
};

namespace {

// shaders/raster/atlas_placement.glsl's ATLAS_GUARD: the texels the atlas
// viewport reaches beyond the atlas on every side, so that a small
// triangle at the atlas's edge is not clipped.
constexpr std::uint32_t kAtlasGuard = 128;
// shaders/raster/raster_common.glsl's VIEWPORTS_PER_DRAW: pass 2a's
// samples a draw. Every device with multiViewport has at least 16
// viewports (the minimum of maxViewports).
constexpr std::uint32_t kViewportsPerDraw = 16;
// Pass 2a draws the samples block by block of the window, each block a
// render pass instance over it alone: lavapipe's work for a render pass
// grows with its area (2e5 full-screen triangles through render areas of
// 1024, 4096 and 8192 pixels square: 1.0, 6.5 and 22 s), and the samples'
// real pixels span whole frames (one area over the largest frame: 2.5 s;
// blocks of 64, 128, 256 and 512 pixels: 2.8, 1.5, 1.1 to 1.3 and 1.2 s).
constexpr std::uint32_t kCaptureBlock = 256;
// The fewest blocks worth a secondary command buffer of their own
// (RecordCapturesInParallel). Samples spread over frames of many sizes
// fill many blocks: batches of 3000 samples of the typical domain filled
// about 100 each, of 262144 samples all 39 of a 1e7-sample run on an H100
// took the parallel path.
constexpr std::size_t kBlocksPerRecorder = 8;
// raster_cells.glsl's NO_SLICE: a prepared cell the run does not list.
constexpr std::uint32_t kNoSlice = 0xffffffffu;
constexpr VkFormat kCoverageFormat = VK_FORMAT_R8_UINT;
constexpr std::uint32_t kTriangleVertices = 3;
// The light volume's twelve triangles as corners of its cube
// (shaders/raster/light_volume.vert), two a face, counter-clockwise seen
// from outside: with the y-flipping viewport that is the front face.
constexpr std::array<std::uint16_t, 36> kCubeIndices = {4, 6, 2, 4, 2, 0, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                                                        6, 7, 3, 6, 3, 2, 2, 3, 1, 2, 1, 0, 4, 5, 7, 4, 7, 6};
constexpr std::uint32_t kCubeCorners = 8;
// A pass 2a draw's cubes, kViewportsPerDraw of them: cube k's corners are
// vertices 8k to 8k + 7 (light_volume.vert).
std::vector<std::uint16_t> DrawOfCubes(std::uint32_t cubes) {
  std::vector<std::uint16_t> indices;
  indices.reserve(cubes * kCubeIndices.size());
  for (std::uint32_t k = 0; k < cubes; ++k) {
    for (const std::uint16_t corner : kCubeIndices)
      indices.push_back(static_cast<std::uint16_t>(k * kCubeCorners + corner));
  }
  return indices;
}

// The descriptor set both passes draw with (shaders/raster/): the batch's
// inputs first.
enum Binding : std::uint32_t {
  kFrames,
  kDepthParams,
  kPixels,
  kGeometry,
  kAtlases,
  kPositions,
  kAttributes,      // what pass 2a captures for pass 2b: kAttributesPerSample vec4s a sample
  kFetched,         // fetch.comp's outputs: per (depth slot, sample) the fetched value,
  kTexelStatus,     // and its DB_RASTER_TEXEL_* status,
  kCoverageCopies,  // from the copy of pass 1's coverage the host reads (Lane::readback)
  kDrawOrder,       // pass 2a: the sample each primitive draws (CaptureBlock)
  kCellSlices,      // pass 2b: per prepared cell, its slice of the positions in this run
  kBindingCount
};
// shaders/raster/atlas.inc's ATTRIBUTES_PER_SAMPLE.
constexpr VkDeviceSize kAttributesPerSample = 4;
constexpr std::size_t kInputBindings = kGeometry + 1;

// The bytes of the batch's inputs, binding by binding.
std::array<VkDeviceSize, kInputBindings> InputBytes(const ShaderInputs& batch) {
  const std::size_t frames = std::size_t{batch.FrameOf(batch.count - 1)} + 1;
  return {frames * sizeof(f32::FrameParams), frames * kHardwareConventionCount * sizeof(f32::DepthParams),
          std::size_t{batch.count} * sizeof(std::uint32_t), std::size_t{batch.count} * sizeof(f32::RasterSample)};
}
constexpr VkShaderStageFlags kDrawStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
// The draws, and the fetch that reads pass 1's texels back (fetch.comp).
constexpr VkShaderStageFlags kSetStages = kDrawStages | VK_SHADER_STAGE_COMPUTE_BIT;
constexpr std::uint32_t kFetchWorkgroup = 64;  // fetch.comp's and no_geometry.comp's local size

// gbuffer.frag's specialization constant VIEW_Z; capture.frag's and the
// reconstruction's LIGHT_VOLUME; capture.frag's COMPUTE_ATTRIBUTES.
constexpr std::uint32_t kViewZConstant = 0;
constexpr std::uint32_t kLightVolumeConstant = 0;
constexpr std::uint32_t kComputeAttributesConstant = 1;

// A light volume or not, and capture.frag's probe.
struct CaptureConstants {
  VkBool32 light_volume;
  VkBool32 compute_attributes;
};

bool ClipMinusOne(Convention convention) { return (Info(convention).bits & catalog::kGl) != 0; }
bool ReversedDepth(Convention convention) { return (Info(convention).bits & catalog::kRev) != 0; }

VkDeviceSize AlignedTo4(VkDeviceSize bytes) { return (bytes + 3) / 4 * 4; }

bool IsZero(const glm::vec4& v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f && v.w == 0.0f; }
// All zero: the host has nothing for the sample to draw.
bool HasGeometry(const f32::RasterSample& sample) {
  return !(IsZero(sample.triangle0) && IsZero(sample.triangle1) && IsZero(sample.triangle2));
}

// Per sample of `batch`, 1 where HasGeometry; on `pool`'s threads, if given.
std::vector<std::uint8_t> GeometryOf(const ShaderInputs& batch, ThreadPool* pool = nullptr) {
  std::vector<std::uint8_t> geometry(batch.count);
  const auto mark = [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t i = begin; i < end; ++i) geometry[i] = HasGeometry(batch.raster[i]) ? 1 : 0;
  };
  constexpr std::size_t kGrain = 16384;
  if (pool == nullptr) {
    mark(0, batch.count, 0);
  } else {
    pool->ParallelFor(batch.count, mark, kGrain);
  }
  return geometry;
}

VkRenderingAttachmentInfo ClearedAttachment(const VulkanImage& image, VkImageLayout layout, VkClearValue clear) {
  VkRenderingAttachmentInfo attachment{};
  attachment.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
  attachment.imageView = image.view.get();
  attachment.imageLayout = layout;
  attachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachment.clearValue = clear;
  return attachment;
}

// The atlas's rows. The atlas has a fixed size, and sample g of the sweep
// always lies at texel g mod its size (RunShape), so that a sample is
// rasterized at the same window position whatever batch it is in: a
// device's interpolation rounds differently elsewhere (on lavapipe, 0.2%
// of r32_sfloat texels changed between batches of 1024 and 4096 samples).
// Its 262144 texels hold the device judge's default batch.
constexpr std::uint32_t kMostAtlasRows = 1024;
// The one viewport of a batch's draws, `rows` atlas rows: powers of two
// wide and high, the atlas and kAtlasGuard texels around it, y up
// (shaders/raster/atlas_placement.glsl).
std::uint32_t ViewportHeight(std::uint32_t rows) { return std::bit_ceil(rows + 2 * kAtlasGuard); }
VkViewport AtlasViewport(std::uint32_t rows) {
  const auto height = static_cast<float>(ViewportHeight(rows));
  const auto guard = static_cast<float>(kAtlasGuard);
  return {-guard, height - guard, 2.0f * RasterPass::kAtlasWidth, -height, 0.0f, 1.0f};
}

// Ok when the device can use `format` for everything `needed` says.
Status CheckFormat(VkPhysicalDevice physical_device, VkFormat format, std::string_view name,
                   VkFormatFeatureFlags needed, const std::string& device_name) {
  VkFormatProperties properties{};
  vkGetPhysicalDeviceFormatProperties(physical_device, format, &properties);
  if ((properties.optimalTilingFeatures & needed) == needed) return Status::Ok();
  return Unavailable(fmt::format(
      "the raster form renders into {} and copies it back{}; Vulkan device '{}' cannot (format features {:#x} of "
      "{:#x})",
      name, (needed & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) != 0 ? " and samples it" : "", device_name,
      properties.optimalTilingFeatures & needed, needed));
}

}  // namespace

Status CheckRasterFeatures(const RasterFeatures& features, std::span<const CellPlan> cells,
                           const std::string& device_name) {
  std::vector<std::string> missing;
  const auto need = [&](bool has, std::string_view what) {
    if (!has) missing.emplace_back(what);
  };
  need(features.graphics_queue, "a queue that can both compute and draw");
  need(features.dynamic_rendering, "dynamicRendering (Vulkan 1.3)");
  need(features.multi_viewport, "multiViewport");
  need(features.viewport_index, "shaderOutputViewportIndex (Vulkan 1.2)");
  need(features.fragment_stores, "fragmentStoresAndAtomics");
  const bool volumes = std::any_of(cells.begin(), cells.end(),
                                   [](const CellPlan& plan) { return plan.cell.variant == Variant::kVolumeRay; });
  if (volumes) need(features.depth_clamp, "depthClamp (volume_ray draws its light volumes unclipped)");
  std::vector<std::string_view> gl_conventions;
  for (const CellPlan& plan : cells) {
    const Convention convention = plan.cell.convention;
    if (!Info(convention).hardware || !ClipMinusOne(convention)) continue;
    if (std::find(gl_conventions.begin(), gl_conventions.end(), Info(convention).name) == gl_conventions.end()) {
      gl_conventions.push_back(Info(convention).name);
    }
  }
  if (!gl_conventions.empty() && !features.depth_clip_control) {
    missing.push_back(fmt::format("VK_EXT_depth_clip_control (GL-style clip depth, for the conventions {})",
                                  fmt::join(gl_conventions, ", ")));
  }
  if (missing.empty()) return Status::Ok();
  return Unavailable(fmt::format("the raster form (--pipeline raster) needs what Vulkan device '{}' lacks: {}",
                                 device_name, fmt::join(missing, "; ")));
}

RasterPass::RasterPass(std::shared_ptr<VulkanContext> context) : context_(std::move(context)) {}
// The device may still run a lane's work: wait before its buffers and
// command pools go.
RasterPass::~RasterPass() {
  if (pass_ == nullptr) return;
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) (void)pass_->Wait(lane);
}

Expected<std::unique_ptr<RasterPass>> RasterPass::Create(std::shared_ptr<VulkanContext> context,
                                                         std::span<const CellPlan> cells,
                                                         const std::filesystem::path& shader_dir,
                                                         std::uint32_t arithmetic_probes,
                                                         std::vector<std::string>& sources) {
  if (context == nullptr) return InvalidArgument("the raster form needs a Vulkan context");
  const std::string& device_name = context->properties().name;
  DB_RETURN_IF_ERROR(CheckRasterFeatures(context->raster_features(), cells, device_name));
  std::unique_ptr<RasterPass> pass(new RasterPass(std::move(context)));
  pass->cells_.assign(cells.begin(), cells.end());

  std::uint32_t slot_count = 0;
  for (const CellPlan& plan : cells) slot_count = std::max(slot_count, plan.depth_slot + 1);
  pass->slots_.resize(slot_count);
  std::uint32_t atlases = 0;
  for (const CellPlan& plan : cells) {
    Slot& slot = pass->slots_[plan.depth_slot];
    if (slot.atlas) continue;
    slot.encoding = plan.cell.encoding();
    slot.convention_slot = plan.convention_slot;
    slot.atlas = atlases++;
    const Format format = slot.encoding.format;
    const VkFormatFeatureFlags use =
        VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT |
        (IsDepthFormat(format) ? VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT);
    DB_RETURN_IF_ERROR(CheckFormat(pass->context_->physical_device(), VulkanFormatOf(format), Info(format).vulkan_name,
                                   use, device_name));
  }
  DB_RETURN_IF_ERROR(CheckFormat(pass->context_->physical_device(), kCoverageFormat, "VK_FORMAT_R8_UINT",
                                 VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT,
                                 device_name));
  pass->atlases_.resize(atlases);
  pass->agreement_.assign(slot_count, RasterAgreement{});
  for (std::uint32_t s = 0; s < slot_count; ++s) pass->agreement_[s].encoding = pass->slots_[s].encoding;

  std::array<VkDescriptorSetLayoutBinding, kBindingCount> bindings{};
  for (std::uint32_t i = 0; i < kBindingCount; ++i) {
    bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kSetStages, nullptr};
  }
  bindings[kAtlases].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  // A set per atlas and lane (SetOf): a lane's sets differ in the atlas
  // alone, and a cell's draws bind its slot's. A command buffer per lane.
  DB_ASSIGN_OR_RETURN(pass->pass_, ComputePass::Create(pass->context_, bindings, sizeof(f32::RasterConstants),
                                                       kSetStages, std::max(atlases, 1u) * kLanes, kLanes));
  if (TimestampQueries::Supported(*pass->context_).ok()) {
    DB_ASSIGN_OR_RETURN(pass->clock_, TimestampQueries::Create(*pass->context_, kLanes * (kRasterParts + 1)));
  }
  DB_ASSIGN_OR_RETURN(pass->sampler_, pass->context_->CreateTexelSampler());
  const std::vector<std::uint16_t> cubes = DrawOfCubes(kViewportsPerDraw);
  const std::size_t cube_bytes = cubes.size() * sizeof(std::uint16_t);
  DB_RETURN_IF_ERROR(pass->context_->GrowHostBuffer(pass->cube_indices_, cube_bytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                                    HostAccess::kUpload));
  std::memcpy(pass->cube_indices_.mapped(), cubes.data(), cube_bytes);
  DB_RETURN_IF_ERROR(pass->cube_indices_.FlushHostWrites());
  DB_RETURN_IF_ERROR(pass->BuildPipelines(cells, shader_dir, arithmetic_probes, sources));
  return pass;
}

Status RasterPass::BuildPipelines(std::span<const CellPlan> cells, const std::filesystem::path& shader_dir,
                                  std::uint32_t arithmetic_probes, std::vector<std::string>& sources) {
  const auto module = [&](Expected<std::vector<std::uint32_t>> compiled,
                          const std::string& what) -> Expected<DeviceObject<VkShaderModule>> {
    if (!compiled.ok()) return compiled.status();
    DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> spirv, ApplyArithmeticProbes(*compiled, arithmetic_probes));
    return CreateShaderModule(device(), spirv, what);
  };
  const auto stage = [&](std::string_view file, ShaderStage kind) {
    const std::filesystem::path path = shader_dir / "raster" / file;
    return module(CompileShader(path, kind, &sources), path.string());
  };
  DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> triangle, stage("sample_triangle.vert", ShaderStage::kVertex));
  DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> coverage, stage("coverage.frag", ShaderStage::kFragment));
  DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> gbuffer, stage("gbuffer.frag", ShaderStage::kFragment));
  DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> full_screen, stage("full_screen.vert", ShaderStage::kVertex));
  DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> light_volume,
                      stage("light_volume.vert", ShaderStage::kVertex));
  DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> capture, stage("capture.frag", ShaderStage::kFragment));
  DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> cover, stage("atlas_cover.vert", ShaderStage::kVertex));
  const VkPipelineLayout layout = pass_->pipeline_layout();
  for (auto [file, pipeline] : {std::pair{"fetch.comp", &fetch_}, std::pair{"no_geometry.comp", &no_geometry_}}) {
    const std::filesystem::path path = shader_dir / "raster" / file;
    DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> spirv, CompileShader(path, ShaderStage::kCompute, &sources));
    DB_ASSIGN_OR_RETURN(*pipeline, pass_->CreatePipeline(spirv, VkSpecializationInfo{}, path.string()));
  }

  for (Slot& slot : slots_) {
    if (!slot.atlas) continue;
    const Format format = slot.encoding.format;
    const VkBool32 view_z = Info(format).stores == DepthInput::kViewZ ? VK_TRUE : VK_FALSE;
    const VkSpecializationMapEntry entry{kViewZConstant, 0, sizeof(VkBool32)};
    const VkSpecializationInfo constants{1, &entry, sizeof(view_z), &view_z};
    DrawState state;
    state.vertex = triangle.get();
    state.colors = {kCoverageFormat};
    if (IsDepthFormat(format)) {
      state.fragment = coverage.get();
      state.depth = VulkanFormatOf(format);
      state.clip_minus_one = ClipMinusOne(slot.encoding.convention);
    } else {
      state.fragment = gbuffer.get();
      state.fragment_constants = &constants;
      state.colors.push_back(VulkanFormatOf(format));
    }
    DB_ASSIGN_OR_RETURN(slot.production,
                        CreateGraphicsPipeline(device(), layout, state,
                                               fmt::format("the raster form's {}/{} depth pass",
                                                           Info(slot.encoding.convention).name, Info(format).name)));
  }

  // Pass 2a: the full-screen triangle's rays, and the light volume's
  // position where a volume_ray cell reads it. Pass 2b's programs take the
  // first constant alone.
  const std::array<VkSpecializationMapEntry, 2> capture_entries = {{
      {kLightVolumeConstant, offsetof(CaptureConstants, light_volume), sizeof(VkBool32)},
      {kComputeAttributesConstant, offsetof(CaptureConstants, compute_attributes), sizeof(VkBool32)},
  }};
  const VkBool32 compute_attributes = (arithmetic_probes & kComputeAttributes) != 0 ? VK_TRUE : VK_FALSE;
  const std::array<CaptureConstants, 2> capture_values = {{{VK_FALSE, compute_attributes},
                                                           {VK_TRUE, compute_attributes}}};
  std::array<VkSpecializationInfo, 2> capture_constants{}, light_volume_constants{};
  for (std::size_t k = 0; k < capture_constants.size(); ++k) {
    capture_constants[k] = {2, capture_entries.data(), sizeof(CaptureConstants), &capture_values[k]};
    light_volume_constants[k] = {1, capture_entries.data(), sizeof(CaptureConstants), &capture_values[k]};
  }
  for (std::size_t k = 0; k < capture_.size(); ++k) {
    DrawState state;
    state.light_volume = k == 1;
    state.viewports = kViewportsPerDraw;
    state.vertex = state.light_volume ? light_volume.get() : full_screen.get();
    state.fragment = capture.get();
    state.fragment_constants = &capture_constants[k];
    DB_ASSIGN_OR_RETURN(capture_[k], CreateGraphicsPipeline(device(), layout, state,
                                                            state.light_volume ? "the raster form's light volumes"
                                                                               : "the raster form's full-screen rays"));
  }

  // Pass 2b: one program per depth slot for its built-in cells, and one
  // per user's variant, each over the whole atlas.
  for (std::uint32_t index = 0; index < cells.size(); ++index) {
    const CellPlan& plan = cells[index];
    if (plan.cell.variant_info().user == nullptr) slots_[plan.depth_slot].built_in_cells.push_back(index);
  }
  for (Slot& slot : slots_) {
    if (slot.built_in_cells.empty()) continue;
    std::vector<RasterCell> programs;
    for (const std::uint32_t index : slot.built_in_cells) {
      const Variant variant = cells[index].cell.variant;
      programs.push_back({&cells[index].cell.variant_info(), index, variant == Variant::kVolumeRay});
    }
    DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> fragment,
                        module(CompileRasterCells(programs, shader_dir, &sources),
                               fmt::format("the raster program of {}/{}", Info(slot.encoding.convention).name,
                                           Info(slot.encoding.format).name)));
    DrawState state;
    state.vertex = cover.get();
    state.fragment = fragment.get();
    DB_ASSIGN_OR_RETURN(slot.reconstruction, CreateGraphicsPipeline(device(), layout, state, "the raster program"));
  }
  reconstruction_.clear();
  reconstruction_.resize(kMostVariants);
  for (const CellPlan& plan : cells) {
    if (plan.cell.variant_info().user == nullptr) continue;
    const Variant variant = plan.cell.variant;
    DeviceObject<VkPipeline>& pipeline = reconstruction_[static_cast<std::size_t>(variant)];
    if (pipeline.get() != VK_NULL_HANDLE) continue;
    const std::string name = VariantProgramName(plan.cell.variant_info(), VariantPass::kRaster, shader_dir);
    DB_ASSIGN_OR_RETURN(
        const DeviceObject<VkShaderModule> fragment,
        module(CompileVariant(plan.cell.variant_info(), VariantPass::kRaster, shader_dir, &sources), name));
    DrawState state;
    state.vertex = cover.get();
    state.fragment = fragment.get();
    state.fragment_constants = &light_volume_constants[variant == Variant::kVolumeRay ? 1 : 0];
    DB_ASSIGN_OR_RETURN(pipeline, CreateGraphicsPipeline(device(), layout, state, name));
  }
  return Status::Ok();
}

std::uint32_t RasterPass::AtlasRows() const {
  const VkPhysicalDeviceLimits& limits = context_->properties().limits;
  // The atlas viewport is a power of two high, the rows and their guard.
  const std::uint32_t viewport_rows = std::bit_floor(limits.maxViewportDimensions[1]) - 2 * kAtlasGuard;
  return std::min({limits.maxImageDimension2D, limits.maxFramebufferHeight, viewport_rows, kMostAtlasRows});
}

std::vector<bool> RasterPass::EverySlot() const {
  std::vector<bool> drawn(slots_.size());
  for (std::size_t s = 0; s < slots_.size(); ++s) drawn[s] = slots_[s].atlas.has_value();
  return drawn;
}

std::uint64_t RasterPass::MaxBatchSamples() const { return std::uint64_t{kAtlasWidth} * AtlasRows(); }

RasterPass::RunShape RasterPass::ShapeOf(const ShaderInputs& batch) const {
  const std::uint32_t texels = kAtlasWidth * AtlasRows();
  RunShape shape{.count = batch.count,
                 .first_offset = batch.first_offset,
                 .first_texel = static_cast<std::uint32_t>(batch.first_index % texels)};
  // The rows the batch's texels lie in; all of them where they wrap round.
  const std::uint32_t last = shape.first_texel + std::max(batch.count, 1u) - 1;
  const bool wraps = last >= texels;
  shape.first_row = wraps ? 0 : shape.first_texel / kAtlasWidth;
  shape.rows = wraps ? AtlasRows() : last / kAtlasWidth - shape.first_row + 1;
  return shape;
}

Status RasterPass::CheckRun(const ShaderInputs& batch, const std::vector<bool>& drawn) const {
  if (batch.raster.size() < batch.count) {
    return InvalidArgument(fmt::format(
        "the raster form draws the batch's geometry, and a batch of {} samples has it for {}: its domain's "
        "production must be the raster pipeline's (--pipeline raster)",
        batch.count, batch.raster.size()));
  }
  for (std::size_t slot = 0; slot < drawn.size(); ++slot) {
    const std::size_t codes_needed = (slot + 1) * batch.count;
    if (drawn[slot] && batch.codes.size() < codes_needed) {
      return InvalidArgument(fmt::format("depth slot {} is compared with {} texel codes; the batch has {}", slot,
                                         codes_needed, batch.codes.size()));
    }
  }
  const std::uint64_t rows = AtlasRows();
  if (std::uint64_t{batch.count} > MaxBatchSamples()) {
    return InvalidArgument(fmt::format("a batch of {} samples needs more than the atlas's {} rows of {} texels",
                                       batch.count, rows, kAtlasWidth));
  }
  // Pass 2a draws through each frame's own viewport, into a window as large.
  const VkPhysicalDeviceLimits& limits = context_->properties().limits;
  for (const f32::FrameParams& frame : batch.frame_params) {
    const float width = frame.resolution.x;
    const float height = frame.resolution.y;
    const float most_width = static_cast<float>(std::min(limits.maxViewportDimensions[0], limits.maxFramebufferWidth));
    const float most_height =
        static_cast<float>(std::min(limits.maxViewportDimensions[1], limits.maxFramebufferHeight));
    if (width > most_width || height > most_height || height > limits.viewportBoundsRange[1]) {
      return InvalidArgument(fmt::format(
          "a {}x{} frame is larger than the device's viewports and framebuffers (at most {}x{}, within [{}, {}])",
          width, height, most_width, most_height, limits.viewportBoundsRange[0], limits.viewportBoundsRange[1]));
    }
  }
  return Status::Ok();
}

// The atlases are made once, whole (kMostAtlasRows); each is made
// readable at once, so that pass 2's descriptors are valid for every atlas
// whether or not the run draws it.
Status RasterPass::EnsureAtlases() {
  if (atlases_made_) return Status::Ok();
  const std::uint32_t rows = AtlasRows();
  for (const Slot& slot : slots_) {
    if (!slot.atlas) continue;
    const Format format = slot.encoding.format;
    const bool depth = IsDepthFormat(format);
    Atlas& atlas = atlases_[*slot.atlas];
    const VkImageUsageFlags use = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                  (depth ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT
                                         : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
    DB_ASSIGN_OR_RETURN(atlas.value,
                        context_->CreateImage(VulkanFormatOf(format), {kAtlasWidth, rows}, use,
                                              depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT));
    DB_ASSIGN_OR_RETURN(atlas.coverage,
                        context_->CreateImage(kCoverageFormat, {kAtlasWidth, rows},
                                              VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                              VK_IMAGE_ASPECT_COLOR_BIT));
  }
  DB_RETURN_IF_ERROR(pass_->Submit([&](VkCommandBuffer commands) {
    for (const Atlas& atlas : atlases_) {
      RecordImageBarrier(commands, atlas.value, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                         VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                         VK_ACCESS_SHADER_READ_BIT);
    }
  }));
  atlases_made_ = true;
  return Status::Ok();
}

Status RasterPass::Upload(const ShaderInputs& batch, std::uint32_t lane, ThreadPool* pool) {
  Lane& to = lanes_[lane];
  const std::array<VkDeviceSize, kInputBindings> bytes = InputBytes(batch);
  const std::array<const void*, kInputBindings> data = {batch.frame_params.data(), batch.depth_params.data(),
                                                        batch.pixels.data(), batch.raster.data()};
  const std::array<VulkanBuffer*, kInputBindings> buffers = {&to.frames, &to.depth_params, &to.pixels, &to.geometry};
  for (std::size_t binding = 0; binding < kInputBindings; ++binding) {
    VulkanBuffer& buffer = *buffers[binding];
    DB_RETURN_IF_ERROR(context_->GrowHostBuffer(buffer, bytes[binding], VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                                HostAccess::kUpload));
    if (pool != nullptr) {
      pool->Copy(buffer.mapped(), data[binding], bytes[binding]);
    } else {
      std::memcpy(buffer.mapped(), data[binding], bytes[binding]);
    }
    DB_RETURN_IF_ERROR(buffer.FlushHostWrites());
  }

  DB_RETURN_IF_ERROR(context_->GrowHostBuffer(to.draw_order,
                                              std::max<std::size_t>(draw_order_.size(), 1) * sizeof(std::uint32_t),
                                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, HostAccess::kUpload));
  std::memcpy(to.draw_order.mapped(), draw_order_.data(), draw_order_.size() * sizeof(std::uint32_t));
  DB_RETURN_IF_ERROR(to.draw_order.FlushHostWrites());

  // Pass 1's texels and coverage, slot after slot, each laid out as its
  // whole atlas and at a multiple of 4 bytes, as copies of depth aspects
  // require.
  texel_offsets_.assign(slots_.size(), 0);
  coverage_offsets_.assign(slots_.size(), 0);
  VkDeviceSize readback_bytes = 0;
  const VkDeviceSize texels = MaxBatchSamples();
  for (std::size_t s = 0; s < slots_.size(); ++s) {
    if (!slots_[s].atlas) continue;
    texel_offsets_[s] = readback_bytes;
    readback_bytes += AlignedTo4(texels * TexelBytes(slots_[s].encoding.format));
    coverage_offsets_[s] = readback_bytes;
    readback_bytes += AlignedTo4(texels);
  }
  DB_RETURN_IF_ERROR(context_->GrowHostBuffer(to.readback, readback_bytes,
                                              VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                              HostAccess::kReadback));
  return Status::Ok();
}

// Everything a submission of either pass needs: the atlases, the batch's
// buffers, room for the positions of `which`, the descriptors and the
// samples' viewports.
Status RasterPass::Stage(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                         const std::vector<bool>& drawn, HostAccess outputs, std::uint32_t lane, ThreadPool* pool) {
  DB_RETURN_IF_ERROR(CheckRun(batch, drawn));
  const std::uint32_t count = batch.count;
  DB_RETURN_IF_ERROR(EnsureAtlases());
  OrderCaptures(batch, pool);
  DB_RETURN_IF_ERROR(Upload(batch, lane, pool));
  Lane& to = lanes_[lane];
  // The outputs go where their reader is: a buffer the host maps, or
  // device memory alone.
  if (outputs != to.outputs) {
    to.positions = VulkanBuffer();
    to.fetched_texels = VulkanBuffer();
    to.outputs = outputs;
  }
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const VkDeviceSize position_bytes = std::max<VkDeviceSize>(VkDeviceSize{3} * count * which.size(), 1) * sizeof(float);
  const VkDeviceSize texel_bytes = VkDeviceSize{count} * slots_.size() * sizeof(float);
  DB_RETURN_IF_ERROR(context_->GrowHostBuffer(to.positions, position_bytes, storage, to.outputs));
  DB_RETURN_IF_ERROR(context_->GrowHostBuffer(to.fetched_texels, texel_bytes, storage, to.outputs));
  DB_RETURN_IF_ERROR(context_->GrowHostBuffer(to.texel_status, texel_bytes, storage, HostAccess::kNone));
  const VkDeviceSize attribute_bytes = kAttributesPerSample * count * sizeof(glm::vec4);
  // Where each listed cell's positions go (raster_cells.glsl's cell_slices).
  std::vector<std::uint32_t> slices(std::max<std::size_t>(cells_.size(), 1), kNoSlice);
  for (std::size_t k = 0; k < which.size(); ++k) slices[which[k]] = static_cast<std::uint32_t>(k);
  DB_RETURN_IF_ERROR(context_->GrowHostBuffer(to.cell_slices, slices.size() * sizeof(std::uint32_t),
                                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, HostAccess::kUpload));
  std::memcpy(to.cell_slices.mapped(), slices.data(), slices.size() * sizeof(std::uint32_t));
  DB_RETURN_IF_ERROR(to.cell_slices.FlushHostWrites());
  DB_RETURN_IF_ERROR(context_->GrowHostBuffer(to.attributes, attribute_bytes,
                                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                              HostAccess::kNone));

  // Points the sets at this run's buffers (they may have been reallocated)
  // and each at its atlas.
  const std::array<VkDeviceSize, kInputBindings> input_bytes = InputBytes(batch);
  const std::array<VkDescriptorBufferInfo, kBindingCount> infos = {{
      {to.frames.handle(), 0, input_bytes[kFrames]},
      {to.depth_params.handle(), 0, input_bytes[kDepthParams]},
      {to.pixels.handle(), 0, input_bytes[kPixels]},
      {to.geometry.handle(), 0, input_bytes[kGeometry]},
      {},
      {to.positions.handle(), 0, position_bytes},
      {to.attributes.handle(), 0, attribute_bytes},
      {to.fetched_texels.handle(), 0, texel_bytes},
      {to.texel_status.handle(), 0, texel_bytes},
      {to.readback.handle(), 0, VK_WHOLE_SIZE},
      {to.draw_order.handle(), 0, VK_WHOLE_SIZE},
      {to.cell_slices.handle(), 0, VK_WHOLE_SIZE},
  }};
  for (std::uint32_t atlas = 0; atlas < atlases_.size(); ++atlas) {
    const VkDescriptorImageInfo image{sampler_.get(), atlases_[atlas].value.view.get(),
                                      VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    std::array<VkWriteDescriptorSet, kBindingCount> writes{};
    for (std::uint32_t binding = 0; binding < kBindingCount; ++binding) {
      writes[binding].dstBinding = binding;
      writes[binding].descriptorType =
          binding == kAtlases ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[binding].pBufferInfo = &infos[binding];
    }
    writes[kAtlases].pBufferInfo = nullptr;
    writes[kAtlases].pImageInfo = &image;
    pass_->WriteDescriptors(writes, SetOf(lane, atlas));
  }

  return Status::Ok();
}

// Pass 2a: primitive i of its draws draws sample draw_order_[i], through
// its frame's viewport as the engine sets it, and a scissor that keeps the
// sample's pixel alone. The samples go block by block of the window (kCaptureBlock),
// each block's padded to whole draws by repeating its last sample (which
// then writes the same attributes again). The blocks' primitives are
// written on `pool`'s threads, if given.
void RasterPass::OrderCaptures(const ShaderInputs& batch, ThreadPool* pool) {
  const std::uint32_t count = batch.count;
  const auto x_of = [&](std::uint32_t i) { return batch.pixels[i] & 0xffffu; };
  const auto y_of = [&](std::uint32_t i) { return batch.pixels[i] >> 16; };
  const std::uint32_t columns = 0x10000u / kCaptureBlock;
  const auto block_of = [&](std::uint32_t i) { return y_of(i) / kCaptureBlock * columns + x_of(i) / kCaptureBlock; };
  // A counting sort by block, stable, so that a block's samples keep their order.
  std::vector<std::uint32_t> starts(columns * columns + 1, 0);
  for (std::uint32_t i = 0; i < count; ++i) ++starts[block_of(i) + 1];
  for (std::size_t b = 1; b < starts.size(); ++b) starts[b] += starts[b - 1];
  std::vector<std::uint32_t> sorted(count);
  std::vector<std::uint32_t> next(starts.begin(), starts.end() - 1);
  for (std::uint32_t i = 0; i < count; ++i) sorted[next[block_of(i)]++] = i;

  capture_blocks_.clear();
  std::vector<std::uint32_t> sorted_first;  // of each capture block, in `sorted`
  std::uint32_t primitives = 0;
  for (std::uint32_t b = 0; b + 1 < starts.size(); ++b) {
    if (starts[b] == starts[b + 1]) continue;
    const std::uint32_t samples = starts[b + 1] - starts[b];
    const std::uint32_t padded = (samples + kViewportsPerDraw - 1) / kViewportsPerDraw * kViewportsPerDraw;
    const VkOffset2D corner = {static_cast<std::int32_t>(b % columns * kCaptureBlock),
                               static_cast<std::int32_t>(b / columns * kCaptureBlock)};
    capture_blocks_.push_back({{corner, {kCaptureBlock, kCaptureBlock}}, primitives, padded});
    sorted_first.push_back(starts[b]);
    primitives += padded;
  }
  draw_order_.resize(primitives);
  viewports_.resize(primitives);
  scissors_.resize(primitives);
  const auto write = [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t c = begin; c < end; ++c) {
      const CaptureBlock& block = capture_blocks_[c];
      const std::uint32_t samples = (c + 1 < capture_blocks_.size() ? sorted_first[c + 1] : count) - sorted_first[c];
      for (std::uint32_t k = 0; k < block.samples; ++k) {
        const std::uint32_t sample = sorted[sorted_first[c] + std::min(k, samples - 1)];
        const glm::vec4& resolution = batch.frame_params[batch.FrameOf(sample)].resolution;
        const std::size_t at = std::size_t{block.first} + k;
        draw_order_[at] = sample;
        // Negative height: y up in NDC, pixel row 0 at the top, as the frames' uv.
        viewports_[at] = {0.0f, resolution.y, resolution.x, -resolution.y, 0.0f, 1.0f};
        scissors_[at] = {{static_cast<std::int32_t>(x_of(sample)), static_cast<std::int32_t>(y_of(sample))}, {1, 1}};
      }
    }
  };
  // A thread's share is worth it from a few dozen blocks (a few thousand samples).
  constexpr std::size_t kBlocksPerShare = 32;
  if (pool == nullptr) {
    write(0, capture_blocks_.size(), 0);
  } else {
    pool->ParallelFor(capture_blocks_.size(), write, kBlocksPerShare);
  }
}

Expected<RenderedDepths> RasterPass::Render(const ShaderInputs& batch) {
  DB_RETURN_IF_ERROR(FinishResident());
  staged_resident_.reset();
  const std::vector<bool> drawn = EverySlot();
  rendered_.reset();
  DB_RETURN_IF_ERROR(Stage(batch, {}, drawn, HostAccess::kReadback, 0));
  const RunShape shape = ShapeOf(batch);
  DB_RETURN_IF_ERROR(pass_->Submit([&](VkCommandBuffer commands) { Record(commands, 0, shape, {}, drawn, true, 0); }));
  const Lane& lane = lanes_[0];
  DB_RETURN_IF_ERROR(lane.readback.InvalidateForHostReads());
  DB_RETURN_IF_ERROR(lane.fetched_texels.InvalidateForHostReads());
  const std::vector<std::uint8_t> geometry = GeometryOf(batch);
  CompareTexels(0, shape, batch.codes, geometry, drawn, /*keep=*/true, nullptr);
  // The batch's own fetched value where nothing was drawn, as for the codes.
  const std::size_t count = batch.count;
  fetched_.assign(batch.depths.begin(), batch.depths.begin() + static_cast<std::ptrdiff_t>(slots_.size() * count));
  const auto* device_fetched = static_cast<const float*>(lane.fetched_texels.mapped());
  for (std::size_t s = 0; s < slots_.size(); ++s) {
    if (!drawn[s]) continue;
    for (std::size_t i = 0; i < count; ++i) {
      if (geometry[i] != 0) fetched_[s * count + i] = device_fetched[s * count + i];
    }
  }
  rendered_ = RenderedBatch{batch.first_index, batch.count};
  return RenderedDepths{texels_, fetched_, texel_drawn_};
}

Expected<const float*> RasterPass::Run(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                       std::uint32_t unwritten_bits) {
  DB_RETURN_IF_ERROR(FinishResident());
  staged_resident_.reset();
  // Pass 1 again only where Render did not just draw this batch.
  const bool rendered = rendered_ && rendered_->first_index == batch.first_index && rendered_->count == batch.count;
  std::vector<bool> drawn(slots_.size(), false);
  if (!rendered) {
    for (const std::uint32_t index : which) drawn[cells_[index].depth_slot] = true;
  }
  DB_RETURN_IF_ERROR(Stage(batch, which, drawn, HostAccess::kReadback, 0));
  const RunShape shape = ShapeOf(batch);
  DB_RETURN_IF_ERROR(pass_->Submit(
      [&](VkCommandBuffer commands) { Record(commands, 0, shape, which, drawn, false, unwritten_bits); }));
  const Lane& lane = lanes_[0];
  DB_RETURN_IF_ERROR(lane.positions.InvalidateForHostReads());
  if (!rendered) {
    DB_RETURN_IF_ERROR(lane.readback.InvalidateForHostReads());
    CompareTexels(0, shape, batch.codes, GeometryOf(batch), drawn, /*keep=*/true, nullptr);
    // Only some slots may have been drawn: none of the atlases holds a whole render now.
    rendered_.reset();
  }
  return static_cast<const float*>(lane.positions.mapped());
}

Expected<DeviceRunBuffers> RasterPass::StageResident(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                                     std::uint32_t unwritten_bits, ThreadPool* pool) {
  // The lane the run before last used: the device may still draw the last.
  const auto lane = static_cast<std::uint32_t>(resident_runs_ % kLanes);
  DB_RETURN_IF_ERROR(FinishLane(lane, pool));
  rendered_.reset();
  staged_resident_.reset();
  const std::vector<bool> drawn = EverySlot();
  DB_RETURN_IF_ERROR(Stage(batch, which, drawn, HostAccess::kNone, lane, pool));
  staged_lane_ = lane;
  const Lane& to = lanes_[lane];
  const std::uint32_t count = batch.count;
  // The storage of the lane's last run, reused: 4 bytes a sample and depth
  // slot, which a fresh vector would have the system zero and map page by
  // page every batch.
  staged_resident_ = std::move(lanes_[lane].finished);
  lanes_[lane].finished.reset();
  if (!staged_resident_) staged_resident_ = ResidentRun{};
  staged_resident_->shape = ShapeOf(batch);
  staged_resident_->which.assign(which.begin(), which.end());
  staged_resident_->unwritten_bits = unwritten_bits;
  staged_resident_->geometry = GeometryOf(batch, pool);
  staged_resident_->pool = pool;
  std::vector<std::uint32_t>& codes = staged_resident_->codes;
  codes.resize(std::size_t{count} * slots_.size());
  if (pool != nullptr) {
    pool->Copy(codes.data(), batch.codes.data(), codes.size() * sizeof(std::uint32_t));
  } else {
    std::copy_n(batch.codes.begin(), codes.size(), codes.begin());
  }
  const VkDeviceSize texel_bytes = VkDeviceSize{count} * slots_.size() * sizeof(float);
  DeviceRunBuffers buffers;
  buffers.positions = to.positions.handle();
  buffers.position_bytes = VkDeviceSize{3} * count * which.size() * sizeof(float);
  buffers.lead = 0;
  buffers.slice_length = count;
  buffers.texels = to.fetched_texels.handle();
  buffers.texel_bytes = texel_bytes;
  buffers.pixels = to.pixels.handle();
  buffers.pixel_bytes = VkDeviceSize{count} * sizeof(std::uint32_t);
  buffers.frame_params = to.frames.handle();
  buffers.frame_param_bytes = batch.frame_params.size() * sizeof(f32::FrameParams);
  buffers.depth_params = to.depth_params.handle();
  buffers.depth_param_bytes = batch.depth_params.size() * sizeof(f32::DepthParams);
  buffers.texel_status = to.texel_status.handle();
  buffers.texel_status_bytes = texel_bytes;
  return buffers;
}

Status RasterPass::QueueResident() {
  if (!staged_resident_) return Internal("no resident raster run staged");
  ResidentRun& run = *staged_resident_;
  const std::vector<bool> drawn = EverySlot();
  const std::uint32_t lane = staged_lane_;
  DB_ASSIGN_OR_RETURN(const std::vector<VkCommandBuffer> captures, RecordCapturesInParallel(lane, run));
  DB_RETURN_IF_ERROR(pass_->SubmitWithoutWaiting(
      [&](VkCommandBuffer commands) {
        Record(commands, lane, run.shape, run.which, drawn, true, run.unwritten_bits, captures);
      },
      lane));
  lanes_[lane].queued = std::move(staged_resident_);
  lanes_[lane].order = resident_runs_++;
  staged_resident_.reset();
  return Status::Ok();
}

Status RasterPass::FinishLane(std::uint32_t lane, ThreadPool* pool) {
  Lane& from = lanes_[lane];
  if (!from.queued) return Status::Ok();
  from.finished = std::move(from.queued);
  from.queued.reset();
  const ResidentRun& run = *from.finished;
  DB_RETURN_IF_ERROR(pass_->Wait(lane));
  DB_RETURN_IF_ERROR(from.readback.InvalidateForHostReads());
  const std::vector<bool> drawn = EverySlot();
  CompareTexels(lane, run.shape, run.codes, run.geometry, drawn, /*keep=*/false, pool);
  if (clock_.count() > 0 && !run.which.empty()) {
    DB_ASSIGN_OR_RETURN(const std::vector<std::uint64_t> stamps,
                        clock_.Read(lane * (kRasterParts + 1), kRasterParts + 1));
    for (std::uint32_t k = 0; k < kRasterParts; ++k) part_seconds_[k] += clock_.IntervalNs(stamps[k], stamps[k + 1]) * 1e-9;
  }
  return Status::Ok();
}

// Oldest first, as they were queued.
Status RasterPass::FinishResident(ThreadPool* pool) {
  std::array<std::uint32_t, kLanes> order{};
  for (std::uint32_t lane = 0; lane < kLanes; ++lane) order[lane] = lane;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return lanes_[a].order < lanes_[b].order; });
  for (const std::uint32_t lane : order) DB_RETURN_IF_ERROR(FinishLane(lane, pool));
  return Status::Ok();
}

std::vector<std::pair<std::string, double>> RasterPass::part_seconds() const {
  if (clock_.count() == 0) return {};
  constexpr std::array<const char*, kRasterParts> kNames = {"depth", "fetch", "attributes", "reconstruction",
                                                            "no geometry"};
  std::vector<std::pair<std::string, double>> out;
  for (std::uint32_t k = 0; k < kRasterParts; ++k) out.emplace_back(kNames[k], part_seconds_[k]);
  return out;
}

void RasterPass::Record(VkCommandBuffer commands, std::uint32_t lane, RunShape shape,
                        std::span<const std::uint32_t> which, const std::vector<bool>& drawn, bool fetch,
                        std::uint32_t unwritten_bits, std::span<const VkCommandBuffer> captures) const {
  const Lane& on = lanes_[lane];
  // Part k starts at the lane's timestamp k (Part); FinishLane reads them.
  const std::uint32_t first_query = lane * (kRasterParts + 1);
  const auto mark = [&](std::uint32_t part) {
    if (clock_.count() > 0) clock_.RecordWrite(commands, first_query + part);
  };
  if (clock_.count() > 0) clock_.RecordReset(commands, first_query, kRasterParts + 1);
  mark(kDepthPart);
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    if (drawn[slot]) RecordProduction(commands, lane, shape, slot);
  }
  mark(kFetchPart);
  if (fetch) RecordFetch(commands, lane, shape, drawn);
  mark(kAttributesPart);
  if (which.empty()) {
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                        VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                        VK_ACCESS_HOST_READ_BIT);
    return;
  }
  vkCmdFillBuffer(commands, on.positions.handle(), 0, VK_WHOLE_SIZE, unwritten_bits);
  vkCmdFillBuffer(commands, on.attributes.handle(), 0, VK_WHOLE_SIZE, 0);
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);

  // Pass 2 has no attachments: its fragments write the attributes (2a),
  // then the positions (2b).
  VkRenderingInfo rendering{};
  rendering.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
  rendering.renderArea = shape.Area();
  rendering.layerCount = 1;
  f32::RasterConstants constants = PassTwoConstants(shape, which.size());
  // Pass 2a draws at the samples' real pixels, a block of the window at a
  // time: here, or in the secondary command buffers recorded for it.
  if (captures.empty()) {
    RecordCaptures(commands, lane, constants, CapturedPrimitives(which), 0, capture_blocks_.size());
  } else {
    vkCmdExecuteCommands(commands, static_cast<std::uint32_t>(captures.size()), captures.data());
  }
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  mark(kReconstructionPart);

  vkCmdBeginRendering(commands, &rendering);
  // A draw per depth slot for its built-in cells (those the run does not
  // list write nothing), then one per user's cell.
  std::vector<bool> listed(cells_.size(), false);
  for (const std::uint32_t index : which) listed[index] = true;
  for (const Slot& slot : slots_) {
    if (std::none_of(slot.built_in_cells.begin(), slot.built_in_cells.end(),
                     [&](std::uint32_t index) { return listed[index]; })) {
      continue;
    }
    pass_->Bind(commands, slot.reconstruction.get(), VK_PIPELINE_BIND_POINT_GRAPHICS, SetOf(lane, *slot.atlas));
    constants.convention_slot = slot.convention_slot;
    constants.output_offset = 0;
    pass_->PushConstants(commands, &constants, sizeof(constants));
    RecordDraws(commands, shape, kTriangleVertices);  // atlas_cover.vert: the whole atlas
  }
  for (std::size_t k = 0; k < which.size(); ++k) {
    const CellPlan& plan = cells_[which[k]];
    const Variant variant = plan.cell.variant;
    if (plan.cell.variant_info().user == nullptr) continue;
    pass_->Bind(commands, reconstruction_[static_cast<std::size_t>(variant)].get(), VK_PIPELINE_BIND_POINT_GRAPHICS,
                SetOf(lane, *slots_[plan.depth_slot].atlas));
    constants.convention_slot = plan.convention_slot;
    constants.output_offset = static_cast<std::uint32_t>(k * 3 * shape.count);
    pass_->PushConstants(commands, &constants, sizeof(constants));
    RecordDraws(commands, shape, kTriangleVertices);  // atlas_cover.vert: the whole atlas
  }
  vkCmdEndRendering(commands);

  // Nothing was drawn for a sample without geometry: it has no position.
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);
  mark(kNoGeometryPart);
  pass_->Bind(commands, no_geometry_.get(), VK_PIPELINE_BIND_POINT_COMPUTE, SetOf(lane, 0));
  constants.output_offset = 0;
  pass_->PushConstants(commands, &constants, sizeof(constants));
  vkCmdDispatch(commands, (shape.count + kFetchWorkgroup - 1) / kFetchWorkgroup, 1, 1);
  mark(kRasterParts);
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                      VK_ACCESS_HOST_READ_BIT);
}

void RasterPass::RecordCaptures(VkCommandBuffer commands, std::uint32_t lane, const f32::RasterConstants& constants,
                                std::array<bool, 2> captured, std::size_t begin, std::size_t end) const {
  VkRenderingInfo capturing{};
  capturing.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
  capturing.layerCount = 1;
  for (std::size_t b = begin; b < end; ++b) {
    const CaptureBlock& block = capture_blocks_[b];
    capturing.renderArea = block.area;
    vkCmdBeginRendering(commands, &capturing);
    for (std::size_t k = 0; k < capture_.size(); ++k) {
      if (!captured[k]) continue;
      pass_->Bind(commands, capture_[k].get(), VK_PIPELINE_BIND_POINT_GRAPHICS, SetOf(lane, 0));
      pass_->PushConstants(commands, &constants, sizeof(constants));
      RecordSampleDraws(commands, block, k == 1);
    }
    vkCmdEndRendering(commands);
  }
}

f32::RasterConstants RasterPass::PassTwoConstants(RunShape shape, std::size_t listed) const {
  return {.sample_count = shape.count,
          .atlas_width = kAtlasWidth,
          .samples_per_frame = kSamplesPerFrame,
          .first_in_frame = shape.first_offset,
          .conventions_per_frame = kHardwareConventionCount,
          .convention_slot = 0,
          .output_offset = 0,
          .viewport_height = ViewportHeight(AtlasRows()),
          .coverage_word = 0,
          .slices = static_cast<std::uint32_t>(3 * listed),
          .first_texel = shape.first_texel,
          .atlas_rows = AtlasRows()};
}

std::array<bool, 2> RasterPass::CapturedPrimitives(std::span<const std::uint32_t> which) const {
  const auto reads_volume = [&](std::uint32_t index) { return cells_[index].cell.variant == Variant::kVolumeRay; };
  return {!std::all_of(which.begin(), which.end(), reads_volume),
          std::any_of(which.begin(), which.end(), reads_volume)};
}

// A driver records pass 2a's many small draws (each sets its viewports and
// scissors) slowly: an H200's host took about 20 ms a batch of 262144
// samples on one thread. Each recorder takes a run of whole blocks, about
// as many samples each, and the primary runs them in block order. A
// block's commands set all they use (pipeline, set, push constants,
// dynamic state): a secondary command buffer inherits none of it.
Expected<std::vector<VkCommandBuffer>> RasterPass::RecordCapturesInParallel(std::uint32_t lane,
                                                                            const ResidentRun& run) {
  const std::size_t blocks = capture_blocks_.size();
  const auto recorders = static_cast<std::uint32_t>(
      std::min<std::size_t>(run.pool == nullptr ? 1 : run.pool->size(), blocks / kBlocksPerRecorder));
  if (recorders <= 1) return std::vector<VkCommandBuffer>{};

  Lane& on = lanes_[lane];
  while (on.recorders.size() < recorders) {
    VkCommandPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    pool_info.queueFamilyIndex = context_->properties().queue_family;
    VkCommandPool handle = VK_NULL_HANDLE;
    DB_RETURN_IF_ERROR(CheckVk(vkCreateCommandPool(device(), &pool_info, nullptr, &handle), "vkCreateCommandPool"));
    Lane::Recorder recorder;
    recorder.pool = DeviceObject<VkCommandPool>(device(), handle, vkDestroyCommandPool);
    VkCommandBufferAllocateInfo buffer_info{};
    buffer_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    buffer_info.commandPool = handle;
    buffer_info.level = VK_COMMAND_BUFFER_LEVEL_SECONDARY;
    buffer_info.commandBufferCount = 1;
    DB_RETURN_IF_ERROR(
        CheckVk(vkAllocateCommandBuffers(device(), &buffer_info, &recorder.commands), "vkAllocateCommandBuffers"));
    on.recorders.push_back(std::move(recorder));
  }
  // Recorder g starts at the first block whose first sample is at least
  // g / recorders of the way through the draw order.
  std::vector<std::size_t> starts(recorders + 1, blocks);
  const std::size_t total = draw_order_.size();
  for (std::size_t g = 0, b = 0; g < recorders; ++g) {
    while (b < blocks && std::size_t{capture_blocks_[b].first} * recorders < g * total) ++b;
    starts[g] = b;
  }
  const f32::RasterConstants constants = PassTwoConstants(run.shape, run.which.size());
  const std::array<bool, 2> captured = CapturedPrimitives(run.which);
  std::vector<VkResult> results(recorders, VK_SUCCESS);
  std::vector<VkCommandBuffer> secondaries(recorders);
  run.pool->ParallelFor(recorders, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t g = begin; g < end; ++g) {
      secondaries[g] = on.recorders[g].commands;
      results[g] = vkResetCommandPool(device(), on.recorders[g].pool.get(), 0);
      VkCommandBufferInheritanceInfo inheritance{};
      inheritance.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO;
      VkCommandBufferBeginInfo begin_info{};
      begin_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
      begin_info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
      begin_info.pInheritanceInfo = &inheritance;
      if (results[g] == VK_SUCCESS) results[g] = vkBeginCommandBuffer(secondaries[g], &begin_info);
      if (results[g] != VK_SUCCESS) continue;
      RecordCaptures(secondaries[g], lane, constants, captured, starts[g], starts[g + 1]);
      results[g] = vkEndCommandBuffer(secondaries[g]);
    }
  });
  for (const VkResult result : results) DB_RETURN_IF_ERROR(CheckVk(result, "recording pass 2a's blocks"));
  return secondaries;
}

// After pass 1: what a fetch returns for every drawn texel, and its status.
void RasterPass::RecordFetch(VkCommandBuffer commands, std::uint32_t lane, RunShape shape,
                             const std::vector<bool>& drawn) const {
  // The coverage copies (RecordProduction's) before the fetch reads them.
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    if (!drawn[slot]) continue;
    pass_->Bind(commands, fetch_.get(), VK_PIPELINE_BIND_POINT_COMPUTE, SetOf(lane, *slots_[slot].atlas));
    f32::RasterConstants constants{};
    constants.sample_count = shape.count;
    constants.atlas_width = kAtlasWidth;
    constants.output_offset = static_cast<std::uint32_t>(slot * shape.count);
    constants.coverage_word = static_cast<std::uint32_t>(coverage_offsets_[slot] / 4);
    constants.first_texel = shape.first_texel;
    constants.atlas_rows = AtlasRows();
    pass_->PushConstants(commands, &constants, sizeof(constants));
    vkCmdDispatch(commands, (shape.count + kFetchWorkgroup - 1) / kFetchWorkgroup, 1, 1);
  }
  // A judge on the device reads them next, in a later submission.
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
}

void RasterPass::RecordProduction(VkCommandBuffer commands, std::uint32_t lane, RunShape shape,
                                  std::size_t slot_index) const {
  const Slot& slot = slots_[slot_index];
  const Atlas& atlas = atlases_[*slot.atlas];
  const bool depth = IsDepthFormat(slot.encoding.format);
  constexpr VkPipelineStageFlags kAttachmentStages = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                                     VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
                                                     VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  constexpr VkAccessFlags kAttachmentWrites =
      VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  const VkImageLayout value_layout =
      depth ? VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  // What the atlases held is cleared: the old contents need not survive.
  RecordImageBarrier(commands, atlas.value, VK_IMAGE_LAYOUT_UNDEFINED, value_layout,
                     VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, kAttachmentStages, kAttachmentWrites);
  RecordImageBarrier(commands, atlas.coverage, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                     VK_PIPELINE_STAGE_TRANSFER_BIT, 0, kAttachmentStages, kAttachmentWrites);

  VkClearValue uncovered{};
  uncovered.color.uint32[0] = 0;
  VkClearValue far{};  // what a depth buffer holds where nothing was drawn
  far.depthStencil.depth = ReversedDepth(slot.encoding.convention) ? 0.0f : 1.0f;
  VkClearValue nothing{};
  nothing.color.float32[0] = 0.0f;
  std::vector<VkRenderingAttachmentInfo> colors = {
      ClearedAttachment(atlas.coverage, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, uncovered)};
  if (!depth) colors.push_back(ClearedAttachment(atlas.value, value_layout, nothing));
  const VkRenderingAttachmentInfo depth_attachment = ClearedAttachment(atlas.value, value_layout, far);
  VkRenderingInfo rendering{};
  rendering.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
  rendering.renderArea = shape.Area();
  rendering.layerCount = 1;
  rendering.colorAttachmentCount = static_cast<std::uint32_t>(colors.size());
  rendering.pColorAttachments = colors.data();
  rendering.pDepthAttachment = depth ? &depth_attachment : nullptr;
  vkCmdBeginRendering(commands, &rendering);
  pass_->Bind(commands, slot.production.get(), VK_PIPELINE_BIND_POINT_GRAPHICS, SetOf(lane, 0));
  f32::RasterConstants constants{};
  constants.sample_count = shape.count;
  constants.atlas_width = kAtlasWidth;
  constants.samples_per_frame = kSamplesPerFrame;
  constants.first_in_frame = shape.first_offset;
  constants.conventions_per_frame = kHardwareConventionCount;
  constants.convention_slot = slot.convention_slot;
  constants.viewport_height = ViewportHeight(AtlasRows());
  constants.first_texel = shape.first_texel;
  constants.atlas_rows = AtlasRows();
  pass_->PushConstants(commands, &constants, sizeof(constants));
  RecordDraws(commands, shape, kTriangleVertices * shape.count);
  vkCmdEndRendering(commands);

  // The texels and the coverage go to the host; the texels then to pass 2.
  for (const VulkanImage* image : {&atlas.value, &atlas.coverage}) {
    RecordImageBarrier(commands, *image, image == &atlas.value ? value_layout : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                       VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, kAttachmentStages, kAttachmentWrites,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferImageCopy region{};
    // The batch's rows, where they lie in the whole atlas's layout.
    const std::uint32_t texel_bytes = image == &atlas.value ? TexelBytes(slot.encoding.format) : 1;
    region.bufferOffset = (image == &atlas.value ? texel_offsets_[slot_index] : coverage_offsets_[slot_index]) +
                          VkDeviceSize{shape.first_row} * kAtlasWidth * texel_bytes;
    region.imageSubresource = {image->aspect, 0, 0, 1};
    region.imageOffset = {0, static_cast<std::int32_t>(shape.first_row), 0};
    region.imageExtent = {kAtlasWidth, shape.rows, 1};
    vkCmdCopyImageToBuffer(commands, image->image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           lanes_[lane].readback.handle(), 1,
                           &region);
  }
  RecordImageBarrier(commands, atlas.value, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_TRANSFER_READ_BIT,
                     VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                     VK_ACCESS_SHADER_READ_BIT);
}

// Pass 1 and 2b: one draw for the whole batch through the atlas viewport
// (pass 1: vertices 3i to 3i + 2 are sample i's triangle, which the vertex
// stage places on its texel; 2b: one triangle over the atlas).
void RasterPass::RecordDraws(VkCommandBuffer commands, RunShape shape, std::uint32_t vertices) const {
  const VkViewport viewport = AtlasViewport(AtlasRows());
  const VkRect2D scissor = shape.Area();
  vkCmdSetViewport(commands, 0, 1, &viewport);
  vkCmdSetScissor(commands, 0, 1, &scissor);
  vkCmdDraw(commands, vertices, 1, 0, 0);
}

// Pass 2a over one block: kViewportsPerDraw samples a draw (a block's
// samples start at a multiple of it), the draw's primitive k (sample
// draw_order_[first + k]) taking viewport k, which the draw has just set;
// a full-screen triangle each, or a light volume (`cubes`). The draw's
// first vertex, or its vertex offset, names the block's sample
// `first` to the vertex stage.
void RasterPass::RecordSampleDraws(VkCommandBuffer commands, const CaptureBlock& block, bool cubes) const {
  if (cubes) vkCmdBindIndexBuffer(commands, cube_indices_.handle(), 0, VK_INDEX_TYPE_UINT16);
  const std::uint32_t end = block.first + block.samples;
  for (std::uint32_t first = block.first; first < end; first += kViewportsPerDraw) {
    vkCmdSetViewport(commands, 0, kViewportsPerDraw, viewports_.data() + first);
    vkCmdSetScissor(commands, 0, kViewportsPerDraw, scissors_.data() + first);
    const std::uint32_t samples = std::min(kViewportsPerDraw, end - first);
    if (cubes) {
      vkCmdDrawIndexed(commands, static_cast<std::uint32_t>(samples * kCubeIndices.size()), 1, 0,
                       static_cast<std::int32_t>(first * kCubeCorners), 0);
    } else {
      vkCmdDraw(commands, samples * kTriangleVertices, 1, first * kTriangleVertices, 0);
    }
  }
}

namespace {

// CompareTexels over n samples whose texels lie side by side (`bytes` a
// texel, 2 or 4): adds to `counted` and, where given, keeps each sample's
// texel (the device's where it has geometry, else the host's code) and
// whether it was drawn. Without branches on the texels' values (a GPU's
// differ from the model's in about half the samples of many encodings),
// and with CodeDistance's arithmetic inline.
void CountTexels(const std::byte* texels, std::uint32_t bytes, std::uint32_t mask, std::uint32_t sign,
                 const std::uint8_t* coverage, const std::uint32_t* host_codes, const std::uint8_t* geometry,
                 std::size_t n, std::uint32_t* kept, std::uint8_t* kept_drawn, RasterAgreement& counted) {
  std::uint64_t judged_count = 0, uncovered_count = 0, differing_count = 0;
  std::int64_t farthest = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t device = 0;
    if (bytes == 2) {
      std::uint16_t half = 0;
      std::memcpy(&half, texels + i * 2, sizeof(half));
      device = half;
    } else {
      std::memcpy(&device, texels + i * 4, sizeof(device));
      device &= mask;
    }
    const std::uint32_t host = host_codes[i];
    // An uncovered texel holds the clear value: it is counted apart,
    // neither judged nor compared with the model (fetch.comp marks it
    // undrawn for a judge on the device by the same byte).
    const bool judged = geometry[i] != 0;
    const bool uncovered = judged && coverage[i] == 0;
    const bool differing = judged && !uncovered && device != host;
    judged_count += judged;
    uncovered_count += uncovered;
    differing_count += differing;
    const std::int64_t distance = CodeOnLine(device, sign) - CodeOnLine(host, sign);
    farthest = std::max(farthest, differing ? std::abs(distance) : 0);
    if (kept != nullptr) {
      kept[i] = judged ? device : host;
      kept_drawn[i] = uncovered ? 0 : 1;
    }
  }
  counted.texels += judged_count;
  counted.uncovered += uncovered_count;
  counted.differing += differing_count;
  counted.max_code_distance = std::max<std::uint32_t>(
      counted.max_code_distance,
      static_cast<std::uint32_t>(std::min<std::int64_t>(farthest, std::numeric_limits<std::uint32_t>::max())));
}

}  // namespace

void RasterPass::CompareTexels(std::uint32_t lane, RunShape shape, std::span<const std::uint32_t> codes,
                               std::span<const std::uint8_t> geometry, const std::vector<bool>& drawn, bool keep,
                               ThreadPool* pool) {
  const std::size_t count = shape.count;
  texels_.resize(keep ? slots_.size() * count : 0);
  texel_drawn_.resize(keep ? slots_.size() * count : 0);
  const auto* readback = static_cast<const std::byte*>(lanes_[lane].readback.mapped());
  const std::uint32_t atlas_texels = kAtlasWidth * AtlasRows();
  // Each slot apart (its texels, its agreement): on the pool's threads.
  const auto compare = [&](std::size_t s) {
    std::uint32_t* kept = texels_.data() + (keep ? s * count : 0);
    std::uint8_t* kept_drawn = texel_drawn_.data() + (keep ? s * count : 0);
    const std::uint32_t* host_codes = codes.data() + s * count;
    if (!drawn[s]) {
      if (keep) {
        std::copy_n(host_codes, count, kept);
        std::fill_n(kept_drawn, count, std::uint8_t{1});
      }
      return;
    }
    const Format format = slots_[s].encoding.format;
    const std::byte* texels = readback + texel_offsets_[s];
    const std::byte* coverage = readback + coverage_offsets_[s];
    // Counted here and added once: the slots' counts lie side by side in
    // agreement_, and threads adding to them texel by texel would fight
    // over their cache lines.
    RasterAgreement counted;
    // A texel's bits as ShaderInputs::codes holds them: X8_D24 keeps its
    // depth in the low 24 bits of the word, the other 8 are undefined.
    const std::uint32_t bytes = TexelBytes(format);
    const std::uint32_t mask = format == Format::kX8D24Unorm ? 0x00ff'ffffu : 0xffff'ffffu;
    const std::uint32_t sign = CodeSignBit(format);
    // Sample i's texel steps through the atlas from shape.first_texel
    // (RunShape::TexelOf), wrapping at its end: a run of samples at a time
    // whose texels do not wrap.
    std::uint32_t first = shape.first_texel;
    for (std::size_t begin = 0; begin < count;) {
      const std::size_t run = std::min<std::size_t>(count - begin, atlas_texels - first);
      CountTexels(texels + std::size_t{first} * bytes, bytes, mask, sign,
                  reinterpret_cast<const std::uint8_t*>(coverage) + first, host_codes + begin, geometry.data() + begin,
                  run, keep ? kept + begin : nullptr, keep ? kept_drawn + begin : nullptr, counted);
      begin += run;
      first = 0;
    }
    agreement_[s].Merge(counted);
  };
  if (pool == nullptr) {
    for (std::size_t s = 0; s < slots_.size(); ++s) compare(s);
    return;
  }
  pool->ParallelFor(slots_.size(), [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t s = begin; s < end; ++s) compare(s);
  });
}

}  // namespace depthbench
