#include "bench/pipeline/user_variant.h"

#include <algorithm>
#include <cctype>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/suggest.h"

namespace depthbench {
namespace {

// The declaration is looked for in the file's first lines, where a header
// comment is.
constexpr int kDeclarationLines = 40;
constexpr std::string_view kMarker = "// depthbench:";

std::string Suggestion(std::string_view word, std::vector<std::string> names) { return DidYouMean(word, names); }

bool IsName(std::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

Expected<DepthInput> ParseInput(std::string_view value) {
  if (value == "hardware") return DepthInput::kHardware;
  if (value == "linear") return DepthInput::kLinear;
  if (value == "viewz") return DepthInput::kViewZ;
  return InvalidArgument(fmt::format("input={}: allowed: hardware, linear, viewz{}", value,
                                     Suggestion(value, {"hardware", "linear", "viewz"})));
}

// One `key=value` of the declaration line into `shader`, `input` and `name`.
Status ApplyKey(std::string_view key, std::string_view value, UserShader& shader, std::optional<DepthInput>& input,
                std::string& name) {
  auto choose = [&](std::string_view first, std::string_view second, bool& is_second) -> Status {
    if (value != first && value != second) {
      return InvalidArgument(fmt::format("{}={}: allowed: {}, {}", key, value, first, second));
    }
    is_second = value == second;
    return Status::Ok();
  };
  if (key == "input") return StoreInto(ParseInput(value), input.emplace());
  if (key == "uv") return choose("top-left", "bottom-left", shader.uv_bottom_left);
  if (key == "view") return choose("right-handed", "left-handed", shader.view_left_handed);
  if (key == "entry" || key == "name") {
    const bool identifier =
        !value.empty() && !(value[0] >= '0' && value[0] <= '9') && std::all_of(value.begin(), value.end(), [](char c) {
          return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
        });
    if (!identifier || (key == "name" && !IsName(value))) {
      return InvalidArgument(fmt::format("{}={}: not a {}", key, value,
                                         key == "entry" ? "function name" : "name of lower-case letters, digits, _"));
    }
    (key == "entry" ? shader.entry : name) = std::string(value);
    return Status::Ok();
  }
  return InvalidArgument(fmt::format("unknown key '{}'; allowed: input, entry, uv, view, name{}", key,
                                     Suggestion(key, {"input", "entry", "uv", "view", "name"})));
}

const char* kExample = "// depthbench: input=hardware entry=reconstruct uv=top-left view=right-handed";

// The words of a shader source outside comments and preprocessor lines,
// each with its line; a number in brackets (an array's size) is given as
// the word "[" and its value.
struct SourceToken {
  std::string word;
  int line = 0;
  std::uint64_t size = 0;  // for "["
};
std::vector<SourceToken> Tokens(const std::string& text) {
  std::vector<SourceToken> tokens;
  int line = 1;
  bool block_comment = false;
  bool line_start = true;  // only blanks since the line began
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (line_start && !block_comment && c == '#') {  // a preprocessor line
      while (i < text.size() && text[i] != '\n') ++i;
      continue;
    }
    if (c != ' ' && c != '\t') line_start = c == '\n';
    if (c == '\n') {
      ++line;
      ++i;
    } else if (block_comment) {
      block_comment = text.compare(i, 2, "*/") != 0;
      i += block_comment ? 1 : 2;
    } else if (text.compare(i, 2, "/*") == 0) {
      block_comment = true;
      i += 2;
    } else if (text.compare(i, 2, "//") == 0) {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      std::size_t end = i;
      while (end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_')) ++end;
      tokens.push_back({text.substr(i, end - i), line, 0});
      i = end;
    } else if (c == '[') {
      std::size_t end = i + 1;
      while (end < text.size() && (text[end] == ' ' || text[end] == '\t')) ++end;
      std::uint64_t size = 0;
      bool digits = false;
      for (; end < text.size() && std::isdigit(static_cast<unsigned char>(text[end])); ++end) {
        digits = true;
        size = std::min<std::uint64_t>(size * 10 + static_cast<std::uint64_t>(text[end] - '0'), UINT64_MAX / 20);
      }
      if (digits) tokens.push_back({"[", line, size});
      ++i;
    } else {
      ++i;
    }
  }
  return tokens;
}

// The names a source #defines: a port's `#define float3 vec3` makes
// float3 the file's own word.
std::vector<std::string> DefinedNames(const std::string& text) {
  std::vector<std::string> names;
  std::istringstream lines(text);
  std::string directive;
  while (std::getline(lines, directive)) {
    std::istringstream words(directive);
    std::string hash, name;
    if (words >> hash >> name && (hash == "#define" || (hash == "#" && name == "define" && words >> name))) {
      names.push_back(name.substr(0, name.find('(')));
    }
  }
  return names;
}


// What a variant file may not hold, checked before it is compiled; the
// error names the line.
//  - Words of the other language: a GLSL type or layout in a file named
//    .hlsl, an HLSL type or cbuffer in a file named .glsl. glslang's HLSL
//    front end accepts much GLSL and gives it another meaning (`m * v` is
//    component-wise there), so the extension alone must not decide. Only
//    types and declarations are looked for (a function of the user's may
//    be called `saturate` or `mix` in either language), and a name the
//    file #defines is its own.
//  - Resources: a variant is a function of its arguments and the named
//    constants. A buffer, image or shared-memory declaration could take a
//    binding of the bench's own (set 0, binding 5 is the positions every
//    cell writes) and change other cells' figures.
//  - Arrays over kMostVariantArrayElements elements.
Status CheckVariantSource(const std::string& text, ShaderLanguage named, const std::string& given,
                          const std::string& extension) {
  static const std::vector<std::string> kGlslOnly = {"vec2",  "vec3",  "vec4",  "mat3",  "mat4",
                                                     "uvec2", "ivec2", "dvec3", "dmat4", "layout"};
  static const std::vector<std::string> kHlslOnly = {"float2", "float3", "float4", "float3x3", "float4x4",
                                                     "half2",  "half3",  "half4",  "cbuffer"};
  static const std::vector<std::string> kGlslResources = {"layout",  "buffer",    "uniform",  "shared",
                                                          "image2D", "sampler2D", "texture2D"};
  static const std::vector<std::string> kHlslResources = {"register",
                                                          "groupshared",
                                                          "cbuffer",
                                                          "tbuffer",
                                                          "ConstantBuffer",
                                                          "StructuredBuffer",
                                                          "RWStructuredBuffer",
                                                          "ByteAddressBuffer",
                                                          "RWByteAddressBuffer",
                                                          "Texture2D",
                                                          "RWTexture2D",
                                                          "SamplerState",
                                                          "vk"};
  const bool hlsl = named == ShaderLanguage::kHlsl;
  std::vector<std::string> foreign = hlsl ? kGlslOnly : kHlslOnly;
  std::vector<std::string> resources = hlsl ? kHlslResources : kGlslResources;
  for (const std::string& name : DefinedNames(text)) {
    std::erase(foreign, name);
    std::erase(resources, name);
  }
  const auto has = [](const std::vector<std::string>& list, const std::string& word) {
    return std::find(list.begin(), list.end(), word) != list.end();
  };
  for (const SourceToken& t : Tokens(text)) {
    if (t.word == "[") {
      if (t.size > kMostVariantArrayElements) {
        return InvalidArgument(
            fmt::format("{}:{}: an array of {} elements; a variant function may declare arrays "
                        "of at most {} (each invocation holds its own)",
                        given, t.line, t.size, kMostVariantArrayElements));
      }
    } else if (has(foreign, t.word)) {
      return InvalidArgument(fmt::format(
          "{}:{}: '{}' is {}, but the file is named {}: it would be compiled as {}, "
          "where it means something else or nothing; rename the file {}",
          given, t.line, t.word, hlsl ? "GLSL" : "HLSL", extension, hlsl ? "HLSL" : "GLSL", hlsl ? ".glsl" : ".hlsl"));
    } else if (has(resources, t.word)) {
      return InvalidArgument(
          fmt::format("{}:{}: '{}' declares a resource (a buffer, image, binding or shared "
                      "memory); a variant is a function of its arguments and the constants "
                      "docs/variant-files.md lists, and may not reach the bench's bindings",
                      given, t.line, t.word));
    }
  }
  return Status::Ok();
}

// The absolute, normal form of a path the user gave.
std::filesystem::path Absolute(const std::string& given) {
  std::error_code error;
  return std::filesystem::absolute(given, error).lexically_normal();
}

}  // namespace

Expected<UserVariant> ReadVariantFile(const std::string& given) {
  const std::filesystem::path path = Absolute(given);
  UserShader shader;
  shader.path = path;
  const std::string extension = path.extension().string();
  if (extension == ".hlsl") {
    shader.language = ShaderLanguage::kHlsl;
  } else if (extension != ".glsl") {
    return InvalidArgument(
        fmt::format("--variant-file {}: the file's extension says its language: .glsl or .hlsl", given));
  }
  DB_ASSIGN_OR_RETURN(const std::string text, ReadFile(path, kMaxSourceFileBytes, "--variant-file"));
  // Visual Studio saves UTF-8 with a byte-order mark; glslang reads it as
  // a stray character at the file's first token.
  if (text.starts_with("\xEF\xBB\xBF")) {
    return InvalidArgument(fmt::format(
        "{}:1: the file starts with a UTF-8 byte-order mark, which the shader compiler cannot read; save it as "
        "UTF-8 without a signature (Visual Studio: File > Save As > Save with Encoding)",
        given));
  }
  DB_RETURN_IF_ERROR(CheckVariantSource(text, shader.language, given, extension));
  // The path goes into an #include "..." line of the generated program.
  if (path.string().find_first_of("\"\n\\") != std::string::npos) {
    return InvalidArgument(
        fmt::format("--variant-file {}: a path with '\"', '\\\\' or a line break cannot be "
                    "included; copy the file to a plainer path",
                    given));
  }
  std::optional<DepthInput> input;
  std::string name = path.stem().string();
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  int declared_at = 0;  // the contract's line; 0 before it is found
  while (std::getline(lines, line)) {
    ++number;
    const std::size_t at = line.find(kMarker);
    if (at == std::string::npos) continue;
    // One contract a file: a second line would otherwise be ignored, and
    // whichever the author edited last might not be the one that counts.
    if (declared_at != 0) {
      return InvalidArgument(
          fmt::format("{}:{}: a second '// depthbench:' line (the first is line {}); a file "
                      "declares one contract",
                      given, number, declared_at));
    }
    if (number > kDeclarationLines) break;  // too late to be the header's; said below
    declared_at = number;
    std::istringstream words(line.substr(at + kMarker.size()));
    std::string word;
    std::vector<std::string> keys;
    while (words >> word) {
      const std::size_t equals = word.find('=');
      const std::string key = word.substr(0, equals);
      const std::string value = equals == std::string::npos ? "" : word.substr(equals + 1);
      if (std::find(keys.begin(), keys.end(), key) != keys.end()) {
        return InvalidArgument(
            fmt::format("{}:{}: '{}' is given twice; a contract gives each key once", given, number, key));
      }
      keys.push_back(key);
      Status applied = ApplyKey(key, value, shader, input, name);
      if (!applied.ok()) return InvalidArgument(fmt::format("{}:{}: {}", given, number, applied.message()));
    }
  }
  const bool declared = declared_at != 0;
  if (!declared || !input) {
    return InvalidArgument(
        fmt::format("{}: {} the contract in its first {} lines; for example\n  {}\n(see docs/variant-files.md)", given,
                    declared ? "the '// depthbench:' line does not say input=hardware|linear|viewz; it must, to declare"
                             : "no '// depthbench:' line declares",
                    kDeclarationLines, kExample));
  }
  if (!IsName(name)) {
    return InvalidArgument(
        fmt::format("{}: '{}' cannot name a variant (lower-case letters, digits and _); "
                    "rename the file or declare name=... on the '// depthbench:' line",
                    given, name));
  }
  UserVariant variant;
  variant.shader = shader;
  variant.name = name;
  variant.input = *input;
  variant.source = "user shader " + path.filename().string();
  variant.idea = fmt::format("{} function {}() from {}", shader.language == ShaderLanguage::kHlsl ? "HLSL" : "GLSL",
                             shader.entry, path.string());
  return variant;
}

Expected<std::unique_ptr<const Catalogue>> MakeCatalogue(const std::vector<std::string>& paths) {
  std::vector<UserVariant> variants;
  for (const std::string& given : paths) {
    const std::filesystem::path path = Absolute(given);
    const bool again =
        std::any_of(variants.begin(), variants.end(), [&](const UserVariant& v) { return v.shader.path == path; });
    if (again) continue;
    DB_ASSIGN_OR_RETURN(UserVariant variant, ReadVariantFile(given));
    const bool built_in = std::any_of(AllVariants().begin(), AllVariants().end(),
                                      [&](const VariantInfo& v) { return v.name == variant.name; });
    const bool taken =
        std::any_of(variants.begin(), variants.end(), [&](const UserVariant& v) { return v.name == variant.name; });
    if (built_in || taken) {
      return InvalidArgument(
          fmt::format("{}: the variant name '{}' is taken{}; declare another with name=... on "
                      "the '// depthbench:' line",
                      given, variant.name, taken ? " by another --variant-file" : ""));
    }
    if (variants.size() >= static_cast<std::size_t>(kMostUserVariants)) {
      return InvalidArgument(fmt::format("--variant-file: at most {} files", kMostUserVariants));
    }
    variants.push_back(std::move(variant));
  }
  return std::make_unique<const Catalogue>(std::move(variants));
}

}  // namespace depthbench
