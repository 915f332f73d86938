// Fuzz target: ReadBopResultsCsv (include/posefilter/bop.h, src/eval/bop_results_csv.cc), the
// BOP 2019 results CSV reader of `eval --dataset` and of `run-dataset`'s resume. Seeds:
// fuzz/corpus/bop_csv_fuzz/; dictionary: fuzz/bop_csv.dict.
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_util.h"
#include "posefilter/bop.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static posefilter_fuzz::ScratchFile file("bop_results", ".csv");
  const std::string& path = file.Write(data, size);
  posefilter_fuzz::ReadOrError(path, [&] {
    const std::vector<posefilter::BopResult> results = posefilter::ReadBopResultsCsv(path);
    for (const posefilter::BopResult& r : results) {
      posefilter_fuzz::Require(r.scene_id >= 0 && r.im_id >= 0 && r.obj_id >= 0, "ids are >= 0");
      posefilter_fuzz::Require(std::isfinite(r.score) && std::isfinite(r.time_s), "score and time are finite");
      posefilter_fuzz::Require(r.T_cam_obj.matrix().allFinite(), "pose is finite");
      const Eigen::Matrix3d R = r.T_cam_obj.linear();
      const double ortho = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
      posefilter_fuzz::Require(ortho <= 1e-3 && R.determinant() > 0, "R is a rotation");
    }
  });
  return 0;
}
