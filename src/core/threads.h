// src/core/threads.h — how many worker threads an option's thread count means, and the one
// parallel loop of the library (internal): the filter's weighings and searches, the scene
// normals, the heuristic volumes and the PPF voting run their workers through ParallelFor.
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

// Calls body(worker, i) once for every i in [0, n), on `workers` threads (a count already
// resolved by WorkerThreads; 1 or less: in order on the calling thread), handing out `chunk`
// consecutive indices at a time to whichever worker is free (dynamic schedule; chunk ≥ 1).
// `worker` is in [0, workers): the index of the caller's own scratch (a per-thread workspace).
// Which worker runs which i varies from call to call, so a body that writes only to index i's
// own outputs and to its worker's scratch gives the same results whatever the thread count.
// The body must not throw (an exception cannot leave an OpenMP worker).
template <typename Body>
void ParallelFor(int workers, int n, int chunk, const Body& body) {
  if (workers <= 1 || n <= 1) {
    for (int i = 0; i < n; ++i) body(0, i);
    return;
  }
#pragma omp parallel for num_threads(workers) schedule(dynamic, chunk)
  for (int i = 0; i < n; ++i) body(omp_get_thread_num(), i);
}

}  // namespace posefilter
