#include "bench/backends/vulkan/variant_program.h"

#include <algorithm>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/pipeline/user_variant.h"

namespace depthbench {
namespace {

std::filesystem::path BuiltInProgram(const VariantInfo& variant, VariantPass pass,
                                     const std::filesystem::path& shader_dir) {
  const std::string file = std::string(variant.name) + ".comp";
  return pass == VariantPass::kSpeed ? shader_dir / "speed" / file : shader_dir / file;
}

const char* PassName(VariantPass pass) {
  switch (pass) {
    case VariantPass::kSpeed: return "speed";
    case VariantPass::kRaster: return "raster";
    case VariantPass::kJudged: return "judged";
    case VariantPass::kAccuracy: break;
  }
  return "accuracy";
}

// Whether the program is generated around the variant's function rather
// than read from a file of the shader directory.
bool Generated(const VariantInfo& variant, VariantPass pass) {
  return variant.user != nullptr || pass == VariantPass::kRaster || pass == VariantPass::kJudged;
}

// The program around a variant's function: for a user's, the contract's
// settings, the shared headers, the contract, the user's file; for a
// built-in one, the shared headers and its shared/variants/ header; then
// the pass.
std::string Include(const std::filesystem::path& path) { return fmt::format("#include \"{}\"\n", path.string()); }
// A built-in variant's header, shared/variants/NAME.h beside the shader directory `dir`.
std::filesystem::path BuiltInHeader(const std::filesystem::path& dir, const VariantInfo& variant) {
  return dir.parent_path() / "shared" / "variants" / (std::string(variant.name) + ".h");
}
constexpr std::string_view kGlslPreamble = "#version 450\n#extension GL_GOOGLE_include_directive : require\n";

std::string GeneratedProgram(const VariantInfo& variant, VariantPass pass, const std::filesystem::path& dir) {
  const UserShader* user = variant.user;
  const bool hlsl = user != nullptr && user->language == ShaderLanguage::kHlsl;
  std::string text = hlsl ? "" : std::string(kGlslPreamble);
  if (pass == VariantPass::kJudged) {
    // The judge counts in 64-bit integers and raises 64-bit maxima.
    text +=
        "#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require\n"
        "#extension GL_EXT_shader_atomic_int64 : require\n";
  }
  if (user == nullptr) {
    text += Include(dir / "common.glsl");
    text += Include(BuiltInHeader(dir, variant));
    text += fmt::format("#define RECONSTRUCT {}\n", ReconstructFunctionName(variant));
  } else {
    text += fmt::format(
        "#define DB_USER_ENTRY {}\n#define DB_USER_UV_BOTTOM_LEFT {}\n#define DB_USER_VIEW_LEFT_HANDED {}\n",
        user->entry, user->uv_bottom_left ? 1 : 0, user->view_left_handed ? 1 : 0);
    text += Include(hlsl ? dir / "user" / "common.hlsl" : dir / "common.glsl");
    text += Include(dir / "user" / "contract.inc");
    text += Include(user->path);
    text += fmt::format("#define RECONSTRUCT {}\n", ReconstructFunctionName(variant));
  }
  switch (pass) {
    case VariantPass::kAccuracy: text += Include(hlsl ? dir / "user" / "compute_pass.hlsl" : dir / "compute_pass.glsl"); break;
    case VariantPass::kSpeed:
      text += Include(hlsl ? dir / "user" / "speed_pass.hlsl" : dir / "speed" / "speed_pass.glsl");
      break;
    case VariantPass::kRaster:
      text += Include(hlsl ? dir / "user" / "raster_pass.hlsl" : dir / "raster" / "raster_pass.glsl");
      break;
    case VariantPass::kJudged: text += Include(dir / "judge" / "fused.comp"); break;
  }
  return text;
}

}  // namespace

std::string VariantFunctionName(const VariantInfo& variant) {
  return variant.user != nullptr ? variant.user->entry : std::string(variant.name) + "_world_position";
}

std::string ReconstructFunctionName(const VariantInfo& variant) {
  return variant.user != nullptr ? "db_user_world_position" : VariantFunctionName(variant);
}

std::string VariantProgramName(const VariantInfo& variant, VariantPass pass, const std::filesystem::path& shader_dir) {
  if (!Generated(variant, pass)) return BuiltInProgram(variant, pass, shader_dir).string();
  return fmt::format("<{}'s {} program>", variant.name, PassName(pass));
}

namespace {

// The most elements of any array type in a compiled module (counting the
// elements of nested arrays): what the source scan of a variant file
// (user_variant.cc) cannot see when a size is a #define'd name or a
// constant expression. Read from the words: OpConstant (43) gives the
// sizes, OpTypeArray (28) their element types and sizes.
std::uint64_t LargestArray(const std::vector<std::uint32_t>& words) {
  constexpr std::uint32_t kOpTypeArray = 28, kOpConstant = 43;
  std::unordered_map<std::uint32_t, std::uint64_t> constants, arrays;
  std::uint64_t largest = 0;
  for (std::size_t at = 5; at < words.size();) {
    const std::uint32_t count = words[at] >> 16, opcode = words[at] & 0xFFFFu;
    if (count == 0 || at + count > words.size()) break;
    if (opcode == kOpConstant && count >= 4) constants[words[at + 2]] = words[at + 3];
    if (opcode == kOpTypeArray && count == 4) {
      const auto length = constants.find(words[at + 3]);
      const auto inner = arrays.find(words[at + 2]);
      const std::uint64_t n = (length != constants.end() ? length->second : 0) *
                              (inner != arrays.end() ? inner->second : 1);
      arrays[words[at + 1]] = n;
      largest = std::max(largest, n);
    }
    at += count;
  }
  return largest;
}

// The line of the first loop in a compiled module whose source line lies in
// `file` (0 where none does), read from a module compiled with source lines:
// OpString (7) names the files, OpLine (8) says where the instructions after
// it came from until OpNoLine (317), and OpLoopMerge (246) opens each loop.
// The compiled module, not the text, is read, so a loop a macro writes is
// found at the line that uses the macro.
std::uint32_t FirstLoopLine(const std::vector<std::uint32_t>& words, const std::filesystem::path& file) {
  constexpr std::uint32_t kOpString = 7, kOpLine = 8, kOpLoopMerge = 246, kOpNoLine = 317;
  std::unordered_map<std::uint32_t, std::string> strings;
  std::uint32_t line_file = 0, line = 0;
  for (std::size_t at = 5; at < words.size();) {
    const std::uint32_t count = words[at] >> 16, opcode = words[at] & 0xFFFFu;
    if (count == 0 || at + count > words.size()) break;
    if (opcode == kOpString && count >= 3) {
      std::string text(reinterpret_cast<const char*>(&words[at + 2]), (count - 2) * sizeof(std::uint32_t));
      text.resize(text.find('\0') == std::string::npos ? text.size() : text.find('\0'));
      strings[words[at + 1]] = std::move(text);
    } else if (opcode == kOpLine && count >= 3) {
      line_file = words[at + 1];
      line = words[at + 2];
    } else if (opcode == kOpNoLine) {
      line_file = 0;
    } else if (opcode == kOpLoopMerge && line_file != 0) {
      const auto name = strings.find(line_file);
      if (name != strings.end() && std::filesystem::path(name->second) == file) return line;
    }
    at += count;
  }
  return 0;
}

}  // namespace

Expected<std::vector<std::uint32_t>> CompileVariant(const VariantInfo& variant, VariantPass pass,
                                                    const std::filesystem::path& shader_dir,
                                                    std::vector<std::string>* sources) {
  const UserShader* user = variant.user;
  if (pass == VariantPass::kJudged && user != nullptr && user->language == ShaderLanguage::kHlsl) {
    return Unavailable(fmt::format("the device judge's fused program is GLSL; {} is an HLSL function",
                                   user->path.string()));
  }
  if (!Generated(variant, pass)) return CompileShader(BuiltInProgram(variant, pass, shader_dir), ShaderStage::kCompute, sources);
  const bool raster = pass == VariantPass::kRaster;
  const std::filesystem::path dir = std::filesystem::absolute(shader_dir).lexically_normal();
  const std::string program = VariantProgramName(variant, pass, shader_dir);
  Expected<std::vector<std::uint32_t>> compiled =
      CompileShaderSource(GeneratedProgram(variant, pass, dir), program, dir,
                          user != nullptr ? user->language : ShaderLanguage::kGlsl,
                          raster ? ShaderStage::kFragment : ShaderStage::kCompute, sources, user != nullptr);
  // A variant is straight-line code. How long a loop runs is the data's
  // to say, and devices end one that runs too long each in its own way:
  // lavapipe leaves every loop of an invocation after 65535 iterations in
  // all and goes on with what the loop had computed (the raster form judges
  // that) or drops what the invocation would have stored (the compute form
  // finds outputs unwritten); a desktop GPU runs until its driver resets the
  // device. Refused in every form, before anything runs.
  if (user != nullptr && compiled.ok()) {
    if (const std::uint32_t line = FirstLoopLine(*compiled, user->path); line != 0) {
      return InvalidArgument(fmt::format(
          "{}:{}: a loop; a variant function must be straight-line code (unroll it): a loop that runs too "
          "long is cut short by the device (lavapipe after 65535 iterations, a GPU by resetting), and the "
          "figures would describe the cut, not the function",
          user->path.string(), line));
    }
  }
  if (user != nullptr && compiled.ok() && LargestArray(*compiled) > kMostVariantArrayElements) {
    return InvalidArgument(fmt::format("{}: the compiled function declares an array of {} elements; a variant "
                                       "function may declare arrays of at most {} (each invocation holds its own)",
                                       user->path.string(), LargestArray(*compiled), kMostVariantArrayElements));
  }
  if (user == nullptr || compiled.ok() || compiled.status().code() != StatusCode::kCompileError) return compiled;
  // A mistake in the user's file often makes the parser stumble again in
  // the generated lines after it: those follow-on messages only confuse.
  const std::string& log = compiled.status().message();
  if (log.find(user->path.string() + ":") == std::string::npos) return compiled;
  std::string kept;
  std::size_t begin = 0;
  while (begin < log.size()) {
    const std::size_t end = std::min(log.find('\n', begin), log.size());
    const std::string_view line(log.data() + begin, end - begin);
    if (!line.starts_with(program + ":")) kept += std::string(line) + "\n";
    begin = end + 1;
  }
  if (!kept.empty()) kept.pop_back();
  return CompileError(kept);
}

Expected<std::vector<std::uint32_t>> CompileRasterCells(std::span<const RasterCell> cells,
                                                        const std::filesystem::path& shader_dir,
                                                        std::vector<std::string>* sources) {
  const std::filesystem::path dir = std::filesystem::absolute(shader_dir).lexically_normal();
  std::string text = std::string(kGlslPreamble) + Include(dir / "common.glsl");
  std::string body;
  std::vector<std::string_view> names;
  for (const RasterCell& cell : cells) {
    if (cell.variant == nullptr || cell.variant->user != nullptr) {
      return InvalidArgument("a raster program of several cells runs built-in variants only");
    }
    text += Include(BuiltInHeader(dir, *cell.variant));
    body += fmt::format("  DB_RASTER_CELL_AT({}, {}, {}u)\n", ReconstructFunctionName(*cell.variant),
                        cell.light_volume ? "true" : "false", cell.cell);
    names.push_back(cell.variant->name);
  }
  text += Include(dir / "raster" / "raster_cells.glsl");
  text += "void main() {\n  DB_RASTER_CELLS_BEGIN\n" + body + "}\n";
  return CompileShaderSource(text, fmt::format("<the raster program of {}>", fmt::join(names, ", ")), dir,
                             ShaderLanguage::kGlsl, ShaderStage::kFragment, sources);
}

}  // namespace depthbench
