// FilterOptions::record_particles (EstimateResult::particle_history): one set per iteration of
// every run, in order, each best first with its run and iteration; the best weight of each set
// is that iteration's best_weight_history entry; and recording changes no pose and no weight.
#include <gtest/gtest.h>

#include <algorithm>

#include "posefilter/filter.h"
#include "posefilter/prior.h"
#include "posefilter/synth.h"

namespace posefilter {
namespace {

TEST(ParticleRecord, OneSetPerIterationBestFirstAndNoChange) {
  SynthOptions so;
  so.target = "box";
  so.clutter = 0;
  const SynthScene scene = MakeSynthScene(so, 5);
  const Prior prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
  const int cls = prior.ClassIndex(scene.target.name);
  FilterOptions opt;
  opt.num_particles = 40;
  opt.stop.max_iterations = 4;
  opt.restarts = 2;
  opt.polish.steps = 0;
  const SceneInput input{scene.depth, scene.camera};
  const EstimateResult plain = EstimatePose(input, scene.target, prior, cls, opt);
  opt.record_particles = true;
  const EstimateResult rec = EstimatePose(input, scene.target, prior, cls, opt);

  EXPECT_TRUE(plain.particle_history.empty());
  EXPECT_TRUE(rec.T_cam_obj.matrix().isApprox(plain.T_cam_obj.matrix(), 0.0));
  EXPECT_EQ(rec.weight, plain.weight);
  EXPECT_EQ(rec.best_weight_history, plain.best_weight_history);

  const std::vector<ParticleSet>& h = rec.particle_history;
  ASSERT_EQ(int(h.size()), rec.iterations);
  ASSERT_EQ(h.size(), rec.best_weight_history.size());
  int run = 0, next_iteration = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    SCOPED_TRACE(i);
    if (h[i].run != run) {  // the next restart starts at iteration 0
      EXPECT_EQ(h[i].run, run + 1);
      run = h[i].run;
      next_iteration = 0;
    }
    EXPECT_EQ(h[i].iteration, next_iteration++);
    ASSERT_EQ(h[i].poses.size(), h[i].weights.size());
    ASSERT_FALSE(h[i].weights.empty());
    EXPECT_TRUE(std::is_sorted(h[i].weights.rbegin(), h[i].weights.rend())) << "not best first";
    EXPECT_EQ(h[i].weights[0], rec.best_weight_history[i]);
  }
  EXPECT_EQ(run, 1) << "the second restart's sets are missing";
  EXPECT_EQ(h[0].poses.size(), 40u);
}

}  // namespace
}  // namespace posefilter
