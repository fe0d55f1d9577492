// Instruction counts from the compiled SPIR-V: a hand-written shader with a
// known mix, and each variant's reconstruction function against the
// operations its formula in shared/variants/ spells out.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/pipeline/cells.h"
#include "bench/speed/instruction_mix.h"
#include "tests/command_runner.h"

namespace depthbench {
namespace {

std::vector<std::uint32_t> CompileText(const std::string& name, const std::string& source) {
  const std::filesystem::path path = std::filesystem::path(testing::MakeTempDir("instruction_mix")) / name;
  std::ofstream(path) << source;
  auto spirv = CompileShader(path);
  EXPECT_TRUE(spirv.ok()) << spirv.status().message();
  return spirv.ok() ? *spirv : std::vector<std::uint32_t>{};
}

InstructionMix MixOf(const std::vector<std::uint32_t>& spirv, const std::string& function) {
  auto mix = CountInstructionMix(spirv, function);
  EXPECT_TRUE(mix.ok()) << mix.status().message();
  return mix.ok() ? *mix : InstructionMix{};
}

// One of each class, in a function main() calls, and a matrix-vector and
// a matrix-matrix product in main() itself.
constexpr char kKnownShader[] = R"(#version 450
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer Values { vec4 v[]; };
float known(vec4 a, vec4 b) {
  float d = dot(a, b);
  float q = a.x / b.y;
  vec3 s = a.xyz / b.w;
  float f = fma(a.z, b.z, q);
  float r = inversesqrt(abs(d) + 1.0);
  return f * r + s.y;
}
void main() {
  v[0].x = known(v[1], v[2]);
  mat4 m = mat4(v[4], v[5], v[6], v[7]);
  v[3] = m * v[8];
  v[9] = (m * m)[0];
}
)";

TEST(InstructionMixTest, CountsAKnownShaderClassByClass) {
  const std::vector<std::uint32_t> spirv = CompileText("known.comp", kKnownShader);
  const InstructionMix known = MixOf(spirv, "known");
  EXPECT_EQ(known.fdiv, (OpCount{2, 4}));  // a.x / b.y, and a vec3 divided by b.w (3 lanes)
  EXPECT_EQ(known.dot, (OpCount{1, 4}));
  EXPECT_EQ(known.fma, (OpCount{1, 1}));
  EXPECT_EQ(known.fadd, (OpCount{2, 2}));  // abs(d) + 1, f * r + s.y
  EXPECT_EQ(known.fmul, (OpCount{1, 1}));
  EXPECT_EQ(known.extended, (OpCount{2, 2}));
  EXPECT_EQ(known.extended_by_name.at("InverseSqrt"), (OpCount{1, 1}));
  EXPECT_EQ(known.extended_by_name.at("FAbs"), (OpCount{1, 1}));
  EXPECT_EQ(known.matrix_vector, (OpCount{0, 0}));
  EXPECT_EQ(known.function_calls, 0u);

  // main() includes what it calls, plus its own products: 16 multiply-adds
  // for the 4x4 matrix times a vector, 64 for the 4x4 matrix squared.
  const InstructionMix whole = MixOf(spirv, "main");
  EXPECT_EQ(whole.function_calls, 1u);
  EXPECT_EQ(whole.matrix_vector, (OpCount{1, 16}));
  EXPECT_EQ(whole.matrix_matrix, (OpCount{1, 64}));
  EXPECT_EQ(whole.fdiv, known.fdiv);
  EXPECT_EQ(whole.fma, known.fma);
  EXPECT_GT(whole.total_instructions, known.total_instructions);
}

TEST(InstructionMixTest, RefusesMissingFunctionsAndBrokenModules) {
  const std::vector<std::uint32_t> spirv = CompileText("known.comp", kKnownShader);
  auto missing = CountInstructionMix(spirv, "unknown");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("no function named 'unknown'"), std::string::npos);
  std::vector<std::uint32_t> broken = spirv;
  broken.resize(broken.size() / 2);  // cut mid-module
  broken[0] = 0x12345678;            // and not even SPIR-V's magic number
  auto parsed = CountInstructionMix(broken, "known");
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.status().message().find("does not parse"), std::string::npos);
}

