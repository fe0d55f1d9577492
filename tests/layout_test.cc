// The std430 contract of shared/params.h: the C++ structs the host uploads
// must have exactly the member offsets and sizes glslang gives the GLSL
// structs. Every member is listed, so a reordered, added or differently
// padded member fails here before it scrambles a GPU run.
#include <cstddef>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/numerics/formulas.h"

namespace depthbench {
namespace {

// Each struct sits in its own block, followed by a uint whose offset is the
// struct's std430 size (its array stride). main() touches every block:
// glslang reflects only the blocks a shader uses.
constexpr char kLayoutShader[] = R"(#version 450
#extension GL_GOOGLE_include_directive : require
#include "compat.h"
#include "params.h"
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer FrameBlock { FrameParams frame; uint frame_end; };
layout(std430, binding = 1) buffer DepthBlock { DepthParams depth; uint depth_end; };
layout(std430, binding = 2) buffer PassBlock { PassConstants pass; uint pass_end; };
layout(std430, binding = 3) buffer CellBlock { CellSlice cell; uint cell_end; };
layout(std430, binding = 4) buffer RasterBlock { RasterSample raster; uint raster_end; };
layout(std430, binding = 5) buffer DrawBlock { RasterConstants draw; uint draw_end; };
void main() {
  frame_end = 0u;
  depth_end = 0u;
  pass_end = 0u;
  cell_end = 0u;
  raster_end = 0u;
  draw_end = 0u;
}
)";

class LayoutTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto members = ReflectBufferMembers(kLayoutShader, DEPTHBENCH_SOURCE_DIR "/shared");
    ASSERT_TRUE(members.ok()) << members.status().message();
    for (const BufferMemberOffset& member : *members) offsets_[member.name] = member.offset;
  }

  // The reflected offset of `name`, or -1 when glslang does not know it.
  int Offset(const std::string& name) const {
    auto it = offsets_.find(name);
    return it == offsets_.end() ? -1 : it->second;
  }

  // How many reflected members belong to the block member `prefix`.
  int MembersOf(const std::string& prefix) const {
    int count = 0;
    for (const auto& [name, offset] : offsets_) count += name.starts_with(prefix + ".") ? 1 : 0;
    return count;
  }

  std::map<std::string, int> offsets_;
};

