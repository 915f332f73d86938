// reduce.glsl — the sums of one workgroup (64 invocations, all of one particle) added into
// the particle's result: a tree over shared memory (unrolled), then one 64-bit atomic add per
// sum. Every invocation of the workgroup calls it (it holds barriers).
layout(local_size_x = 64) in;

shared int64_t red[kNumSums * 64u];

void ReduceStep(uint l, uint stride) {
  if (l < stride)
    for (uint k = 0u; k < kNumSums; ++k) red[k * 64u + l] += red[k * 64u + l + stride];
  barrier();
}

void ReduceAndAdd(uint p, int64_t s[kNumSums]) {
  const uint l = gl_LocalInvocationIndex;
  for (uint k = 0u; k < kNumSums; ++k) red[k * 64u + l] = s[k];
  barrier();
  ReduceStep(l, 32u);
  ReduceStep(l, 16u);
  ReduceStep(l, 8u);
  ReduceStep(l, 4u);
  ReduceStep(l, 2u);
  ReduceStep(l, 1u);
  if (l < kNumSums && p < uint(pc.num_particles)) AtomicAdd64(p, l, red[l * 64u]);
}
