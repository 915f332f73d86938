// tests/eval/bop_test_dataset.h — a tiny BOP-format dataset built from the synthetic generator,
// shared by the bop_* tests (tests/eval) and the run-dataset CLI tests (tests/cli).
//
// Models (millimetre PLY + models_info.json): obj 1 = box 12×8×16 cm (discrete symmetries: 180°
// about x, y and z), obj 2 = cylinder r 4 cm h 14 cm (continuous about z, discrete 180° about x),
// obj 3 = L-shape (no symmetry). Split "test", scene 1: image i (1-based) shows obj ((i−1) mod 3)
// + 1 in a MakeSynthScene of seed 100 + i (640×480, one clutter object, default sensor noise).
#pragma once

#include <Eigen/Geometry>

#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "posefilter/bop.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter::testing_util {

struct TinyBop {
  std::string root;
  std::vector<Mesh> meshes;            // metres, index obj_id − 1
  std::vector<DatasetModel> models;    // as written
  std::vector<DatasetImage> images;    // as written (gt in metres)
  std::vector<DepthImage> depths;      // as written (quantised to 0.1 mm)
};

inline Eigen::Isometry3d HalfTurn(const Eigen::Vector3d& axis) {
  Eigen::Isometry3d S = Eigen::Isometry3d::Identity();
  S.linear() = Eigen::AngleAxisd(std::numbers::pi, axis).toRotationMatrix();
  return S;
}

// Writes the dataset under `root` (created) with `n_images` images.
inline TinyBop MakeTinyBop(const std::filesystem::path& root, int n_images = 3) {
  TinyBop t;
  t.root = root.string();
  const char* kinds[] = {"box", "cylinder", "lshape"};
  for (int k = 0; k < 3; ++k) {
    t.meshes.push_back(MakeShape(kinds[k]));
    DatasetModel m;
    m.obj_id = k + 1;
    m.name = "obj_00000" + std::to_string(k + 1);
    m.diameter_m = t.meshes.back().Diameter();
    t.models.push_back(m);
  }
  t.models[0].symmetries_discrete = {HalfTurn(Eigen::Vector3d::UnitX()), HalfTurn(Eigen::Vector3d::UnitY()),
                                     HalfTurn(Eigen::Vector3d::UnitZ())};
  t.models[1].symmetries_discrete = {HalfTurn(Eigen::Vector3d::UnitX())};
  t.models[1].symmetries_continuous = {ContinuousSymmetry{}};
  WriteBopModels(t.root, t.models, {&t.meshes[0], &t.meshes[1], &t.meshes[2]});

  for (int i = 1; i <= n_images; ++i) {
    const int k = (i - 1) % 3;
    SynthOptions o;
    o.target = kinds[k];
    o.clutter = 1;
    o.false_positives = 0;
    const SynthScene s = MakeSynthScene(o, 100 + i);
    DatasetImage im;
    im.scene_id = 1;
    im.im_id = i;
    im.camera = s.camera;
    im.depth_scale_m = s.depth_scale;
    im.has_gt = true;
    GtInstance g;
    g.obj_id = k + 1;
    g.T_cam_obj = s.gt[0].T_cam_obj;
    im.gt.push_back(g);
    t.images.push_back(im);
    t.depths.push_back(s.depth);
  }
  WriteBopScene(t.root, "test", t.images, t.depths);
  return t;
}

// The ground-truth poses as results rows (score 1, time 0.5 s).
inline std::vector<BopResult> GtResults(const TinyBop& t) {
  std::vector<BopResult> rows;
  for (const auto& im : t.images)
    for (const auto& g : im.gt) {
      BopResult r;
      r.scene_id = im.scene_id;
      r.im_id = im.im_id;
      r.obj_id = g.obj_id;
      r.score = 1;
      r.T_cam_obj = g.T_cam_obj;
      r.time_s = 0.5;
      rows.push_back(r);
    }
  return rows;
}

// A fixture whose suite shares one tiny 3-image dataset, built once in a per-suite temporary
// folder and removed after the suite; tests that modify it work on Copy().
class TinyBopTest : public ScratchDirTest {
 protected:
  explicit TinyBopTest(const std::string& tag) : ScratchDirTest(tag) {}
  static void SetUpTestSuite() {
    const std::string suite = ::testing::UnitTest::GetInstance()->current_test_suite()->name();
    base_dir_ = new std::filesystem::path(FreshTempPath("tiny_bop_" + suite));
    tiny_ = new TinyBop(MakeTinyBop(*base_dir_, 3));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    std::filesystem::remove_all(*base_dir_, ec);
    delete tiny_;
    delete base_dir_;
    tiny_ = nullptr;
    base_dir_ = nullptr;
  }
  // A private copy of the dataset in this test's scratch folder.
  std::string Copy() {
    const std::filesystem::path dst = dir() / "ds";
    std::filesystem::copy(*base_dir_, dst, std::filesystem::copy_options::recursive);
    return dst.string();
  }
  inline static std::filesystem::path* base_dir_ = nullptr;
  inline static TinyBop* tiny_ = nullptr;
};

}  // namespace posefilter::testing_util