InstructionMix VariantMix(Variant variant) {
  const std::string name(Info(variant).name);
  const std::filesystem::path path =
      std::filesystem::path(DEPTHBENCH_SOURCE_DIR) / "shaders" / "speed" / (name + ".comp");
  auto spirv = CompileShader(path);
  EXPECT_TRUE(spirv.ok()) << spirv.status().message();
  if (!spirv.ok()) return {};
  return MixOf(*spirv, name + "_world_position");
}

// The divisions each formula writes, read off shared/variants/*.h (the
// harness's uv_from_pixel is not part of a reconstruction):
//   divide:     ndc.x / H, ndc.y / V, ndc_z / b, a / b, and view (a vec3) / (...)
//   reciprocal: ndc.x / H, ndc.y / V, B / (ndc_z - A)
//   pq:         ndc.x / H, ndc.y / V, 1 / (ndc_z * P + Q): its reciprocal
//   inverse_vp: world.xyz / world.w (one vec3 division)
//   volume_ray: far / -surface.z;  eye_ray: stored / ray_view.z
//   tan_aspect, frustum_ray: none
TEST(InstructionMixTest, EachVariantHasTheDivisionsItsFormulaWrites) {
  EXPECT_EQ(VariantMix(Variant::kDivide).fdiv, (OpCount{5, 7}));
  EXPECT_EQ(VariantMix(Variant::kReciprocal).fdiv, (OpCount{3, 3}));
  EXPECT_EQ(VariantMix(Variant::kPq).fdiv, (OpCount{3, 3}));
  EXPECT_EQ(VariantMix(Variant::kInverseVp).fdiv, (OpCount{1, 3}));
  EXPECT_EQ(VariantMix(Variant::kVolumeRay).fdiv, (OpCount{1, 1}));
  EXPECT_EQ(VariantMix(Variant::kEyeRay).fdiv, (OpCount{1, 1}));
  EXPECT_EQ(VariantMix(Variant::kTanAspect).fdiv, (OpCount{0, 0}));
  EXPECT_EQ(VariantMix(Variant::kFrustumRay).fdiv, (OpCount{0, 0}));
}

// The 4x4 products the formulas write: inverse_vp's inverse
// view-projection, and the camera world matrix of world_from_view for the
// variants that reconstruct in view space.
TEST(InstructionMixTest, MatrixVectorProductsAreWhereTheFormulasPutThem) {
  EXPECT_EQ(VariantMix(Variant::kInverseVp).matrix_vector, (OpCount{1, 16}));
  for (Variant v : {Variant::kDivide, Variant::kReciprocal, Variant::kPq, Variant::kTanAspect, Variant::kVolumeRay}) {
    EXPECT_EQ(VariantMix(v).matrix_vector, (OpCount{1, 16})) << Info(v).name;
  }
  // The ray variants that are already in world space have none.
  EXPECT_EQ(VariantMix(Variant::kFrustumRay).matrix_vector, (OpCount{0, 0}));
  EXPECT_EQ(VariantMix(Variant::kEyeRay).matrix_vector, (OpCount{0, 0}));
}

// No formula calls a transcendental or a fused multiply-add: glslang keeps
// a * b + c as two instructions (fusing is the driver's choice).
TEST(InstructionMixTest, FormulasUseNoExtendedInstructions) {
  for (const VariantInfo& v : AllVariants()) {
    const InstructionMix mix = VariantMix(v.id);
    EXPECT_EQ(mix.extended.instructions, 0u) << v.name;
    EXPECT_EQ(mix.fma.instructions, 0u) << v.name;
    EXPECT_GT(mix.total_instructions, 0u) << v.name;
  }
}

}  // namespace
}  // namespace depthbench
