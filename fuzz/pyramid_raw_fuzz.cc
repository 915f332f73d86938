// Fuzz target: ReadRawPyramid (include/posefilter/prior.h, src/prior/pyramid.cc), the raw
// stage-1 pyramid reader of `estimate --prior x.pyr`, followed by PostProcessPyramid as the CLI
// does. The thesis layout needs 655 KB files, so a small layout comes from the first two bytes
// (1–3 classes; 1–3 levels of 1×2, 2×4, 4×8 cells over a 64×48 image); the rest is the file.
// Seeds: fuzz/corpus/pyramid_raw_fuzz/ (written by WriteRawPyramid, see fuzz/make_corpus.cc).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "posefilter/prior.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static posefilter_fuzz::ScratchFile file("pyramid", ".pyr");
  if (size < 2) return 0;
  posefilter::PyramidLayout layout;
  layout.image_width = 64;
  layout.image_height = 48;
  layout.num_classes = 1 + data[0] % 3;
  const int grids[3][2] = {{1, 2}, {2, 4}, {4, 8}};
  for (int l = 0; l < 1 + data[1] % 3; ++l) {
    const double stride_x = 64.0 / grids[l][1], stride_y = 48.0 / grids[l][0];
    layout.levels.push_back({grids[l][0], grids[l][1], 4 * stride_x, 4 * stride_y});
  }
  std::vector<std::string> classes;
  for (int c = 0; c < layout.num_classes; ++c) classes.push_back("class" + std::to_string(c));
  const std::string& path = file.Write(data + 2, size - 2);
  posefilter_fuzz::ReadOrError(path, [&] {
    const std::vector<float> raw = posefilter::ReadRawPyramid(path, layout);
    posefilter_fuzz::Require(raw.size() == std::size_t(layout.CellCount()) * layout.RawValuesPerCell(),
                             "raw holds CellCount x (num_classes + 5) values");
    for (float v : raw) posefilter_fuzz::Require(std::isfinite(v), "raw values are finite");
    const posefilter::Prior prior = posefilter::PostProcessPyramid(raw, layout, classes);
    for (float p : prior.prob) posefilter_fuzz::Require(std::isfinite(p) && p >= 0 && p <= 1, "prob in [0, 1]");
    for (const posefilter::Box& b : prior.boxes) {
      posefilter_fuzz::Require(std::isfinite(b.cx) && std::isfinite(b.cy) && b.w >= 1 && b.w <= 200 && b.h >= 1 &&
                                   b.h <= 200,
                               "decoded boxes finite and clipped to [1, max_box_px]");
    }
  });
  return 0;
}
