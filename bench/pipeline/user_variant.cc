#include "bench/pipeline/user_variant.h"

#include <algorithm>
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
  bool declared = false;
  while (!declared && number < kDeclarationLines && std::getline(lines, line)) {
    ++number;
    const std::size_t at = line.find(kMarker);
    if (at == std::string::npos) continue;
    declared = true;
    std::istringstream words(line.substr(at + kMarker.size()));
    std::string word;
    while (words >> word) {
      const std::size_t equals = word.find('=');
      const std::string key = word.substr(0, equals);
      const std::string value = equals == std::string::npos ? "" : word.substr(equals + 1);
      Status applied = ApplyKey(key, value, shader, input, name);
      if (!applied.ok()) return InvalidArgument(fmt::format("{}:{}: {}", given, number, applied.message()));
    }
  }
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
