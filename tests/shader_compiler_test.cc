// The glslang front end of the Vulkan backend: every shader compiles, errors
// name the real file and line (inside included files too), and includes
// resolve next to the including file, so a copied tree compiles from itself.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/pipeline/cells.h"

namespace depthbench {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kSpirvMagic = 0x07230203;
const fs::path kSourceDir = DEPTHBENCH_SOURCE_DIR;

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// Replaces the first line of `path` that contains `needle` with
// `replacement`; returns its 1-based number, or 0 when no line matches.
int ReplaceLine(const fs::path& path, const std::string& needle, const std::string& replacement) {
  std::istringstream lines(ReadFile(path));
  std::string text;
  std::string line;
  int number = 0;
  int replaced = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (replaced == 0 && line.find(needle) != std::string::npos) {
      line = replacement;
      replaced = number;
    }
    text += line + "\n";
  }
  WriteFile(path, text);
  return replaced;
}

int LineCount(const fs::path& path) {
  const std::string text = ReadFile(path);
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

// Each test gets its own copy of shaders/ and shared/ to break.
class ShaderCompilerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    copy_ = fs::path(::testing::TempDir()) / ("depthbench_shaders_" + std::to_string(getpid()) + "_" + test);
    fs::remove_all(copy_);
    fs::create_directories(copy_);
    fs::copy(kSourceDir / "shaders", copy_ / "shaders", fs::copy_options::recursive);
    fs::copy(kSourceDir / "shared", copy_ / "shared", fs::copy_options::recursive);
  }
  void TearDown() override { fs::remove_all(copy_); }

  fs::path copy_;
};

TEST_F(ShaderCompilerTest, EveryShaderCompiles) {
  int compiled = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kSourceDir / "shaders")) {
    if (entry.path().extension() != ".comp") continue;
    auto spirv = CompileShader(entry.path());
    ASSERT_TRUE(spirv.ok()) << spirv.status().message();
    ASSERT_FALSE(spirv->empty());
    EXPECT_EQ(spirv->front(), kSpirvMagic) << entry.path();
    ++compiled;
  }
  EXPECT_EQ(compiled, kVariantCount);
  for (const VariantInfo& variant : AllVariants()) {
    EXPECT_TRUE(fs::exists(kSourceDir / "shaders" / (std::string(variant.name) + ".comp"))) << variant.name;
  }
}

TEST_F(ShaderCompilerTest, ErrorInIncludedFileNamesThatFileAndLine) {
  const fs::path header = copy_ / "shared" / "variants" / "divide.h";
  const int line = ReplaceLine(header, "real ndc_z =", "  real ndc_z = undeclared_depth;");
  ASSERT_GT(line, 0);

  auto spirv = CompileShader(copy_ / "shaders" / "divide.comp");
  ASSERT_FALSE(spirv.ok());
  EXPECT_EQ(spirv.status().code(), StatusCode::kCompileError);
  const std::string location = header.lexically_normal().string() + ":" + std::to_string(line) + ": error: ";
  EXPECT_NE(spirv.status().message().find(location + "'undeclared_depth' : undeclared identifier"), std::string::npos)
      << spirv.status().message();
}

TEST_F(ShaderCompilerTest, ErrorAfterIncludesNamesTheShaderAndLine) {
  const fs::path shader = copy_ / "shaders" / "pq.comp";
  WriteFile(shader, ReadFile(shader) + "int broken = ;\n");
  const int line = LineCount(shader);

  auto spirv = CompileShader(shader);
  ASSERT_FALSE(spirv.ok());
  EXPECT_EQ(spirv.status().code(), StatusCode::kCompileError);
  EXPECT_NE(spirv.status().message().find(shader.string() + ":" + std::to_string(line) + ": error: "),
            std::string::npos)
      << spirv.status().message();
}

TEST_F(ShaderCompilerTest, MissingFileIsNotFound) {
  const fs::path missing = copy_ / "shaders" / "no_such_variant.comp";
  auto spirv = CompileShader(missing);
  ASSERT_FALSE(spirv.ok());
  EXPECT_EQ(spirv.status().code(), StatusCode::kNotFound);
  EXPECT_NE(spirv.status().message().find(missing.string()), std::string::npos) << spirv.status().message();
}

TEST_F(ShaderCompilerTest, EditedCopyCompilesFromTheCopy) {
  auto original = CompileShader(kSourceDir / "shaders" / "reciprocal.comp");
  ASSERT_TRUE(original.ok()) << original.status().message();
  // An untouched copy gives the same words: the SPIR-V does not depend on
  // where the sources live, so a difference below comes from the edit.
  auto unchanged = CompileShader(copy_ / "shaders" / "reciprocal.comp");
  ASSERT_TRUE(unchanged.ok()) << unchanged.status().message();
  EXPECT_EQ(*unchanged, *original);

  const fs::path header = copy_ / "shared" / "variants" / "reciprocal.h";
  ASSERT_GT(ReplaceLine(header, "real inverse_w =",
                        "  real inverse_w = depth.coefficients.y / (ndc_z + depth.coefficients.x);"),
            0);
  auto edited = CompileShader(copy_ / "shaders" / "reciprocal.comp");
  ASSERT_TRUE(edited.ok()) << edited.status().message();
  EXPECT_NE(*edited, *original);
}

}  // namespace
}  // namespace depthbench
