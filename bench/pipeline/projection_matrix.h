// An engine's projection matrix as input: 16 numbers, their layout and the
// graphics API they are for. ReadProjectionMatrix derives what the matrix
// holds in depthbench's terms (perspective or orthographic, handedness, the
// depth convention and clip range, near and far or infinite, the frustum's
// sides and off-centre terms, a flipped y) or refuses it with the reason;
// ApplyProjection makes a domain of it.
//
// The matrix M is the one that takes a column vector of view space to clip
// space, clip = M * (x, y, z, 1). "column-major" lists M column by column
// (what GLM, GLSL and a D3D row-vector matrix hold in memory: the two are
// transposes of each other and are stored alike); "row-major" lists M row
// by row, as one writes it on paper.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"

namespace depthbench {

// The APIs a matrix may be for; they decide its clip-depth range. OpenGL
// clips depth to [-1, 1] unless glClipControl(..., GL_ZERO_TO_ONE) is in
// force; Direct3D, Vulkan and Metal clip it to [0, 1].
enum class GraphicsApi : std::uint8_t { kDirect3D, kVulkan, kMetal, kOpenGL, kOpenGLClipControl };
inline constexpr const char* kGraphicsApiNames = "d3d, vulkan, metal, opengl, opengl-clip-control";
Expected<GraphicsApi> ParseGraphicsApi(std::string_view name);
const char* GraphicsApiName(GraphicsApi api);

enum class MatrixLayout : std::uint8_t { kColumnMajor, kRowMajor };
Expected<MatrixLayout> ParseMatrixLayout(std::string_view name);  // "column-major" or "row-major"

struct ProjectionMatrix {
  std::array<double, 16> numbers{};  // as given, in `layout`
  MatrixLayout layout = MatrixLayout::kColumnMajor;
  GraphicsApi api = GraphicsApi::kVulkan;
  // M[row][column] of clip = M * view.
  double At(int row, int column) const;
};

// What a projection matrix holds.
struct ProjectionFacts {
  bool orthographic = false;
  bool left_handed = false;  // view space looks down +z (Direct3D's custom), not -z
  bool y_flipped = false;    // clip y points down (a Vulkan engine's flip): mirrors the image, no precision change
  Convention convention = Convention::kStandard;  // its depth convention; clip range from the API
  double near = 0.0;
  double far = 0.0;  // +infinity for an infinite far plane
  // The frustum's sides at unit eye depth (perspective) or in view units
  // (orthographic): x at NDC -1 and +1, y at NDC -1 and +1.
  double left = 0.0, right = 0.0, bottom = 0.0, top = 0.0;
  bool off_centre() const;
  // One line per fact, for `--projection` and the scene's description.
  std::vector<std::string> Describe() const;
};

// Recognises the matrix, or refuses it naming the entries at fault: an
// oblique near plane (clip z depending on x or y), a w row that is neither
// perspective nor orthographic, skew, a depth mapping whose near or far
// plane lies behind the eye, non-finite numbers.
Expected<ProjectionFacts> ReadProjectionMatrix(const ProjectionMatrix& matrix);

// The domain the matrix fixes: its near and far planes (or an infinite
// far), and its frustum as an eye field of view (which carries any
// off-centre term, a TAA jitter baked into the matrix included), or its
// orthographic view volume.
Status ApplyProjection(const ProjectionFacts& facts, Domain& domain);

// "API:LAYOUT:N0,N1,...,N15" (the --projection flag), e.g.
// "vulkan:column-major:1.2,0,0,0,...".
Expected<ProjectionMatrix> ParseProjectionFlag(std::string_view text);

// What an API must do to produce convention `c`'s depth: "Direct3D,
// Vulkan, Metal: ...; OpenGL: ...". Empty for linear (a shader writes it,
// on any API).
std::string ApiRecipe(Convention c);

}  // namespace depthbench
