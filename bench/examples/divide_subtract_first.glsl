// An edit of the built-in `divide` variant that loses less near the far
// plane. divide forms the reciprocal eye depth as depth/B - A/B: two
// rounded quotients of nearly the same size whose difference cancels their
// leading bits. Here the subtraction comes first: near the far plane the
// stored depth and A are within a factor of two of each other, so
// depth - A is exact (Sterbenz's lemma), and one rounding, the division by
// B, remains.
//
// depthbench: input=hardware entry=reconstruct

vec3 reconstruct(vec2 uv, float depth) {
  vec2 ndc = vec2(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
  float ndc_z = depth;
  if ((db_Convention & DB_CONVENTION_CLIP_MINUS_ONE) != 0u) {
    ndc_z = -1.0 + depth * 2.0;
  }
  float a = db_DepthCoefficients.x;
  float b = db_DepthCoefficients.y;
  vec3 view = vec3(ndc.x / db_Lens.z, ndc.y / db_Lens.w, -1.0) / ((ndc_z - a) / b);
  return (db_ViewToWorld * vec4(view, 1.0)).xyz;
}
