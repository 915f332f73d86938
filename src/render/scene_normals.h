// src/render/scene_normals.h — scene normals per rectangle and on demand (internal).
//
// ComputeSceneNormals (render.h) computes the normals of every depth pixel. The filter needs
// them only where an ICP weighing renders (the parents of the ICP move and the final polish:
// windows around the object), so SceneNormalTiles computes them tile by tile, the first time
// a window asks for a tile, with the same per-pixel code (NormalsInRect): every value it holds
// is ComputeSceneNormals's.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/render.h"

namespace posefilter::render {

// Writes the unit normals (camera frame, 3 floats per pixel, zeros where there is none; the
// rules of ComputeSceneNormals) of the pixels u0 ≤ u < u1, v0 ≤ v < v1 of `depth` into `out`,
// a width × height × 3 array laid out like the depth image. The rectangle must lie inside
// the image; only its pixels are written.
void NormalsInRect(const DepthImage& depth, const Camera& camera, int u0, int v0, int u1, int v1, float* out);

// Scene normals of one depth image, computed on demand in square tiles of kTile pixels.
// data() is a full-image array (ComputeSceneNormals's layout) whose prepared tiles hold the
// normals and whose other pixels are unset: read only pixels of windows passed to Prepare.
class SceneNormalTiles {
 public:
  static constexpr int kTile = 32;  // pixels per tile side
  SceneNormalTiles() = default;
  // For a width × height depth image. Allocates the array without touching it (pages are
  // faulted in only where tiles are computed).
  SceneNormalTiles(int width, int height);

  // Computes, from `depth` (width × height; the same image and camera at every call), every
  // tile that overlaps one of `windows` (each clipped to the image) and is not computed yet;
  // `threads` workers over those tiles (0 or less = all cores). Not thread-safe: call it from
  // one thread, before the weighings that read the windows.
  void Prepare(const DepthImage& depth, const Camera& camera, const std::vector<PixelRect>& windows, int threads);
  const float* data() const { return normals_.get(); }
  int tiles_computed() const { return computed_; }  // so far
  int tiles_total() const { return tiles_u_ * tiles_v_; }

 private:
  int width_ = 0, height_ = 0;
  int tiles_u_ = 0, tiles_v_ = 0;
  std::unique_ptr<float[]> normals_;  // width × height × 3, uninitialised outside computed tiles
  std::vector<std::uint8_t> done_;    // per tile (row-major over tiles): computed
  int computed_ = 0;
};

}  // namespace posefilter::render
