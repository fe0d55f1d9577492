// Variants from the user's own shader files (--variant-file): a
// reconstruction function written in GLSL or HLSL under the contract of
// docs/variant-files.md, registered in the catalog after the built-in
// variants, so that every subcommand runs it as it runs those. The file
// declares its contract in one comment line:
//
//   // depthbench: input=hardware entry=reconstruct uv=top-left view=right-handed
//
// input (required): the depth it reads, hardware (a depth buffer), linear
//   (eye depth / far) or viewz (view-space z);
// entry: the function's name (default `reconstruct`); its signature is
//   vec3 NAME(vec2 uv, float depth) in GLSL, float3 NAME(float2 uv, float depth)
//   in HLSL, and it returns the world-space position;
// uv: where uv (0, 0) is, top-left (the default; Vulkan and Direct3D
//   textures) or bottom-left (OpenGL);
// view: the handedness of the view space its matrices and rays are given
//   in, right-handed (the default: the camera looks down -z) or left-handed
//   (it looks down +z, as Direct3D and Unreal do);
// name: the variant's name (default: the file's name without extension).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/cells.h"

namespace depthbench {

enum class ShaderLanguage : std::uint8_t { kGlsl, kHlsl };

// What a user's shader file declares, and where it is.
struct UserShader {
  std::filesystem::path path;  // absolute
  ShaderLanguage language = ShaderLanguage::kGlsl;
  std::string entry = "reconstruct";
  bool uv_bottom_left = false;
  bool view_left_handed = false;
};

// Reads the declaration line of the shader file at `path` (.glsl or .hlsl)
// and adds the variant to the catalog; the same file twice is one variant.
// InvalidArgument, naming the file (and line) and what is allowed, when the
// file cannot be read, declares nothing or something unknown, or its name
// is taken.
Expected<Variant> RegisterVariantFile(const std::string& path);

// Registers every file, in order, after dropping those registered before
// (each command of a process starts from the built-in catalog).
Status RegisterVariantFiles(const std::vector<std::string>& paths);

// Whether any variant of the catalog comes from a user's file.
bool AnyUserVariant();

}  // namespace depthbench
