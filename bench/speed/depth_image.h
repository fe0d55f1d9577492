// DepthImage: the content of the depth image a timed pass reads, made on
// the host. A frame of a fixed, ordinary scene (60 degree lens, near 0.1,
// far/near 1e4, the camera 100 units from the origin) at the pass's
// resolution; every pixel an eye depth that grows up the screen with a
// little per-pixel variation, encoded exactly as the accuracy bench encodes
// (bench/pipeline/encode.h) and packed into the texels of the Vulkan format.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "bench/base/status.h"
#include "bench/base/thread_pool.h"
#include "bench/numerics/formulas.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

struct DepthImage {
  Encoding encoding{};
  Resolution resolution{0, 0};
  std::uint32_t texel_bytes = 0;     // 2 or 4
  std::vector<std::uint8_t> texels;  // row-major, tightly packed, as vkCmdCopyBufferToImage reads them
  Frame frame;                       // the exact frame
  f32::FrameParams frame_params{};   // what the pass's uniform buffer holds
  f32::DepthParams depth_params{};   // zero for the linear convention (no projection is read)

  std::uint32_t Code(std::uint32_t x, std::uint32_t y) const;  // the texel's bits
};

// The frame every timed pass renders at `resolution`.
Frame SpeedFrame(Resolution resolution);

// InvalidArgument when no variant reads `encoding` (the pairing rule of
// cells.h) or the resolution is empty or above 16384 on a side.
Expected<DepthImage> MakeDepthImage(Encoding encoding, Resolution resolution, ThreadPool& pool);

// The texel codes of rows [first_row, first_row + rows) of such an image
// of `frame` (SpeedFrame), row-major: what MakeDepthImage stores there.
std::vector<std::uint32_t> EncodeDepthRows(Encoding encoding, const Frame& frame, std::uint32_t first_row,
                                           std::uint32_t rows);

}  // namespace depthbench
