#include "bench/backends/vulkan/shader_compiler.h"

#include <chrono>
#include <cstdlib>
#include <future>
#include <memory>
#include <regex>
#include <sstream>
#include <thread>
#include <type_traits>
#include <utility>

#include <fmt/format.h>
#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <glslang/build_info.h>

#include "bench/base/files.h"
#include "bench/base/interrupt.h"

namespace depthbench {
namespace {

// GlslangToSpv fills a std::vector<unsigned int>; we hand out uint32_t words.
static_assert(std::is_same_v<unsigned int, std::uint32_t>, "SPIR-V words are 32-bit unsigned int");

// Vulkan semantics and SPIR-V rules, as glslangValidator -V applies them.
constexpr EShMessages kMessages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
// Used only where a shader has no #version line.
constexpr int kDefaultGlslVersion = 450;
// The name glslang reports for source text that does not come from a file.
constexpr char kInlineSourceName[] = "<inline source>";

// glslang keeps process-wide tables that must exist before the first TShader,
// whichever thread compiles first; a function-local static runs exactly once.
void EnsureGlslangInitialized() {
  static const bool initialized = glslang::InitializeProcess();
  (void)initialized;
}

Expected<std::string> ReadSourceFile(const std::filesystem::path& path) {
  return ReadFile(path, kMaxSourceFileBytes, "shader source");
}

// Resolves `#include "name"` relative to the directory of the including
// file. glslang passes the including file's name: the root source's name for
// the top-level file, and for an included file the name this includer gave
// it, which is its normalized path, so nested includes and error messages
// see real paths.
class RelativeIncluder final : public glslang::TShader::Includer {
 public:
  RelativeIncluder(std::string root_name, std::filesystem::path root_dir, std::vector<std::string>* sources)
      : root_name_(std::move(root_name)), root_dir_(std::move(root_dir)), sources_(sources) {}

  IncludeResult* includeLocal(const char* header_name, const char* includer_name, size_t) override {
    const std::filesystem::path base =
        root_name_ == includer_name ? root_dir_ : std::filesystem::path(includer_name).parent_path();
    const std::filesystem::path path = (base / header_name).lexically_normal();
    Expected<std::string> text = ReadSourceFile(path);
    if (!text.ok()) {
      local_failure_ = text.status().message();
      return nullptr;
    }
    if (sources_ != nullptr) sources_->push_back(*text);
    auto* contents = new std::string(std::move(text).value());
    return new IncludeResult(path.string(), contents->data(), contents->size(), contents);
  }

  // glslang tries the system paths after a local include fails, and reports
  // the failure that one returns (a result with no header name, whose text
  // is the message) at the directive's file and line: here, why the local
  // file could not be included (missing, a device, too large).
  IncludeResult* includeSystem(const char*, const char*, size_t) override {
    if (local_failure_.empty()) return nullptr;
    auto* message = new std::string(std::move(local_failure_));
    local_failure_.clear();
    return new IncludeResult("", message->data(), message->size(), message);
  }

  void releaseInclude(IncludeResult* result) override {
    if (result == nullptr) return;
    delete static_cast<std::string*>(result->userData);
    delete result;
  }

