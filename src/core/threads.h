// src/core/threads.h — how many worker threads an option's thread count means (internal).
#pragma once

#include <omp.h>

namespace posefilter {

// The `threads` of FilterOptions, ComputeHeuristics and ComputeSceneNormals: that many
// workers, or all cores (OpenMP's default team size) for 0 or less.
inline int WorkerThreads(int requested) { return requested > 0 ? requested : omp_get_max_threads(); }

}  // namespace posefilter
