// The one place that says which program runs a variant: for a built-in
// variant, its file in the shader directory (NAME.comp for the accuracy
// pass, speed/NAME.comp for the timed pass); for a variant from the user's
// file (--variant-file), a program generated around the user's function:
// the pass of the same shader directory (GLSL, or shaders/user/'s HLSL
// form), the contract of shaders/user/contract.inc, and the user's file,
// included by its path so that compile errors name the user's file and
// line. The raster form's fragment program is generated for every variant
// the same way, around its function: shared/variants/NAME.h for a built-in
// one, the contract and the user's file for the user's; so is the device
// judge's fused program.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/cells.h"

namespace depthbench {

enum class VariantPass : std::uint8_t {
  kAccuracy,  // compute_pass.glsl: positions of the sweep's samples
  kSpeed,     // speed/speed_pass.glsl: the timed full-screen pass
  kRaster,    // raster/raster_pass.glsl: the raster form's reconstruction, a fragment program
  // judge/fused.comp: the compute form's reconstruction judged in the same
  // program (the device judge's fused pass); GLSL only.
  kJudged,
};

// SPIR-V of `variant`'s pass, from the programs in `shader_dir`. The text
// of every source compiled is appended to `sources` when it is not null.
Expected<std::vector<std::uint32_t>> CompileVariant(const VariantInfo& variant, VariantPass pass,
                                                    const std::filesystem::path& shader_dir,
                                                    std::vector<std::string>* sources = nullptr);

// One cell of the raster form's program of a depth slot
// (raster/raster_cells.glsl): a built-in variant, its index in the run's
// list of cells, and whether its rays come from the light volume.
struct RasterCell {
  const VariantInfo* variant = nullptr;
  std::uint32_t cell = 0;
  bool light_volume = false;
};
// SPIR-V of the fragment program that runs `cells`, built-in variants
// reading one depth slot, each as its own raster program would
// (VariantPass::kRaster), from the programs in `shader_dir`.
Expected<std::vector<std::uint32_t>> CompileRasterCells(std::span<const RasterCell> cells,
                                                        const std::filesystem::path& shader_dir,
                                                        std::vector<std::string>* sources = nullptr);

// The function of the program that holds the variant's arithmetic (what a
// static cost model counts): <name>_world_position, or the user's entry.
std::string VariantFunctionName(const VariantInfo& variant);
// What the passes call as RECONSTRUCT(frame, depth, uv, stored): the
// variant's function, or for a user's the contract's wrapper around it.
std::string ReconstructFunctionName(const VariantInfo& variant);

// What compile messages call the program: its path, or for a generated
// one "<NAME's accuracy program>" (speed, raster).
std::string VariantProgramName(const VariantInfo& variant, VariantPass pass, const std::filesystem::path& shader_dir);

}  // namespace depthbench
