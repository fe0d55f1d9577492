// Variants from the user's own shader files (--variant-file): a
// reconstruction function written in GLSL or HLSL under the contract of
// docs/variant-files.md, added to a command's Catalogue after the built-in
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
#include <memory>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/cells.h"

namespace depthbench {

// The largest array a variant function may declare, in elements: a
// reconstruction needs a few values, and a private array is every
// invocation's own (50 million floats took the process to 24 GB). The
// source is checked before compiling (a literal size, with its line), the
// compiled module after (any size).
inline constexpr std::uint64_t kMostVariantArrayElements = 4096;

enum class ShaderLanguage : std::uint8_t { kGlsl, kHlsl };

// What a user's shader file declares, and where it is.
struct UserShader {
  std::filesystem::path path;  // absolute
  ShaderLanguage language = ShaderLanguage::kGlsl;
  std::string entry = "reconstruct";
  bool uv_bottom_left = false;
  bool view_left_handed = false;
};

// A variant a user's shader file declares: what a Catalogue holds for it.
struct UserVariant {
  UserShader shader;
  std::string name;
  DepthInput input = DepthInput::kHardware;
  std::string source;  // "user shader NAME.glsl"
  std::string idea;    // the language, function and path
};

// Reads the declaration line of the shader file at `path` (.glsl or .hlsl).
// InvalidArgument, naming the file (and line) and what is allowed, when the
// file cannot be read or declares nothing or something unknown.
Expected<UserVariant> ReadVariantFile(const std::string& path);

// The catalogue of one command: the built-in variants, then the variant of
// each file of `paths`, in order (the same file twice is one variant).
// ReadVariantFile's errors, and InvalidArgument when a variant's name is
// taken or there are more than kMostUserVariants files.
Expected<std::unique_ptr<const Catalogue>> MakeCatalogue(const std::vector<std::string>& paths);

}  // namespace depthbench
