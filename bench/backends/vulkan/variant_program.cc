#include "bench/backends/vulkan/variant_program.h"

#include <fmt/format.h>

#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/pipeline/user_variant.h"

namespace depthbench {
namespace {

std::filesystem::path BuiltInProgram(Variant variant, VariantPass pass, const std::filesystem::path& shader_dir) {
  const std::string file = std::string(Info(variant).name) + ".comp";
  return pass == VariantPass::kSpeed ? shader_dir / "speed" / file : shader_dir / file;
}

// The program around a user's function: the contract's settings, the
// shared headers, the contract, the user's file, then the pass.
std::string UserProgram(const UserShader& user, VariantPass pass, const std::filesystem::path& dir) {
  const bool hlsl = user.language == ShaderLanguage::kHlsl;
  auto include = [](const std::filesystem::path& path) { return fmt::format("#include \"{}\"\n", path.string()); };
  std::string text = hlsl ? "" : "#version 450\n#extension GL_GOOGLE_include_directive : require\n";
  text +=
      fmt::format("#define DB_USER_ENTRY {}\n#define DB_USER_UV_BOTTOM_LEFT {}\n#define DB_USER_VIEW_LEFT_HANDED {}\n",
                  user.entry, user.uv_bottom_left ? 1 : 0, user.view_left_handed ? 1 : 0);
  text += include(hlsl ? dir / "user" / "common.hlsl" : dir / "common.glsl");
  text += include(dir / "user" / "contract.inc");
  text += include(user.path);
  text += "#define RECONSTRUCT db_user_world_position\n";
  const bool speed = pass == VariantPass::kSpeed;
  text += include(hlsl ? dir / "user" / (speed ? "speed_pass.hlsl" : "compute_pass.hlsl")
                       : (speed ? dir / "speed" / "speed_pass.glsl" : dir / "compute_pass.glsl"));
  return text;
}

}  // namespace

std::string VariantFunctionName(Variant variant) {
  const VariantInfo& info = Info(variant);
  return info.user != nullptr ? info.user->entry : std::string(info.name) + "_world_position";
}

std::string VariantProgramName(Variant variant, VariantPass pass, const std::filesystem::path& shader_dir) {
  if (Info(variant).user == nullptr) return BuiltInProgram(variant, pass, shader_dir).string();
  return fmt::format("<{}'s {} program>", Info(variant).name, pass == VariantPass::kSpeed ? "speed" : "accuracy");
}

Expected<std::vector<std::uint32_t>> CompileVariant(Variant variant, VariantPass pass,
                                                    const std::filesystem::path& shader_dir,
                                                    std::vector<std::string>* sources) {
  const UserShader* user = Info(variant).user;
  if (user == nullptr) return CompileComputeShader(BuiltInProgram(variant, pass, shader_dir), sources);
  const std::filesystem::path dir = std::filesystem::absolute(shader_dir).lexically_normal();
  const std::string program = VariantProgramName(variant, pass, shader_dir);
  Expected<std::vector<std::uint32_t>> compiled =
      CompileComputeSource(UserProgram(*user, pass, dir), program, dir, user->language, sources);
  if (compiled.ok() || compiled.status().code() != StatusCode::kCompileError) return compiled;
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

}  // namespace depthbench
