// Backend: executes reconstructions and returns raw world positions; it
// never judges (the judge and the reference know nothing of backends).
//
// Lifecycle:
//   1. create it for a device (MakeBackend in factory.h, or a backend's own
//      factory that accepts an existing device);
//   2. Prepare(cells) once: whatever running those cells needs (the Vulkan
//      backend compiles the shaders and builds pipelines here);
//   3. Run(batch, which, scratch) any number of times: the listed cells'
//      world positions for every sample of the batch.
// PassKind picks the form: compute (the rasterizer's interpolation computed
// per pixel from the frame's constants, the stored depths as the batch
// gives them) or raster (the batch's RasterSample geometry drawn: depth
// produced by a rasterizer into a real depth or G-buffer target, fetched
// by texel, rays interpolated from the vertex stage).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/device_info.h"
#include "bench/pipeline/raster_model.h"
#include "bench/pipeline/shader_inputs.h"

namespace depthbench {

// A backend's runs that leave their outputs on its device for a judge
// there (the Vulkan backend's: vulkan_backend.h).
class DeviceResidentRuns;

enum class PassKind { kCompute, kRaster };
// The raster production model is produced by the raster form.
inline PassKind PassKindOf(ProductionModel production) {
  return production == ProductionModel::kRaster ? PassKind::kRaster : PassKind::kCompute;
}

// What a raster backend rendered (Backend::RenderDepths).
struct RenderedDepths {
  std::span<const std::uint32_t> codes;
  std::span<const float> fetched;
  // 1 where the rasterizer wrote the sample's texel, 0 where it left it as
  // cleared (a sample with geometry whose triangle was clipped or failed
  // the depth test), laid out as codes; empty when every texel was written.
  std::span<const std::uint8_t> drawn;
};

class Backend {
 public:
  virtual ~Backend() = default;

  virtual std::string name() const = 0;  // "cpu", "vulkan"
  virtual const DeviceInfo& device() const = 0;
  // What the prepared formulas were built from (known after Prepare).
  virtual ProgramInfo program() const = 0;

  virtual Status Prepare(std::span<const CellPlan> cells, PassKind pass = PassKind::kCompute) = 0;
  // Raster backends that produce their own depths (a real rasterizer):
  // renders the batch's geometry into every depth slot of the prepared
  // cells and returns the texel codes and what a texel fetch returns for
  // them (the device's own conversion to float), [depth slot * count +
  // sample], valid until the next call. The sweep adopts them into the batch
  // (BatchBuilder::AdoptStoredDepths) before any backend's Run, so every
  // backend reconstructs from the device's texels; Run then reads the
  // images this call rendered.
  virtual bool renders_depths() const { return false; }
  virtual Expected<RenderedDepths> RenderDepths(const ShaderInputs& /*batch*/) {
    return Unavailable(name() + " does not render depths");
  }
  // How the rendered depths agreed with the batch's (the host's model of
  // a rasterizer, before adoption), one per depth slot of the prepared
  // cells (RunLayout::encodings), since Prepare.
  virtual std::vector<RasterAgreement> raster_agreement() const { return {}; }
  // The texel bits a raster backend's last Run or RenderDepths rendered,
  // laid out as ShaderInputs::codes (the batch's own code where it drew
  // nothing); empty for any other backend or form. What the device
  // stored, for tests and diagnosis that compare forms on the same texels.
  virtual std::vector<std::uint32_t> raster_texels() const { return {}; }

  // World positions of the prepared cells listed in `which` (indices into
  // Prepare's list) for every sample of `batch`, component by component:
  // element ((k * 3 + c) * batch.count + i) is component c (x, y, z) of
  // sample i for the k-th listed cell. The storage is `scratch` or the
  // backend's own, valid until the next Run on the same thread.
  virtual Expected<std::span<const float>> Run(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                               std::vector<float>& scratch) = 0;

  // The most samples one Run of every prepared cell can take (a device's
  // buffer and dispatch limits); the sweep cuts its batches to it. Results
  // do not depend on the batch size.
  virtual std::uint64_t MaxBatchSamples() const { return UINT64_MAX; }
  // Whether Run may be called from several threads at once (with disjoint
  // scratch). The sweep then spreads cells over threads.
  virtual bool concurrent() const = 0;

  // Runs whose outputs stay in device memory, for a judge on the same
  // device (bench/device_judge/); null where outputs come back to the host
  // alone. The same object as this backend, valid as long as it is.
  virtual DeviceResidentRuns* device_resident() { return nullptr; }
};

// Options that select and configure a backend.
struct BackendOptions {
  std::string device;       // Vulkan: device name (substring, case-insensitive); "" picks lavapipe
  std::string shader_dir;   // Vulkan: where the shaders/ sources are ("" = built-in default)
  bool validation = false;  // Vulkan: enable VK_LAYER_KHRONOS_validation, fail on its messages
  // Vulkan: samples each compute invocation reconstructs (a divisor of the
  // samples per frame), and frames each workgroup takes in turn; 0 picks by
  // device type: 8 and 8 on a CPU device, 1 and 1 on a GPU.
  std::uint32_t samples_per_invocation = 0;
  std::uint32_t frames_per_workgroup = 0;
  // Vulkan: ArithmeticProbe bits (backends/vulkan/arithmetic_probe.h)
  // applied to every compiled shader; the backend is then named
  // "vulkan:<probes>".
  std::uint32_t arithmetic_probes = 0;
};

}  // namespace depthbench
