// Fuzz target: LoadDepthPng (include/posefilter/depth_image.h), the 16-bit (or 8-bit) depth PNG
// reader of `estimate --depth` and of every dataset image. Seeds: fuzz/corpus/depth_png_fuzz/.
// Chunk CRCs are recomputed before the read (fuzz_util.h, WithPngCrcsFixed); dictionary:
// fuzz/png.dict.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_util.h"
#include "posefilter/depth_image.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static posefilter_fuzz::ScratchFile file("depth_png", ".png");
  const std::vector<std::uint8_t> png = posefilter_fuzz::WithPngCrcsFixed(data, size);
  const std::string& path = file.Write(png.data(), png.size());
  posefilter_fuzz::ReadOrError(path, [&] {
    const posefilter::DepthImage d = posefilter::LoadDepthPng(path, 0.001);
    posefilter_fuzz::Require(d.width > 0 && d.height > 0, "depth image has a positive size");
    posefilter_fuzz::Require(d.data.size() == std::size_t(d.width) * std::size_t(d.height),
                             "depth data holds width x height values");
    for (float v : d.data) posefilter_fuzz::Require(std::isfinite(v) && v >= 0.f, "depth is finite and >= 0");
  });
  return 0;
}