 private:
  std::string root_name_;
  std::filesystem::path root_dir_;
  std::vector<std::string>* sources_;  // where to record what was read (may be null)
  std::string local_failure_;          // why the last local include failed
};

// glslang's info log says "ERROR: <file>:<line>: <message>"; compilers and
// editors expect "<file>:<line>: error: <message>". Lines without a location
// (link errors) get the root source's name; the closing error count adds
// nothing.
std::string FormatInfoLog(const std::string& log, const std::string& source_name) {
  static const std::regex kLocated(R"(^(ERROR|WARNING): (.+?):(\d+): (.*)$)");
  static const std::regex kSummary(R"(^ERROR: \d+ compilation errors?\..*$)");
  std::istringstream lines(log);
  std::string formatted;
  std::string line;
  std::smatch match;
  while (std::getline(lines, line)) {
    line.erase(line.find_last_not_of(" \t\r") + 1);
    if (line.empty() || std::regex_match(line, kSummary)) continue;
    if (!formatted.empty()) formatted += '\n';
    if (std::regex_match(line, match, kLocated)) {
      const char* severity = match[1] == "ERROR" ? "error" : "warning";
      formatted += fmt::format("{}:{}: {}: {}", match[2].str(), match[3].str(), severity, match[4].str());
    } else {
      const std::string_view kErrorPrefix = "ERROR: ";
      const std::string_view message =
          line.starts_with(kErrorPrefix) ? std::string_view(line).substr(kErrorPrefix.size()) : line;
      formatted += fmt::format("{}: error: {}", source_name, message);
    }
  }
  return formatted.empty() ? fmt::format("{}: error: glslang failed without a message", source_name) : formatted;
}

EShLanguage LanguageOf(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::kVertex: return EShLangVertex;
    case ShaderStage::kFragment: return EShLangFragment;
    case ShaderStage::kCompute: break;
  }
  return EShLangCompute;
}

// A parsed and linked shader. The program refers to the shader, so it is
// declared after it and destroyed before it.
struct LinkedShader {
  explicit LinkedShader(EShLanguage stage) : shader(stage) {}
  glslang::TShader shader;
  glslang::TProgram program;
};

// `root_name` is what glslang reports for the source (its path, for a file);
// includes in it resolve relative to `root_dir`; the text of every included
// file is appended to `sources` when it is not null.
Expected<std::unique_ptr<LinkedShader>> ParseAndLink(const std::string& source, const std::string& root_name,
                                                     const std::filesystem::path& root_dir,
                                                     std::vector<std::string>* sources = nullptr,
                                                     ShaderLanguage language = ShaderLanguage::kGlsl,
                                                     EShLanguage stage = EShLangCompute) {
  EnsureGlslangInitialized();
  auto linked = std::make_unique<LinkedShader>(stage);
  const char* text = source.data();
  const int length = static_cast<int>(source.size());
  const char* name = root_name.c_str();
  glslang::TShader& shader = linked->shader;
  shader.setStringsWithLengthsAndNames(&text, &length, &name, 1);
  const bool hlsl = language == ShaderLanguage::kHlsl;
  shader.setEnvInput(hlsl ? glslang::EShSourceHlsl : glslang::EShSourceGlsl, stage, glslang::EShClientVulkan,
                     100);
  // The raster form's stages need Vulkan 1.3 anyway; under 1.2 rules a
  // vertex stage's gl_ViewportIndex is the core capability
  // (shaderOutputViewportIndex), not an extension's. HLSL stays at 1.1:
  // glslang's HLSL front end decorates storage buffers as SPIR-V 1.3 does
  // (BufferBlock), which later versions reject, and its only graphics
  // program, a fragment stage, needs nothing newer.
  const bool graphics = stage != EShLangCompute;
  const bool vulkan_1_2 = graphics && !hlsl;
  shader.setEnvClient(glslang::EShClientVulkan, vulkan_1_2 ? glslang::EShTargetVulkan_1_2 : glslang::EShTargetVulkan_1_1);
  shader.setEnvTarget(glslang::EShTargetSpv, vulkan_1_2 ? glslang::EShTargetSpv_1_5 : glslang::EShTargetSpv_1_3);
  if (hlsl) shader.setEntryPoint("main");
  // HLSL has no combined image sampler type; the raster form's fragment
  // program binds one (shaders/user/raster_pass.hlsl), so its Texture2D is
  // made one. The compute programs' textures stay sampled images.
  if (hlsl && graphics) shader.setTextureSamplerTransformMode(EShTexSampTransUpgradeTextureRemoveSampler);
  const auto messages = static_cast<EShMessages>(kMessages | (hlsl ? EShMsgReadHlsl : EShMsgDefault));
  RelativeIncluder includer(root_name, root_dir, sources);
  if (!shader.parse(GetDefaultResources(), kDefaultGlslVersion, false, messages, includer)) {
    return CompileError(FormatInfoLog(shader.getInfoLog(), root_name));
  }
  linked->program.addShader(&shader);
  if (!linked->program.link(messages)) {
    return CompileError(FormatInfoLog(linked->program.getInfoLog(), root_name));
  }
  return linked;
}

}  // namespace

std::string GlslangVersion() {
  return fmt::format("glslang {}.{}.{}{}", GLSLANG_VERSION_MAJOR, GLSLANG_VERSION_MINOR, GLSLANG_VERSION_PATCH,
                     GLSLANG_VERSION_FLAVOR);
}

