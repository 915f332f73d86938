// src/prior/volume_cache.h — heuristic volumes computed on demand (internal).
//
// A prior's pyramid has thousands of cells, each with its own box, but a filter run places
// its particles in a few hundred of them (≈ 400–650 of 6300 on the synthetic suite). The
// cache knows up front which boxes have a volume at all (their valid-sample count: the cheap
// half of ComputeHeuristics's work, which the initial draw needs for every cell) and computes
// a box's percentiles the first time the box is asked for. Values are exactly
// ComputeHeuristics's (the same code computes both).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "posefilter/heuristics.h"

namespace posefilter::prior {

class VolumeCache {
 public:
  VolumeCache() = default;
  // Checks the inputs like ComputeHeuristics (throws Error naming the problem) and counts
  // every box's valid samples (`threads` workers, 0 = all cores). `depth`, `camera` and
  // `boxes` are referenced, not copied: they must outlive the cache.
  VolumeCache(const DepthImage& depth, const Camera& camera, const std::vector<Box>& boxes,
              const HeuristicOptions& opt, int threads);

  // A cache of volumes computed elsewhere (all of them known; e.g. ComputeHeuristics's).
  explicit VolumeCache(std::vector<Volume> volumes);

  int size() const { return int(valid_.size()); }
  // Whether box i has a volume (ComputeHeuristics(...)[i].valid); 0 ≤ i < size().
  bool Valid(int i) const { return valid_[std::size_t(i)] != 0; }
  // Box i's volume, computed on the first call for i. Thread-safe: the volumes computed so
  // far sit behind one lock, taken for every call (the filter calls it from its serial steps,
  // so the lock is never contended there); the reference stays valid for the cache's life.
  const Volume& Get(int i) const;
  // Boxes whose volume has been computed so far.
  int computed() const;

 private:
  const DepthImage* depth_ = nullptr;
  const Camera* camera_ = nullptr;
  const std::vector<Box>* boxes_ = nullptr;
  HeuristicOptions opt_;
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();  // camera → base
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
  std::vector<std::uint8_t> valid_;
  // What Get fills in, behind its lock: one volume per box, whether it is computed yet, and how
  // many are. Held by pointer so that a const cache can fill it in and the cache can move.
  struct Computed {
    std::mutex lock;
    std::vector<Volume> volumes;
    std::vector<std::uint8_t> done;
    int count = 0;
  };
  std::unique_ptr<Computed> computed_ = std::make_unique<Computed>();
};

}  // namespace posefilter::prior
