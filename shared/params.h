// Parameter blocks shared by the shaders and the host, laid out for std430.
//
// Layout rules that keep C++ and GLSL in agreement (checked member by member
// against glslang's reflection in tests/layout_test.cc):
//   - only vec4, mat4 and uint members; uints come in groups of four;
//   - no vec3, no mat3, no bool, no arrays;
//   - every struct is a multiple of 16 bytes.
// In C++ these structs are instantiated with float (the backends' view, and
// the bytes uploaded to the GPU) and with a double-double `real` (the exact
// constants the reference and the formula tests use).
// No include guard: see compat.h.

// Bits of DepthParams.convention. A depth convention is a combination of
// these choices. The low three bits number a frame's DepthParams slots: an
// orthographic frame's conventions take the slots of their perspective
// namesakes (a frame is one or the other, and has no infinite far plane).
DB_CONST_UINT(DB_CONVENTION_REVERSED, 1u)        // near maps to 1, far to 0
DB_CONST_UINT(DB_CONVENTION_INFINITE, 2u)        // the far plane is at infinity
DB_CONST_UINT(DB_CONVENTION_CLIP_MINUS_ONE, 4u)  // GL clip depth: NDC z in [-1, 1]
DB_CONST_UINT(DB_CONVENTION_ORTHOGRAPHIC, 8u)    // depth linear in eye depth, w = 1
DB_CONST_UINT(DB_CONVENTION_SLOTS, 7u)           // the bits that number a DepthParams slot

// Everything about one frame that does not depend on the depth convention:
// the camera, the lens, the render target, and the per-vertex values that the
// rasterizer would interpolate for the ray-based variants. All "origin"
// members are the attribute's value at uv (0, 0) (the top-left corner of the
// screen); "du"/"dv" are its change from uv (0, 0) to uv (1, 0) and (0, 1).
//
// An orthographic frame's lens is the view volume's half extents: `lens`
// xy is half its width and height in view units (at every depth, where a
// perspective lens gives them at unit eye depth), and `lens_centre` xy the
// view-space offset of NDC (0, 0).
struct FrameParams {
  mat4 camera_world;        // view space -> world space (rotation + translation)
  vec4 camera_position;     // xyz: camera position in world space; w: far plane distance (0 when infinite)
  vec4 lens;                // x: tan(fovY/2)*aspect, y: tan(fovY/2), z: H = 1/x, w: V = 1/y
  vec4 resolution;          // x: width, y: height, z: 1/width, w: 1/height (pixels)
  vec4 frustum_ray_origin;  // Pettineo 2009: world-space camera->far-plane ray, full-screen pass
  vec4 frustum_ray_du;
  vec4 frustum_ray_dv;
  vec4 volume_position_origin;  // Pettineo 2009: view-space position on a light volume's surface
  vec4 volume_position_du;
  vec4 volume_position_dv;
  vec4 eye_ray_view_origin;  // the eye-ray post 2011: view-space eye ray (x*tan*aspect, y*tan, -w)
  vec4 eye_ray_view_du;
  vec4 eye_ray_view_dv;
  vec4 eye_ray_world_origin;  // the eye-ray post 2011: the same ray rotated by the inverse view matrix
  vec4 eye_ray_world_du;
  vec4 eye_ray_world_dv;
  mat4 world_view;  // world space -> view space (the view matrix): the raster pipeline's light volumes
  // An off-centre lens (a VR eye's field of view, TAA jitter): xy: the view
  // ray through NDC (0, 0) at unit eye depth is (x, y, -1); zw: the
  // projection matrix's off-centre terms, x * H and y * V. Zero for a
  // symmetric frustum; the variants that read only `lens` assume one.
  vec4 lens_centre;
  // x: the near plane's eye depth, y: the far plane's (0 when infinite);
  // zw: 0. What an engine hands its shaders as the clip planes (Unity's
  // _ProjectionParams y and z), read by the orthographic linear map.
  vec4 clip_planes;
};

