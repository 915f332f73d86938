// Estimates a box's pose on a synthetic scene through the installed library; exit 0 when the
// estimate is within 10 % of the diameter (ADD-S) of the ground truth.
#include <cstdio>

#include "posefilter/filter.h"
#include "posefilter/metrics.h"
#include "posefilter/synth.h"

int main() {
  posefilter::SynthOptions so;
  so.target = "box";
  const posefilter::SynthScene sc = posefilter::MakeSynthScene(so, 1);
  const posefilter::Prior prior = posefilter::PostProcessPyramid(sc.raw_pyramid, sc.layout, sc.classes);
  posefilter::FilterOptions o;
  o.restarts = 1;
  const posefilter::EstimateResult r =
      posefilter::EstimatePose({sc.depth, sc.camera}, sc.target, prior, prior.ClassIndex("box"), o);
  const posefilter::PoseErrors e = posefilter::ComputePoseErrors(posefilter::SamplePoints(sc.target), sc.target.Diameter(),
                                                                 r.T_cam_obj, sc.gt[0].T_cam_obj);
  std::printf("consumer: ADD-S %.1f mm, %s\n", 1000 * e.adds, e.adds_ok ? "found" : "NOT found");
  return e.adds_ok ? 0 : 1;
}
