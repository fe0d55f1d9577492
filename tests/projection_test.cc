// Engines' projection matrices are recognised for what they are, and a
// malformed one is refused with a message naming what is wrong.
#include "bench/pipeline/projection_matrix.h"

#include <cmath>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

namespace depthbench {
namespace {

ProjectionMatrix FromGlm(const glm::mat4& m, GraphicsApi api) {
  ProjectionMatrix out;
  const float* p = glm::value_ptr(m);  // column-major, as GLSL holds it
  for (int k = 0; k < 16; ++k) out.numbers[k] = p[k];
  out.layout = MatrixLayout::kColumnMajor;
  out.api = api;
  return out;
}

// The matrices hold float32 entries: near and far come back to float32's
// relative precision, amplified by 1 / (1 - n/f) in the far plane's
// derivation (f = b / (1 - a)); 1e-4 covers f/n up to 1e3 with room.
constexpr double kPlaneTolerance = 1e-4;

TEST(ProjectionMatrixTest, GlmPerspectiveIsStandardOpenGl) {
  const glm::mat4 m = glm::perspectiveRH_NO(glm::radians(60.0f), 16.0f / 9.0f, 0.1f, 100.0f);
  auto facts = ReadProjectionMatrix(FromGlm(m, GraphicsApi::kOpenGL));
  ASSERT_TRUE(facts.ok()) << facts.status().message();
  EXPECT_FALSE(facts->orthographic);
  EXPECT_FALSE(facts->left_handed);
  EXPECT_EQ(facts->convention, Convention::kStandardGl);
  EXPECT_NEAR(facts->near, 0.1, 0.1 * kPlaneTolerance);
  EXPECT_NEAR(facts->far, 100.0, 100.0 * kPlaneTolerance);
  EXPECT_FALSE(facts->off_centre());
  // tan(30 deg) to float32 precision.
  EXPECT_NEAR(facts->top, std::tan(M_PI / 6.0), 1e-6);
  EXPECT_NEAR(facts->right / facts->top, 16.0 / 9.0, 1e-6);

  // The same numbers for Vulkan say another clip range, so other planes:
  // the API decides what the depth row means.
  auto as_vulkan = ReadProjectionMatrix(FromGlm(m, GraphicsApi::kVulkan));
  ASSERT_TRUE(as_vulkan.ok());
  EXPECT_EQ(as_vulkan->convention, Convention::kStandard);
  EXPECT_GT(std::abs(as_vulkan->near - 0.1), 0.01);
}

TEST(ProjectionMatrixTest, ZeroToOneGlmPerspectiveIsStandardForVulkanAndClipControl) {
  const glm::mat4 m = glm::perspectiveRH_ZO(glm::radians(90.0f), 1.0f, 0.5f, 5000.0f);
  for (GraphicsApi api : {GraphicsApi::kVulkan, GraphicsApi::kOpenGLClipControl, GraphicsApi::kMetal}) {
    auto facts = ReadProjectionMatrix(FromGlm(m, api));
    ASSERT_TRUE(facts.ok()) << facts.status().message();
    EXPECT_EQ(facts->convention, Convention::kStandard) << GraphicsApiName(api);
    EXPECT_NEAR(facts->near, 0.5, 0.5 * kPlaneTolerance);
    EXPECT_NEAR(facts->far, 5000.0, 5000.0 * 1e-2);  // f/n 1e4: float32's 2^-24 times 1e4, with room
  }
}

TEST(ProjectionMatrixTest, ReversedInfiniteD3dMatrixIsRecognised) {
  // XMMatrixPerspectiveFovLH's layout for row vectors (clip = v * M), with
  // the depth column of a reversed infinite projection: z_clip = near,
  // w = view z. Its memory is M row by row, which is the column-vector
  // matrix column by column.
  const double near = 0.25, ys = 1.0 / std::tan(0.5), xs = ys / 1.5;
  ProjectionMatrix m;
  m.numbers = {xs, 0, 0, 0, 0, ys, 0, 0, 0, 0, 0, 1, 0, 0, near, 0};
  m.layout = MatrixLayout::kColumnMajor;
  m.api = GraphicsApi::kDirect3D;
  auto facts = ReadProjectionMatrix(m);
  ASSERT_TRUE(facts.ok()) << facts.status().message();
  EXPECT_TRUE(facts->left_handed);
  EXPECT_EQ(facts->convention, Convention::kReversedInf);
  EXPECT_DOUBLE_EQ(facts->near, near);
  EXPECT_TRUE(std::isinf(facts->far));
  EXPECT_DOUBLE_EQ(facts->top, std::tan(0.5));

  // A domain of it: near fixed, infinite far only, its own convention.
  Domain d;
  ASSERT_TRUE(ApplyProjection(*facts, d).ok());
  EXPECT_FALSE(d.finite_far);
  EXPECT_TRUE(d.infinite_far);
  ASSERT_TRUE(d.eye_fov.has_value());
  EXPECT_NEAR(d.eye_fov->up, 0.5 * 180.0 / M_PI, 1e-12);
  EXPECT_TRUE(d.Validate().ok());
}

TEST(ProjectionMatrixTest, OffCentreAndJitteredMatricesAreOffCentre) {
  const glm::mat4 eye = glm::frustumRH_ZO(-0.12f, 0.08f, -0.09f, 0.1f, 0.1f, 1000.0f);
  auto facts = ReadProjectionMatrix(FromGlm(eye, GraphicsApi::kVulkan));
  ASSERT_TRUE(facts.ok()) << facts.status().message();
  EXPECT_TRUE(facts->off_centre());
  EXPECT_NEAR(facts->left, -1.2, 1e-6);  // -0.12 at near 0.1
  EXPECT_NEAR(facts->right, 0.8, 1e-6);
  EXPECT_NEAR(facts->bottom, -0.9, 1e-6);

  // A TAA jitter of half a pixel at 1920 wide shifts NDC x by 1/1920.
  glm::mat4 jittered = glm::perspectiveRH_ZO(1.0f, 16.0f / 9.0f, 0.1f, 1000.0f);
  jittered[2][0] += 1.0f / 1920.0f;
  auto jitter_facts = ReadProjectionMatrix(FromGlm(jittered, GraphicsApi::kVulkan));
  ASSERT_TRUE(jitter_facts.ok());
  EXPECT_TRUE(jitter_facts->off_centre());
  const double centre_ndc = (jitter_facts->left + jitter_facts->right) / (jitter_facts->right - jitter_facts->left);
  EXPECT_NEAR(std::abs(centre_ndc), 1.0 / 1920.0, 1e-7);

  // A Vulkan engine's y flip is seen and changes nothing else.
  glm::mat4 flipped = glm::perspectiveRH_ZO(1.0f, 16.0f / 9.0f, 0.1f, 1000.0f);
  flipped[1][1] = -flipped[1][1];
  auto flip_facts = ReadProjectionMatrix(FromGlm(flipped, GraphicsApi::kVulkan));
  ASSERT_TRUE(flip_facts.ok());
  EXPECT_TRUE(flip_facts->y_flipped);
  EXPECT_FALSE(flip_facts->off_centre());
}

TEST(ProjectionMatrixTest, OrthographicMatrixMakesAnOrthographicDomain) {
  // A shadow cascade's volume, off the view axis in x, as glm builds it for
  // Vulkan; and the same for OpenGL, reversed.
  const glm::mat4 m = glm::orthoRH_ZO(-30.0f, 70.0f, -50.0f, 50.0f, 1.0f, 400.0f);
  auto facts = ReadProjectionMatrix(FromGlm(m, GraphicsApi::kVulkan));
  ASSERT_TRUE(facts.ok()) << facts.status().message();
  EXPECT_TRUE(facts->orthographic);
  EXPECT_EQ(facts->convention, Convention::kOrthoStandard);
  EXPECT_NEAR(facts->near, 1.0, 1e-5);
  EXPECT_NEAR(facts->far, 400.0, 400.0 * 1e-5);
  EXPECT_NEAR(facts->left, -30.0, 1e-4);
  EXPECT_NEAR(facts->right, 70.0, 1e-4);
  Domain d;
  ASSERT_TRUE(ApplyProjection(*facts, d).ok());
  ASSERT_TRUE(d.orthographic.has_value());
  EXPECT_NEAR(d.orthographic->left, -30.0, 1e-4);
  EXPECT_FALSE(d.eye_fov.has_value());
  EXPECT_FALSE(d.infinite_far);
  EXPECT_TRUE(d.OffCentre());
  EXPECT_TRUE(d.Validate().ok());

  // Reversed: near and far swapped in glm's call maps near to 1.
  const glm::mat4 reversed = glm::orthoRH_NO(-50.0f, 50.0f, -50.0f, 50.0f, 400.0f, 1.0f);
  auto gl = ReadProjectionMatrix(FromGlm(reversed, GraphicsApi::kOpenGL));
  ASSERT_TRUE(gl.ok()) << gl.status().message();
  EXPECT_EQ(gl->convention, Convention::kOrthoReversedGl);
  EXPECT_NEAR(gl->near, 1.0, 1e-4);
}

void ExpectRefused(const ProjectionMatrix& m, const std::string& names) {
  auto facts = ReadProjectionMatrix(m);
  ASSERT_FALSE(facts.ok()) << "accepted: " << names;
  EXPECT_NE(facts.status().message().find(names), std::string::npos) << facts.status().message();
}

TEST(ProjectionMatrixTest, MalformedMatricesAreRefusedNamingTheFault) {
  const glm::mat4 good = glm::perspectiveRH_ZO(1.0f, 1.5f, 0.1f, 100.0f);
  glm::mat4 oblique = good;
  oblique[0][2] = 0.3f;  // clip z gains an x term: Lengyel's oblique near plane
  ExpectRefused(FromGlm(oblique, GraphicsApi::kVulkan), "oblique near plane");
  ExpectRefused(FromGlm(oblique, GraphicsApi::kVulkan), "m20 = 0.3");

  ProjectionMatrix transposed = FromGlm(good, GraphicsApi::kVulkan);
  transposed.layout = MatrixLayout::kRowMajor;
  ExpectRefused(transposed, "is the layout right");

  glm::mat4 no_w = good;
  no_w[2][3] = 0.0f;
  ExpectRefused(FromGlm(no_w, GraphicsApi::kVulkan), "w row");

  glm::mat4 behind = good;
  behind[3][2] = -behind[3][2];  // near and far behind the eye
  ExpectRefused(FromGlm(behind, GraphicsApi::kVulkan), "not in front of the eye");

  ProjectionMatrix nan = FromGlm(good, GraphicsApi::kVulkan);
  nan.numbers[5] = NAN;
  ExpectRefused(nan, "finite");
}

TEST(ProjectionMatrixTest, FlagNamesApiLayoutAndSixteenNumbers) {
  auto m = ParseProjectionFlag("d3d:column-major:1,0,0,0,0,1.5,0,0,0,0,0,1,0,0,0.1,0");
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->api, GraphicsApi::kDirect3D);
  EXPECT_EQ(m->numbers[14], 0.1);
  EXPECT_FALSE(ParseProjectionFlag("dx12:column-major:1").ok());
  auto short_list = ParseProjectionFlag("vulkan:row-major:1,2,3");
  ASSERT_FALSE(short_list.ok());
  EXPECT_NE(short_list.status().message().find("3 numbers, not 16"), std::string::npos)
      << short_list.status().message();
  EXPECT_FALSE(ParseProjectionFlag("vulkan:row-major:1,0,0,0,0,1,0,0,0,0,0,1,0,0,1,0,7").ok());
}

TEST(ProjectionMatrixTest, EveryProjectiveConventionNamesWhatEachApiMustDo) {
  EXPECT_NE(ApiRecipe(Convention::kReversed).find("glClipControl"), std::string::npos);
  EXPECT_NE(ApiRecipe(Convention::kStandardGl).find("never store this"), std::string::npos);
  EXPECT_NE(ApiRecipe(Convention::kReversedInf).find("infinity"), std::string::npos);
  EXPECT_NE(ApiRecipe(Convention::kLinear).find("any API"), std::string::npos);
}

}  // namespace
}  // namespace depthbench
