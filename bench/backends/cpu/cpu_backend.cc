#include "bench/backends/cpu/cpu_backend.h"

#include <cstddef>
#include <cstring>

#include <fmt/format.h>

#include "bench/base/build_info.h"
#include "bench/numerics/formulas.h"
#include "bench/pipeline/raster_model.h"
#include "bench/pipeline/user_variant.h"

namespace depthbench {
namespace {

// One cell over a batch. The formula is a template argument so that it is
// inlined into the loop, as a shader compiler inlines it.
// The frame's constants, the same in every lane. The parameter blocks hold
// their float members first, in the same order in both widths.
template <class Wide, class Narrow>
void BroadcastFloats(const Narrow& narrow, Wide& wide, std::size_t floats) {
  const auto* from = reinterpret_cast<const float*>(&narrow);
  auto* to = reinterpret_cast<Float8*>(&wide);
  for (std::size_t k = 0; k < floats; ++k) to[k] = Float8(from[k]);
}

// Lane `lane` of the wide block set to the narrow one's floats.
template <class Wide, class Narrow>
void SetLaneFloats(const Narrow& narrow, Wide& wide, std::size_t floats, int lane) {
  const auto* from = reinterpret_cast<const float*>(&narrow);
  auto* to = reinterpret_cast<float*>(&wide);
  for (std::size_t k = 0; k < floats; ++k) to[k * Float8::kLanes + static_cast<std::size_t>(lane)] = from[k];
}

f32x8::FrameParams Widen(const f32::FrameParams& narrow) {
  f32x8::FrameParams wide;
  BroadcastFloats(narrow, wide, sizeof(narrow) / sizeof(float));
  return wide;
}

f32x8::DepthParams Widen(const f32::DepthParams& narrow) {
  f32x8::DepthParams wide;
  BroadcastFloats(narrow, wide, offsetof(f32::DepthParams, convention) / sizeof(float));
  wide.convention = narrow.convention;
  wide.reserved0 = wide.reserved1 = wide.reserved2 = 0;
  return wide;
}

// The FrameParams the variant reads in each lane: the frame's, or in the
// raster form the sample's own, with the screen attributes a rasterizer
// interpolates at its pixel (bench/pipeline/raster_model.h).
f32x8::FrameParams RasterLaneFrames(const ShaderInputs& batch, std::uint32_t frame_index, std::uint32_t first, int n) {
  const f32::FrameParams& frame = batch.frame_params[frame_index];
  const f32::DepthParams& standard = batch.depth_params[frame_index * kHardwareConventionCount];
  f32x8::FrameParams wide;
  for (int lane = 0; lane < Float8::kLanes; ++lane) {
    const std::uint32_t k = first + static_cast<std::uint32_t>(lane < n ? lane : n - 1);
    const std::uint32_t pixel = batch.pixels[k];
    SetLaneFloats(RasterFrameParams(frame, standard, pixel & 0xffffu, pixel >> 16, batch.raster[k]), wide,
                  sizeof(frame) / sizeof(float), lane);
  }
  return wide;
}

// Frame by frame (the frame's constants are uniform), eight samples at a
// time in the lanes of the f32x8 instantiation.
template <f32x8::WorldPositionFn Reconstruct>
void RunCell(const ShaderInputs& batch, const CellPlan& plan, float* out) {
  const bool raster = !batch.raster.empty();
  constexpr int kLanes = Float8::kLanes;
  const float* depths = batch.depths.data() + static_cast<std::size_t>(plan.depth_slot) * batch.count;
  for (std::uint32_t begin = 0; begin < batch.count;) {
    const std::uint32_t frame_index = batch.FrameOf(begin);
    const std::uint32_t end =
        std::min<std::uint32_t>(batch.count, (frame_index + 1) * kSamplesPerFrame - batch.first_offset);
    const f32x8::FrameParams uniform_frame = Widen(batch.frame_params[frame_index]);
    f32x8::FrameParams lane_frames;
    const f32x8::DepthParams depth =
        Widen(batch.depth_params[frame_index * kHardwareConventionCount + plan.convention_slot]);
    for (std::uint32_t i = begin; i < end; i += kLanes) {
      const int n = static_cast<int>(std::min<std::uint32_t>(kLanes, end - i));
      const f32x8::FrameParams& frame =
          raster ? (lane_frames = RasterLaneFrames(batch, frame_index, i, n)) : uniform_frame;
      using Words = std::uint32_t __attribute__((vector_size(32)));
      Words pixels;
      Float8::Lanes stored;
      if (n == kLanes) {
        std::memcpy(&pixels, batch.pixels.data() + i, sizeof(pixels));
        std::memcpy(&stored, depths + i, sizeof(stored));
      } else {
        for (int lane = 0; lane < kLanes; ++lane) {
          const std::uint32_t k = i + static_cast<std::uint32_t>(lane < n ? lane : n - 1);  // pad the tail
          pixels[lane] = batch.pixels[k];
          stored[lane] = depths[k];
        }
      }
      const Float8::Lanes x = __builtin_convertvector(pixels & 0xffffu, Float8::Lanes);
      const Float8::Lanes y = __builtin_convertvector(pixels >> 16, Float8::Lanes);
      const f32x8::vec2 uv = f32x8::uv_from_pixel(Float8::FromLanes(x), Float8::FromLanes(y), frame.resolution);
      const f32x8::vec3 p = Reconstruct(frame, depth, uv, Float8::FromLanes(stored));
      const std::size_t count = batch.count;
      if (n == kLanes) {
        std::memcpy(out + i, &p.x, sizeof(Float8));
        std::memcpy(out + count + i, &p.y, sizeof(Float8));
        std::memcpy(out + 2 * count + i, &p.z, sizeof(Float8));
      } else {
        for (int lane = 0; lane < n; ++lane) {
          out[i + lane] = p.x[lane];
          out[count + i + lane] = p.y[lane];
          out[2 * count + i + lane] = p.z[lane];
        }
      }
    }
    begin = end;
  }
}

using CellRunner = void (*)(const ShaderInputs&, const CellPlan&, float*);

CellRunner RunnerFor(Variant v) {
  switch (v) {
    case Variant::kFrustumRay: return RunCell<f32x8::frustum_ray_world_position>;
    case Variant::kVolumeRay: return RunCell<f32x8::volume_ray_world_position>;
    case Variant::kTanAspect: return RunCell<f32x8::tan_aspect_world_position>;
    case Variant::kEyeRay: return RunCell<f32x8::eye_ray_world_position>;
    case Variant::kInverseVp: return RunCell<f32x8::inverse_vp_world_position>;
    case Variant::kDivide: return RunCell<f32x8::divide_world_position>;
    case Variant::kReciprocal: return RunCell<f32x8::reciprocal_world_position>;
    case Variant::kPq: return RunCell<f32x8::pq_world_position>;
    case Variant::kOrthoLerp: return RunCell<f32x8::ortho_lerp_world_position>;
    default: break;
  }
  return nullptr;
}

class CpuBackend final : public Backend {
 public:
  CpuBackend() {
    device_.name = "cpu";
    device_.driver = "GLM float32, -ffp-contract=off";
    device_.api = "C++20";
    device_.kind = DeviceKind::kCpu;
#if defined(__clang__)
    device_.compiler = fmt::format("clang++ {}.{}.{}", __clang_major__, __clang_minor__, __clang_patchlevel__);
#elif defined(__GNUC__)
    device_.compiler = fmt::format("g++ {}.{}.{}", __GNUC__, __GNUC_MINOR__, __GNUC_PATCHLEVEL__);
#endif
  }

