// src/core/threads.h — how many worker threads an option's thread count means (internal).
#pragma once

#include <omp.h>

#include <algorithm>
#include <thread>

namespace posefilter {

// The most worker threads any `threads` option accepts: 4 per hardware thread (at least 4).
// More only oversubscribes the cores, and very large teams make the OpenMP runtime fail.
inline int MaxWorkerThreads() {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<int>(std::max(4u, 4u * hw));
}

// The `threads` of FilterOptions, ComputeHeuristics and ComputeSceneNormals: that many
// workers (at most MaxWorkerThreads(); the options' IsValid reject more), or all cores
// (OpenMP's default team size) for 0 or less.
inline int WorkerThreads(int requested) {
  return requested > 0 ? std::min(requested, MaxWorkerThreads()) : omp_get_max_threads();
}

}  // namespace posefilter