// How long a compile may take: our shaders take well under a second; a
// shader whose macros expand exponentially never ends (and grows by about
// 70 MB a second). DEPTHBENCH_COMPILE_SECONDS changes it.
double CompileSeconds() {
  const char* text = std::getenv("DEPTHBENCH_COMPILE_SECONDS");
  char* end = nullptr;
  const double value = text != nullptr ? std::strtod(text, &end) : 0.0;
  return text != nullptr && end != text && *end == '\0' && value > 0.0 ? value : 30.0;
}

Expected<std::vector<std::uint32_t>> CompileOnThisThread(const std::string& source, const std::string& name,
                                                         const std::filesystem::path& include_dir,
                                                         ShaderLanguage language, ShaderStage stage,
                                                         std::vector<std::string>* sources, bool source_lines) {
  if (sources != nullptr) sources->push_back(source);
  DB_ASSIGN_OR_RETURN(std::unique_ptr<LinkedShader> linked,
                      ParseAndLink(source, name, include_dir, sources, language, LanguageOf(stage)));
  std::vector<std::uint32_t> spirv;
  spv::SpvBuildLogger logger;
  glslang::SpvOptions options;
  options.generateDebugInfo = source_lines;
  glslang::GlslangToSpv(*linked->program.getIntermediate(LanguageOf(stage)), spirv, &logger, &options);
  if (spirv.empty()) {
    return CompileError(fmt::format("{}: error: SPIR-V generation failed: {}", name, logger.getAllMessages()));
  }
  return spirv;
}

Expected<std::vector<std::uint32_t>> CompileShader(const std::filesystem::path& path, ShaderStage stage,
                                                   std::vector<std::string>* sources) {
  DB_ASSIGN_OR_RETURN(std::string source, ReadSourceFile(path));
  return CompileShaderSource(std::move(source), path.string(), path.parent_path(), ShaderLanguage::kGlsl, stage,
                             sources);
}

Expected<std::vector<std::uint32_t>> CompileShaderSource(std::string source, std::string name,
                                                         std::filesystem::path include_dir, ShaderLanguage language,
                                                         ShaderStage stage, std::vector<std::string>* sources,
                                                         bool source_lines) {
  // glslang cannot be stopped, so the compile runs on a thread of its own
  // that is given up on when it takes too long (the program then ends
  // without waiting for it: base/interrupt.h). The thread owns what it
  // writes until it is joined.
  using Words = Expected<std::vector<std::uint32_t>>;
  auto read = std::make_shared<std::vector<std::string>>();
  std::packaged_task<Words()> task(
      [source = std::move(source), name, include_dir = std::move(include_dir), language, stage, read, source_lines] {
        return CompileOnThisThread(source, name, include_dir, language, stage, read.get(), source_lines);
      });
  std::future<Words> compiled = task.get_future();
  std::thread compiler(std::move(task));
  const double seconds = CompileSeconds();
  if (compiled.wait_for(std::chrono::duration<double>(seconds)) == std::future_status::timeout) {
    compiler.detach();
    NoteAbandonedThread();
    return CompileError(
        fmt::format("{}: compiling did not finish within {:g} s (an #include or macro that expands without end?); "
                    "DEPTHBENCH_COMPILE_SECONDS sets the limit",
                    name, seconds));
  }
  compiler.join();
  if (sources != nullptr) sources->insert(sources->end(), read->begin(), read->end());
  return compiled.get();
}

Expected<std::vector<BufferMemberOffset>> ReflectBufferMembers(std::string_view source,
                                                               const std::filesystem::path& include_dir) {
  DB_ASSIGN_OR_RETURN(std::unique_ptr<LinkedShader> linked,
                      ParseAndLink(std::string(source), kInlineSourceName, include_dir));
  glslang::TProgram& program = linked->program;
  // Unused members count too: the layout is the contract, not what one
  // shader happens to read.
  if (!program.buildReflection(EShReflectionAllBlockVariables | EShReflectionSeparateBuffers)) {
    return Internal(fmt::format("{}: glslang could not build reflection", kInlineSourceName));
  }
  std::vector<BufferMemberOffset> members;
  members.reserve(static_cast<std::size_t>(program.getNumBufferVariables()));
  for (int i = 0; i < program.getNumBufferVariables(); ++i) {
    const glslang::TObjectReflection& variable = program.getBufferVariable(i);
    members.push_back({variable.name, variable.offset});
  }
  return members;
}

}  // namespace depthbench
