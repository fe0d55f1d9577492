// GLSL (and HLSL) shaders to SPIR-V through glslang's C++ API: compute
// shaders for Vulkan 1.1 (SPIR-V 1.3), vertex and fragment shaders for
// Vulkan 1.2 (SPIR-V 1.5). `#include "..."` (GL_GOOGLE_include_directive) resolves
// relative to the directory of the including file, so a copy of shaders/ and
// shared/ compiles from the copy. Compile errors name the real path and line
// of the file they occur in, included files too.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/user_variant.h"

namespace depthbench {

// "glslang 12.0.0": the compiler the Vulkan backend's formulas go through.
std::string GlslangVersion();

// The pipeline stage a shader is compiled for.
enum class ShaderStage : std::uint8_t { kCompute, kVertex, kFragment };

// SPIR-V words of the `stage` shader in `path`. NotFound when the file does
// not exist, IoError when it cannot be read, CompileError with glslang's
// messages as "<path>:<line>: error: <message>" lines otherwise. When
// `sources` is not null, the text of the shader and of every file it
// includes is appended to it in the order read (what results hash to say
// which program ran).
Expected<std::vector<std::uint32_t>> CompileShader(const std::filesystem::path& path,
                                                   ShaderStage stage = ShaderStage::kCompute,
                                                   std::vector<std::string>* sources = nullptr);

// The same for source text in `language` that glslang reports as `name`,
// whose includes resolve relative to `include_dir` (absolute include paths
// as they are): how a program generated around a user's function compiles.
// HLSL's entry point is main(). With `source_lines`, the module carries
// OpString and OpLine instructions (which file and line each instruction
// came from), for checks that name a line of the user's file; drivers
// ignore them.
Expected<std::vector<std::uint32_t>> CompileShaderSource(std::string source, std::string name,
                                                         std::filesystem::path include_dir, ShaderLanguage language,
                                                         ShaderStage stage = ShaderStage::kCompute,
                                                         std::vector<std::string>* sources = nullptr,
                                                         bool source_lines = false);

// One member of a buffer block as glslang lays it out: its reflected name
// ("frame.camera_world" for member camera_world of a block member `frame`)
// and its byte offset from the start of the block.
struct BufferMemberOffset {
  std::string name;
  int offset = 0;
};

// Compiles compute shader source text whose `#include "..."` directives
// resolve relative to `include_dir`, and returns the offsets of every member
// of its buffer blocks, used or not. glslang reflects only blocks the shader
// uses, so main() must touch each block of interest. For checking that the
// C++ structs of shared/params.h match the GLSL std430 layout.
Expected<std::vector<BufferMemberOffset>> ReflectBufferMembers(std::string_view source,
                                                               const std::filesystem::path& include_dir);

}  // namespace depthbench
