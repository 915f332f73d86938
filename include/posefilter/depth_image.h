// posefilter/depth_image.h — depth (and colour) images and their PNG I/O.
//
// Depth is camera z in metres (not range along the ray), row-major, width×height floats.
// 0 means missing; a depth image never holds NaN/inf after loading (loaders reject them).
// 16-bit PNG convention (BOP; docs/ALGORITHM.md §1): metres = png_value × depth_scale; 0 = missing.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace posefilter {

struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> data;  // row-major, metres, 0 = missing

  DepthImage() = default;
  DepthImage(int w, int h, float fill = 0.f) : width(w), height(h), data(size_t(w) * h, fill) {}
  float& at(int u, int v) { return data[size_t(v) * width + u]; }
  float at(int u, int v) const { return data[size_t(v) * width + u]; }
  bool empty() const { return data.empty(); }
  // Number of pixels with a valid (> 0) depth.
  size_t CountValid() const;
};

// 8-bit RGB image, row-major, 3 bytes per pixel (for overlays).
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> data;  // size width*height*3

  RgbImage() = default;
  RgbImage(int w, int h) : width(w), height(h), data(size_t(w) * h * 3, 0) {}
  std::uint8_t* px(int u, int v) { return &data[(size_t(v) * width + u) * 3]; }
};

// A label or instance-id image (segmentation masks): one unsigned id per pixel, row-major,
// 0 = background.
struct LabelImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> ids;  // width × height
};

// The most pixels any PNG reader here decodes (8192 × 8192; a depth image that size is 268 MB
// of floats). A header that declares more is refused before a pixel buffer exists.
inline constexpr long long kMaxPngPixels = 8192LL * 8192LL;

// Reads a 16-bit single-channel PNG; metres = value × depth_scale.
// Throws Error naming the file if missing, not a PNG, corrupt, not single-channel, not 16-bit
// (an 8-bit PNG is a preview image, not depth), larger than kMaxPngPixels, or if depth_scale is
// not finite and positive.
DepthImage LoadDepthPng(const std::string& path, double depth_scale);
// The same for a camera of width × height pixels: a PNG of another size is refused from its
// header, before anything is decoded (the error names the file and both sizes).
DepthImage LoadDepthPng(const std::string& path, double depth_scale, int width, int height);
// Writes a 16-bit PNG with value = round(metres / depth_scale), clamped to 65535; missing → 0.
void SaveDepthPng(const DepthImage& depth, const std::string& path, double depth_scale);
// Reads an 8-bit RGB/RGBA/gray PNG as RGB. Throws Error naming the file on failure.
RgbImage LoadRgbPng(const std::string& path);
void SaveRgbPng(const RgbImage& image, const std::string& path);
// Reads an 8- or 16-bit single-channel PNG of ids (e.g. YCB-Video's label.png). Throws Error
// naming the file if missing, not a PNG, corrupt or not single-channel.
LabelImage LoadLabelPng(const std::string& path);
// Writes a 16-bit single-channel PNG. Throws Error naming the file on I/O failure or a size
// that does not match the ids.
void SaveLabelPng(const LabelImage& labels, const std::string& path);
// Writes `pixels` (row-major, width×height bytes) as an 8-bit single-channel PNG, e.g. a label
// image. Throws Error naming the file if the size does not match or the file cannot be written.
void SaveGray8Png(const std::vector<std::uint8_t>& pixels, int width, int height, const std::string& path);

}  // namespace posefilter
