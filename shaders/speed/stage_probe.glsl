// The probe of the shader stages of `depthbench speed` (bench/speed/
// gpu_pass_timer.h, MeasureStages): the same arithmetic in whichever stage
// includes this file, so that the stages' times for the same invocations
// compare what each stage can compute. A device may run its stages on
// different processors: a data-centre GPU can leave graphics work to a few
// of them, and a fragment pass then computes far slower than a compute
// pass, which the timings of compute passes do not show.
//
// Each invocation runs four independent chains of kIterations dependent
// fused multiply-adds (independent, so that a processor can overlap them as
// it would a reconstruction's), then counts itself against its stage, and,
// where the device names its processors (VK_NV_shader_sm_builtins; the
// includer defines STAGE_PROBE_PROCESSORS), against the processor it ran on.
#ifdef STAGE_PROBE_PROCESSORS
#extension GL_NV_shader_sm_builtins : require
#endif

// bench/speed/gpu_pass_timer.cc's kStageCounts and kMostProcessors.
const uint kStages = 3u;
const uint kMostProcessors = 1024u;

// counts[s]: invocations of stage s; counts[kStages + s * kMostProcessors + p]:
// those that ran on processor p.
layout(std430, set = 0, binding = 0) buffer Counts { uint counts[]; };
layout(push_constant) uniform Probe {
  uint stage;  // 0 compute, 1 vertex, 2 fragment
  uint width;  // the pass's invocations are width * height
} probe;
// Each chain's multiply-adds: a constant of the pipeline, each count its
// own program. Pushed, the count was not always the one run: on lavapipe,
// a probe's compute passes took the same time at 64 and at 32768
// multiply-adds an invocation once an earlier probe had run.
layout(constant_id = 0) const uint kIterations = 16u;

// `seed` differs between invocations, so that no two compute the same.
void ProbeStage(uint seed) {
  vec4 x = vec4(1.0) + vec4(float(seed & 1023u)) * vec4(1e-3, 2e-3, 3e-3, 4e-3);
  for (uint i = 0u; i < kIterations; ++i) x = fma(x, vec4(0.999999), vec4(1e-6));
  // x stays near 1, so the count is always 1; the comparison keeps the
  // arithmetic from being left out.
  uint count = (x.x + x.y + x.z + x.w) < -1.0 ? 2u : 1u;
  atomicAdd(counts[probe.stage], count);
#ifdef STAGE_PROBE_PROCESSORS
  atomicAdd(counts[kStages + probe.stage * kMostProcessors + min(gl_SMIDNV, kMostProcessors - 1u)], 1u);
#endif
}