// What one depth convention adds to a frame: the mapping between eye depth
// z (= -view.z > 0) and NDC depth, which is  ndc_z = A + B / z  (and
// ndc_z = A + B * z  under an orthographic projection, where P and Q then
// give z = P * ndc_z + Q).
struct DepthParams {
  mat4 inverse_view_projection;  // Unity URP: NDC (x, y, ndc_z, 1) -> homogeneous world position
  mat4 view_projection;          // world position -> clip space: what the raster pipeline draws with
  vec4 coefficients;             // x: A, y: B, z: P = 1/B, w: Q = -A/B (the engine shader notes)
  uint convention;               // DB_CONVENTION_* bits
  uint reserved0;
  uint reserved1;
  uint reserved2;
};

// Push constants of one compute dispatch: how the batch's per-sample
// buffers are laid out, and which cells the dispatch runs. A slice holds one
// value per sample: the batch's samples, after `lead` unused elements where
// the host aligns them (compute_pass.glsl), and padding to slice_length.
// One dispatch runs every cell of one variant, a cell per workgroup row:
// row y runs cell_slices[first_cell + y].
struct PassConstants {
  uint slice_length;       // elements per slice
  uint samples_per_frame;  // element e belongs to frame (e + first_in_frame) / samples_per_frame
  uint conventions_per_frame;
  uint first_in_frame;  // position within its frame of a slice's first element
  uint frame_count;     // frames the batch's samples fall in
  uint first_cell;      // the dispatch's first entry in the CellSlice buffer
  uint reserved0;
  uint reserved1;
};

// The geometry the raster pipeline draws for one sample
// (bench/pipeline/raster_model.h): a small triangle facing the camera
// through the sample's point, which produces its depth, and a light volume
// around the point, which the bounding-volume ray variant draws. A sample
// with nothing to draw has all four zero (no area, no coverage).
struct RasterSample {
  vec4 triangle0;  // xyz: a world-space corner, float32 as a vertex buffer holds it; w: 1
  vec4 triangle1;
  vec4 triangle2;
  vec4 volume;  // xyz: world-space centre of an axis-aligned cube around the point; w: half its edge
};

// Push constants of the raster form's draws (shaders/raster/): how the
// batch's samples lie in the atlas, where sample i is texel
// (i % atlas_width, i / atlas_width), the one viewport every draw uses
// (shaders/raster/atlas_placement.glsl), and what the draw renders: a
// depth slot (pass 1) or a cell (pass 2).
struct RasterConstants {
  uint sample_count;       // samples in the batch: the length of a position slice
  uint atlas_width;        // texels per atlas row
  uint samples_per_frame;  // sample i belongs to frame (i + first_in_frame) / samples_per_frame
  uint first_in_frame;     // position within its frame of the batch's first sample
  uint conventions_per_frame;
  uint convention_slot;  // the slot's or cell's convention within a frame's DepthParams
  uint output_offset;    // pass 2: first float of the cell's positions: slices of x, then y, then z
  uint viewport_height;  // the atlas viewport's height in texels: a power of two
  uint coverage_word;    // fetch.comp: the slot's first word of coverage bytes in the copy it reads
  uint slices;           // no_geometry.comp: the position slices the run writes (3 per cell)
  uint first_texel;      // sample i lies at texel (first_texel + i) mod (atlas_width * atlas_rows), row by row
  uint atlas_rows;
};

// What the raster form says of each (depth slot, sample) texel after pass 1
// (shaders/raster/fetch.comp), for a judge on the device: drawn; left as
// cleared by the rasterizer (nothing of the sample's to judge); or never
// drawn, the host having no geometry for the sample.
DB_CONST_UINT(DB_RASTER_TEXEL_DRAWN, 0u)
DB_CONST_UINT(DB_RASTER_TEXEL_UNDRAWN, 1u)
DB_CONST_UINT(DB_RASTER_TEXEL_NO_GEOMETRY, 2u)

// Where one cell's inputs and outputs lie in the batch's buffers.
struct CellSlice {
  uint convention_slot;  // index of the cell's convention within a frame's DepthParams
  uint depth_offset;     // first element of the cell's stored-depth slice in the depth buffer
  uint output_offset;    // first float of the cell's positions: slices of x, then y, then z
  uint reserved;
};
