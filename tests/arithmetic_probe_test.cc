// The arithmetic probes (bench/backends/vulkan/arithmetic_probe.h): the
// rewritten modules are valid SPIR-V for Vulkan, every contractible result
// is decorated, no float32 division is left, and on lavapipe (which fuses
// nothing and divides correctly rounded) the probes change no position: any
// difference they make on another device is that device's doing.
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <spirv-tools/libspirv.h>
#include <glslang/SPIRV/spirv.hpp>

#include "bench/backends/factory.h"
#include "bench/backends/vulkan/arithmetic_probe.h"
#include "bench/backends/vulkan/variant_program.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"

namespace depthbench {
namespace {

const std::filesystem::path kShaders = std::filesystem::path(DEPTHBENCH_SOURCE_DIR) / "shaders";

struct Counts {
  int contractible = 0, no_contraction = 0, fdiv32 = 0, fdiv64 = 0;
};

// What a module holds, by a walk over its instructions.
Counts CountModule(const std::vector<std::uint32_t>& m) {
  std::map<std::uint32_t, std::uint32_t> width;  // float or float-vector type -> component width
  Counts c;
  for (std::size_t at = 5; at < m.size(); at += m[at] >> 16) {
    const auto op = static_cast<spv::Op>(m[at] & 0xffff);
    const std::uint32_t* w = m.data() + at;
    if (op == spv::OpTypeFloat) width[w[1]] = w[2];
    if (op == spv::OpTypeVector && width.count(w[2]) != 0) width[w[1]] = width[w[2]];
    if (op == spv::OpDecorate && w[2] == spv::DecorationNoContraction) ++c.no_contraction;
    if (op == spv::OpFAdd || op == spv::OpFSub || op == spv::OpFMul || op == spv::OpFDiv || op == spv::OpFNegate ||
        op == spv::OpVectorTimesScalar || op == spv::OpMatrixTimesVector || op == spv::OpMatrixTimesScalar ||
        op == spv::OpVectorTimesMatrix || op == spv::OpMatrixTimesMatrix || op == spv::OpDot || op == spv::OpFRem ||
        op == spv::OpFMod) {
      ++c.contractible;
    }
    if (op == spv::OpFDiv) ++(width[w[1]] == 64 ? c.fdiv64 : c.fdiv32);
  }
  return c;
}

std::string Validate(const std::vector<std::uint32_t>& m) {
  spv_context context = spvContextCreate(SPV_ENV_VULKAN_1_1);
  spv_const_binary_t binary{m.data(), m.size()};
  spv_diagnostic diagnostic = nullptr;
  const spv_result_t result = spvValidate(context, &binary, &diagnostic);
  std::string message = result == SPV_SUCCESS ? "" : (diagnostic != nullptr ? diagnostic->error : "invalid");
  spvDiagnosticDestroy(diagnostic);
  spvContextDestroy(context);
  return message;
}

TEST(ArithmeticProbeTest, EveryVariantStaysValidAndLosesItsFreedoms) {
  for (const VariantInfo& variant : AllVariants()) {
    auto compiled = CompileVariant(variant, VariantPass::kAccuracy, kShaders);
    ASSERT_TRUE(compiled.ok()) << compiled.status().message();
    const Counts before = CountModule(*compiled);
    ASSERT_GT(before.fdiv32, 0) << variant.name << ": every variant divides (at least by w or by the resolution)";
    EXPECT_EQ(before.no_contraction, 0);
    for (std::uint32_t probes : {1u, 2u, 3u, 4u, 5u}) {
      auto probed = ApplyArithmeticProbes(*compiled, probes);
      ASSERT_TRUE(probed.ok()) << probed.status().message();
      EXPECT_EQ(Validate(*probed), "") << variant.name << " " << ArithmeticProbesName(probes);
      const Counts after = CountModule(*probed);
      if ((probes & kNoContraction) != 0) {
        EXPECT_EQ(after.no_contraction, before.contractible) << variant.name;
      }
      if ((probes & (kExactDivision | kWorstDivision)) != 0) {
        EXPECT_EQ(after.fdiv32, 0) << variant.name;
        EXPECT_EQ(after.fdiv64, before.fdiv32) << variant.name;
      }
    }
  }
}

TEST(ArithmeticProbeTest, NamesParseBothWays) {
  EXPECT_EQ(*ParseArithmeticProbes("no-contraction+exact-division"), kNoContraction | kExactDivision);
  EXPECT_EQ(ArithmeticProbesName(kNoContraction | kExactDivision), "no-contraction+exact-division");
  EXPECT_EQ(*ParseArithmeticProbes("worst-division+no-contraction"), kWorstDivision | kNoContraction);
  EXPECT_EQ(ArithmeticProbesName(kWorstDivision), "worst-division");
  EXPECT_FALSE(ParseArithmeticProbes("no-fma").ok());
  EXPECT_FALSE(ApplyArithmeticProbes(std::vector<std::uint32_t>{1, 2, 3}, kNoContraction).ok());
}

TEST(ArithmeticProbeTest, LavapipeGivesTheSamePositionsWithAndWithoutProbes) {
  auto plain = MakeBackend("vulkan", BackendOptions{});
  auto probed = MakeBackend("vulkan:no-contraction+exact-division", BackendOptions{});
  ASSERT_TRUE(plain.ok() && probed.ok()) << (plain.ok() ? probed.status().message() : plain.status().message());
  EXPECT_EQ((*probed)->name(), "vulkan:no-contraction+exact-division");
  const std::vector<Cell> cells = AllCells();
  const RunLayout layout = MakeRunLayout(cells);
  Domain domain;
  const Sampler sampler(11, domain);
  const BatchBuilder builder(sampler, layout.encodings);
  ThreadPool pool;
  Batch batch;
  builder.Build(0, 2048, batch, pool);
  ASSERT_TRUE((*plain)->Prepare(layout.cells).ok());
  ASSERT_TRUE((*probed)->Prepare(layout.cells).ok());
  EXPECT_NE((*plain)->program().hash, (*probed)->program().hash);
  std::vector<std::uint32_t> which(layout.cells.size());
  std::iota(which.begin(), which.end(), 0u);
  std::vector<float> a, b;
  auto want = (*plain)->Run(batch, which, a);
  auto got = (*probed)->Run(batch, which, b);
  ASSERT_TRUE(want.ok() && got.ok());
  ASSERT_EQ(want->size(), got->size());
  EXPECT_EQ(std::memcmp(want->data(), got->data(), want->size_bytes()), 0);
}

}  // namespace
}  // namespace depthbench
