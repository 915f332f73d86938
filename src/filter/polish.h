// src/filter/polish.h — the final polish of the float engines' answer (internal;
// docs/ALGORITHM.md §9 "Final polish"): turned and pivoted copies of the seeds, ICP steps and
// a compass search on the weight, all weighed in a filter Context (filter_context.h).
// EstimatePose (particle_filter.cc) and filter::PolishPoses (driver.cc, the hw engine's host
// side) call it.
#pragma once

#include <vector>

#include "filter/diffusion.h"
#include "filter/filter_context.h"
#include "posefilter/filter.h"

namespace posefilter::filter {

// Final polish (ours, FilterOptions::polish.steps): every seed, and with polish_turns each
// seed turned about the centre c of the model's box (Context::box_axes) by the 23 other
// rotations of a cube in the box's frame
// (T' = T·[R_k | c − R_k·c], so the object stays where it is), takes polish_steps ICP steps
// (the kIcpStep move solved from its own last weighing) at the final inlier threshold. A
// turned copy whose translation is a little off can thus settle before it is compared, which
// the filter's own quarter-turn move cannot do (its copies are outweighed at once). Returns
// the best weighed particle seen, or the best seed if nothing beats it. It
// weighs at the final inlier thresholds on the fine pixel level (FinalRunState), in `scratch`.
Particle Polish(const Context& ctx, Scratch& scratch, const std::vector<Particle>& seeds, FilterStats* stats);

}  // namespace posefilter::filter
