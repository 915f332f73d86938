// reduce.glsl — the sums of the invocations of a subgroup, all of one particle, added into the
// particle's result: subgroupAdd over 16/16/32-bit pieces of each int64 sum (32-bit subgroup
// arithmetic is all Vulkan 1.1 devices offer without extensions), then one 64-bit atomic add
// per sum from one invocation. Every invocation of the workgroup calls it, in uniform control
// flow. No shared memory and no barriers: on a GPU it costs a few shuffles, and on Mesa's
// lavapipe barriers are far dearer than atomics.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

layout(local_size_x = 64) in;

void ReduceAndAdd(uint p, int64_t s[kNumSums]) {
  const bool writer = subgroupElect() && p < uint(pc.num_particles);
  for (uint k = 0u; k < kNumSums; ++k) {
    const uint64_t u = uint64_t(s[k]);
    // Σ of the low and middle 16 bits stays below 2^23 (at most 128 invocations); Σ of the
    // high words wraps mod 2^32, which the sum mod 2^64 allows.
    const uint lo = subgroupAdd(uint(u) & 0xffffu);
    const uint mid = subgroupAdd(uint(u) >> 16);
    const uint hi = subgroupAdd(uint(u >> 32));
    if (writer) AtomicAdd64(p, k, int64_t(uint64_t(lo) + (uint64_t(mid) << 16) + (uint64_t(hi) << 32)));
  }
}