  std::string name() const override { return BackendKindName(BackendKind::kCpu); }
  const DeviceInfo& device() const override { return device_; }
  // The formulas are compiled into the program: its version names them.
  ProgramInfo program() const override { return {"built-in", std::string("depthbench ") + BuildVersion()}; }
  bool concurrent() const override { return true; }

  Status Prepare(std::span<const CellPlan> cells, PassKind) override {
    for (const CellPlan& plan : cells) {
      const VariantInfo& variant = plan.cell.variant_info();
      if (variant.user != nullptr) {
        return Unavailable(fmt::format(
            "the cpu backend cannot run '{}': its formula is a shader file ({}), which runs on Vulkan only; "
            "use --backend vulkan",
            variant.name, variant.user->path.string()));
      }
    }
    cells_.assign(cells.begin(), cells.end());
    return Status::Ok();
  }

  Expected<std::span<const float>> Run(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                       std::vector<float>& scratch) override {
    const std::size_t per_cell = static_cast<std::size_t>(batch.count) * 3;
    scratch.resize(per_cell * which.size());
    for (std::size_t k = 0; k < which.size(); ++k) {
      if (which[k] >= cells_.size()) return Internal("cell index out of range");
      const CellPlan& plan = cells_[which[k]];
      RunnerFor(plan.cell.variant)(batch, plan, scratch.data() + k * per_cell);
    }
    return std::span<const float>(scratch.data(), per_cell * which.size());
  }

 private:
  DeviceInfo device_;
  std::vector<CellPlan> cells_;
};

}  // namespace

std::unique_ptr<Backend> MakeCpuBackend() { return std::make_unique<CpuBackend>(); }

}  // namespace depthbench
