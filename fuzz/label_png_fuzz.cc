// Fuzz target: LoadLabelPng (label / instance-mask PNGs of `estimate --mask` and YCB-Video's
// label.png) and LoadRgbPng (the overlay background of `estimate --rgb`) on the same bytes
// (include/posefilter/depth_image.h). Seeds: fuzz/corpus/label_png_fuzz/.
// Chunk CRCs are recomputed before the read (fuzz_util.h, WithPngCrcsFixed); dictionary:
// fuzz/png.dict.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_util.h"
#include "posefilter/depth_image.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static posefilter_fuzz::ScratchFile file("label_png", ".png");
  const std::vector<std::uint8_t> png = posefilter_fuzz::WithPngCrcsFixed(data, size);
  const std::string& path = file.Write(png.data(), png.size());
  posefilter_fuzz::ReadOrError(path, [&] {
    const posefilter::LabelImage l = posefilter::LoadLabelPng(path);
    posefilter_fuzz::Require(l.width > 0 && l.height > 0, "label image has a positive size");
    posefilter_fuzz::Require(l.ids.size() == std::size_t(l.width) * std::size_t(l.height),
                             "label ids hold width x height values");
  });
  posefilter_fuzz::ReadOrError(path, [&] {
    const posefilter::RgbImage rgb = posefilter::LoadRgbPng(path);
    posefilter_fuzz::Require(rgb.width > 0 && rgb.height > 0, "RGB image has a positive size");
    posefilter_fuzz::Require(rgb.data.size() == std::size_t(rgb.width) * std::size_t(rgb.height) * 3,
                             "RGB data holds width x height x 3 bytes");
  });
  return 0;
}