// Expects GLSL member `instance.member` at offsetof(f32::Struct, member).
#define EXPECT_MEMBER_AT(instance, Struct, member) \
  EXPECT_EQ(Offset(#instance "." #member), static_cast<int>(offsetof(f32::Struct, member))) << #Struct "::" #member

TEST_F(LayoutTest, FrameParamsMatchesStd430) {
  EXPECT_MEMBER_AT(frame, FrameParams, camera_world);
  EXPECT_MEMBER_AT(frame, FrameParams, camera_position);
  EXPECT_MEMBER_AT(frame, FrameParams, lens);
  EXPECT_MEMBER_AT(frame, FrameParams, resolution);
  EXPECT_MEMBER_AT(frame, FrameParams, frustum_ray_origin);
  EXPECT_MEMBER_AT(frame, FrameParams, frustum_ray_du);
  EXPECT_MEMBER_AT(frame, FrameParams, frustum_ray_dv);
  EXPECT_MEMBER_AT(frame, FrameParams, volume_position_origin);
  EXPECT_MEMBER_AT(frame, FrameParams, volume_position_du);
  EXPECT_MEMBER_AT(frame, FrameParams, volume_position_dv);
  EXPECT_MEMBER_AT(frame, FrameParams, eye_ray_view_origin);
  EXPECT_MEMBER_AT(frame, FrameParams, eye_ray_view_du);
  EXPECT_MEMBER_AT(frame, FrameParams, eye_ray_view_dv);
  EXPECT_MEMBER_AT(frame, FrameParams, eye_ray_world_origin);
  EXPECT_MEMBER_AT(frame, FrameParams, eye_ray_world_du);
  EXPECT_MEMBER_AT(frame, FrameParams, eye_ray_world_dv);
  EXPECT_MEMBER_AT(frame, FrameParams, world_view);
  EXPECT_MEMBER_AT(frame, FrameParams, lens_centre);
  EXPECT_MEMBER_AT(frame, FrameParams, clip_planes);
  EXPECT_EQ(MembersOf("frame"), 19) << "a FrameParams member is not listed above";
  EXPECT_EQ(Offset("frame_end"), static_cast<int>(sizeof(f32::FrameParams)));
}

TEST_F(LayoutTest, DepthParamsMatchesStd430) {
  EXPECT_MEMBER_AT(depth, DepthParams, inverse_view_projection);
  EXPECT_MEMBER_AT(depth, DepthParams, view_projection);
  EXPECT_MEMBER_AT(depth, DepthParams, coefficients);
  EXPECT_MEMBER_AT(depth, DepthParams, convention);
  EXPECT_MEMBER_AT(depth, DepthParams, reserved0);
  EXPECT_MEMBER_AT(depth, DepthParams, reserved1);
  EXPECT_MEMBER_AT(depth, DepthParams, reserved2);
  EXPECT_EQ(MembersOf("depth"), 7) << "a DepthParams member is not listed above";
  EXPECT_EQ(Offset("depth_end"), static_cast<int>(sizeof(f32::DepthParams)));
}

TEST_F(LayoutTest, PassConstantsMatchesStd430) {
  EXPECT_MEMBER_AT(pass, PassConstants, slice_length);
  EXPECT_MEMBER_AT(pass, PassConstants, samples_per_frame);
  EXPECT_MEMBER_AT(pass, PassConstants, conventions_per_frame);
  EXPECT_MEMBER_AT(pass, PassConstants, first_in_frame);
  EXPECT_MEMBER_AT(pass, PassConstants, frame_count);
  EXPECT_MEMBER_AT(pass, PassConstants, first_cell);
  EXPECT_MEMBER_AT(pass, PassConstants, reserved0);
  EXPECT_MEMBER_AT(pass, PassConstants, reserved1);
  EXPECT_EQ(MembersOf("pass"), 8) << "a PassConstants member is not listed above";
  EXPECT_EQ(Offset("pass_end"), static_cast<int>(sizeof(f32::PassConstants)));
}

TEST_F(LayoutTest, CellSliceMatchesStd430) {
  EXPECT_MEMBER_AT(cell, CellSlice, convention_slot);
  EXPECT_MEMBER_AT(cell, CellSlice, depth_offset);
  EXPECT_MEMBER_AT(cell, CellSlice, output_offset);
  EXPECT_MEMBER_AT(cell, CellSlice, reserved);
  EXPECT_EQ(MembersOf("cell"), 4) << "a CellSlice member is not listed above";
  EXPECT_EQ(Offset("cell_end"), static_cast<int>(sizeof(f32::CellSlice)));
}

TEST_F(LayoutTest, RasterSampleMatchesStd430) {
  EXPECT_MEMBER_AT(raster, RasterSample, triangle0);
  EXPECT_MEMBER_AT(raster, RasterSample, triangle1);
  EXPECT_MEMBER_AT(raster, RasterSample, triangle2);
  EXPECT_MEMBER_AT(raster, RasterSample, volume);
  EXPECT_EQ(MembersOf("raster"), 4) << "a RasterSample member is not listed above";
  EXPECT_EQ(Offset("raster_end"), static_cast<int>(sizeof(f32::RasterSample)));
}

TEST_F(LayoutTest, RasterConstantsMatchesStd430) {
  EXPECT_MEMBER_AT(draw, RasterConstants, sample_count);
  EXPECT_MEMBER_AT(draw, RasterConstants, atlas_width);
  EXPECT_MEMBER_AT(draw, RasterConstants, samples_per_frame);
  EXPECT_MEMBER_AT(draw, RasterConstants, first_in_frame);
  EXPECT_MEMBER_AT(draw, RasterConstants, conventions_per_frame);
  EXPECT_MEMBER_AT(draw, RasterConstants, convention_slot);
  EXPECT_MEMBER_AT(draw, RasterConstants, output_offset);
  EXPECT_MEMBER_AT(draw, RasterConstants, viewport_height);
  EXPECT_MEMBER_AT(draw, RasterConstants, coverage_word);
  EXPECT_MEMBER_AT(draw, RasterConstants, slices);
  EXPECT_MEMBER_AT(draw, RasterConstants, first_texel);
  EXPECT_MEMBER_AT(draw, RasterConstants, atlas_rows);
  EXPECT_EQ(MembersOf("draw"), 12) << "a RasterConstants member is not listed above";
  EXPECT_EQ(Offset("draw_end"), static_cast<int>(sizeof(f32::RasterConstants)));
}

}  // namespace
}  // namespace depthbench
