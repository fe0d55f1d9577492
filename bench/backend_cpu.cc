#include "bench/backend_cpu.h"

#include <fmt/format.h>

#include "bench/formulas.h"

namespace depthbench {
namespace {

// One cell over a batch. The formula is a template argument so that it is
// inlined into the loop, as a shader compiler inlines it.
template <f32::WorldPositionFn Reconstruct>
void RunCell(const Batch& batch, const CellPlan& plan, float* out) {
  const float* depths = batch.depths.data() + static_cast<std::size_t>(plan.depth_slot) * batch.count;
  for (std::uint32_t i = 0; i < batch.count; ++i) {
    const std::uint32_t frame_index = batch.FrameOf(i);
    const f32::FrameParams& frame = batch.frame_params[frame_index];
    const f32::DepthParams& depth =
        batch.depth_params[frame_index * kHardwareConventionCount + plan.convention_slot];
    const std::uint32_t pixel = batch.pixels[i];
    glm::vec2 uv = f32::uv_from_pixel(pixel & 0xffffu, pixel >> 16, frame.resolution);
    glm::vec3 p = Reconstruct(frame, depth, uv, depths[i]);
    out[3 * i + 0] = p.x;
    out[3 * i + 1] = p.y;
    out[3 * i + 2] = p.z;
  }
}

using CellRunner = void (*)(const Batch&, const CellPlan&, float*);

CellRunner RunnerFor(Variant v) {
  switch (v) {
    case Variant::kFrustumRay: return RunCell<f32::frustum_ray_world_position>;
    case Variant::kVolumeRay: return RunCell<f32::volume_ray_world_position>;
    case Variant::kTanAspect: return RunCell<f32::tan_aspect_world_position>;
    case Variant::kEyeRay: return RunCell<f32::eye_ray_world_position>;
    case Variant::kInverseVp: return RunCell<f32::inverse_vp_world_position>;
    case Variant::kDivide: return RunCell<f32::divide_world_position>;
    case Variant::kReciprocal: return RunCell<f32::reciprocal_world_position>;
    case Variant::kPq: return RunCell<f32::pq_world_position>;
  }
  return nullptr;
}

class CpuBackend final : public Backend {
 public:
  CpuBackend() {
    device_.name = "cpu";
    device_.driver = "GLM float32, -ffp-contract=off";
    device_.api = "C++20";
    device_.kind = "cpu";
#if defined(__clang__)
    device_.compiler = fmt::format("clang++ {}.{}.{}", __clang_major__, __clang_minor__, __clang_patchlevel__);
#elif defined(__GNUC__)
    device_.compiler = fmt::format("g++ {}.{}.{}", __GNUC__, __GNUC_MINOR__, __GNUC_PATCHLEVEL__);
#endif
  }

  std::string name() const override { return "cpu"; }
  const DeviceInfo& device() const override { return device_; }
  bool concurrent() const override { return true; }

  Status Prepare(std::span<const CellPlan> cells, PassKind) override {
    cells_.assign(cells.begin(), cells.end());
    return Status::Ok();
  }

  Expected<std::span<const float>> Run(const Batch& batch, std::span<const std::uint32_t> which,
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
