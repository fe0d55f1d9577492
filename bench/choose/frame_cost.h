// Frame cost: what choosing a (variant, convention, format) makes a frame
// do, in time on one device at one resolution. Three parts:
//
//   - the depth attachment's bytes: written by the geometry pass and, for a
//     hardware depth, read again by the pass that reconstructs positions;
//   - the extra target a linear or view-z depth needs beside the depth
//     attachment (which the depth test still uses): written by the geometry
//     pass, read by the reconstructing pass;
//   - the reconstruction's arithmetic, once per pixel.
//
// Bytes become time at the bandwidth the speed file's probe measured (a
// copy between two device buffers); the arithmetic is the speed file's
// ALU-bound timing of that very cell. What every choice pays alike (the
// geometry, overdraw, the depth test's own reads, compression that
// hardware applies to depth) is left out: it does not move a ranking.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "bench/base/status.h"
#include "bench/choose/ranking.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/speed/speed_results.h"

namespace depthbench {

// The depth attachment an engine that stores a linear or view-z target
// keeps for its depth test: D24 with 8 bits of stencil beside it, the
// common pairing.
inline constexpr Format kLinearTestAttachment = Format::kX8D24Unorm;

// Bytes per pixel of a depth attachment in `format`, with or without
// stencil: D16 2 (4 with stencil: D16_UNORM_S8_UINT padded), D24 4 (the
// stencil takes the X8 byte), D32F 4 (8 with stencil: D32_SFLOAT_S8_UINT
// keeps the stencil in a padded word of its own). A colour format (the
// linear and view-z targets) takes its texel and never a stencil.
std::uint32_t AttachmentBytes(Format format, bool stencil);

// Bytes per pixel a cell's depth makes a frame move.
struct FrameBytes {
  std::uint32_t attachment = 0;  // the depth attachment's texel
  std::uint32_t target = 0;      // the extra linear or view-z texel (0: none)
  // Written and read: the attachment is written once and, where no target
  // stands in for it, read once; the target is written once and read once.
  std::uint32_t moved() const { return target == 0 ? 2 * attachment : attachment + 2 * target; }
};
FrameBytes FrameBytesOf(const Cell& cell, bool stencil);

// One cell's cost per frame, in its parts.
struct FrameCost {
  FrameBytes bytes;
  double memory_us = 0.0;  // the bytes moved at the measured bandwidth
  double alu_us = 0.0;     // one reconstruction per pixel
  double spread_us = 0.0;  // of the ALU timing, scaled alike
  double total_us() const { return memory_us + alu_us; }
};

// Where a frame's costs come from: one speed file's bandwidth probe and
// ALU-bound timings, at a frame size and with or without stencil.
struct FrameCostModel {
  std::shared_ptr<const SpeedResults> speed;
  std::string source;  // the speed file, for the cost's label
  Resolution frame{1920, 1080};
  bool stencil = false;

  // NotFound when the file has no ALU-bound timing of the cell;
  // InvalidArgument when it has no bandwidth probe.
  Expected<FrameCost> Cost(const Cell& cell) const;
  // "µs per 2560x1440 frame on <device>"
  std::string Unit() const;
};

// InvalidArgument, saying how to make one, when `speed` has no
// bandwidth probe (files made before the probe).
Status CheckFrameCostable(const SpeedResults& speed, const std::string& source);

// The model as a ranking's cost lookup: each candidate's total with its
// spread, and its parts in words.
CostLookup FrameCostLookup(FrameCostModel model);

// The speed file a command that runs on `device` costs with: `named` when
// given (whatever device it was measured on: its costs are labelled as
// that device's), else the first committed one (reports/speed/*.json,
// repeats left out) measured on `device` that has a bandwidth probe; null
// when none is.
Expected<std::shared_ptr<const SpeedResults>> SpeedFileFor(const DeviceInfo& device, const std::string& named,
                                                           const Catalogue& catalogue, std::string& source);

}  // namespace depthbench
