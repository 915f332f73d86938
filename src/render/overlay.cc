#include "posefilter/overlay.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <vector>

#include "posefilter/render.h"

namespace posefilter {

namespace {

// A 5×7 pixel font for legends: one row per byte, bit 4 = the leftmost column. Lowercase
// letters draw as capitals; a character not listed draws as '?'.
struct Glyph {
  char c;
  std::uint8_t rows[7];
};
constexpr Glyph kFont[] = {
    {'A', {14, 17, 17, 31, 17, 17, 17}}, {'B', {30, 17, 17, 30, 17, 17, 30}}, {'C', {14, 17, 16, 16, 16, 17, 14}},
    {'D', {30, 17, 17, 17, 17, 17, 30}}, {'E', {31, 16, 16, 30, 16, 16, 31}}, {'F', {31, 16, 16, 30, 16, 16, 16}},
    {'G', {14, 17, 16, 23, 17, 17, 15}}, {'H', {17, 17, 17, 31, 17, 17, 17}}, {'I', {14, 4, 4, 4, 4, 4, 14}},
    {'J', {7, 2, 2, 2, 2, 18, 12}},      {'K', {17, 18, 20, 24, 20, 18, 17}}, {'L', {16, 16, 16, 16, 16, 16, 31}},
    {'M', {17, 27, 21, 21, 17, 17, 17}}, {'N', {17, 17, 25, 21, 19, 17, 17}}, {'O', {14, 17, 17, 17, 17, 17, 14}},
    {'P', {30, 17, 17, 30, 16, 16, 16}}, {'Q', {14, 17, 17, 17, 21, 18, 13}}, {'R', {30, 17, 17, 30, 20, 18, 17}},
    {'S', {15, 16, 16, 14, 1, 1, 30}},   {'T', {31, 4, 4, 4, 4, 4, 4}},       {'U', {17, 17, 17, 17, 17, 17, 14}},
    {'V', {17, 17, 17, 17, 17, 10, 4}},  {'W', {17, 17, 17, 21, 21, 21, 10}}, {'X', {17, 17, 10, 4, 10, 17, 17}},
    {'Y', {17, 17, 10, 4, 4, 4, 4}},     {'Z', {31, 1, 2, 4, 8, 16, 31}},     {'0', {14, 17, 19, 21, 25, 17, 14}},
    {'1', {4, 12, 4, 4, 4, 4, 14}},      {'2', {14, 17, 1, 2, 4, 8, 31}},     {'3', {31, 2, 4, 2, 1, 17, 14}},
    {'4', {2, 6, 10, 18, 31, 2, 2}},     {'5', {31, 16, 30, 1, 1, 17, 14}},   {'6', {6, 8, 16, 30, 17, 17, 14}},
    {'7', {31, 1, 2, 4, 8, 8, 8}},       {'8', {14, 17, 17, 14, 17, 17, 14}}, {'9', {14, 17, 17, 15, 1, 2, 12}},
    {' ', {0, 0, 0, 0, 0, 0, 0}},        {'-', {0, 0, 0, 31, 0, 0, 0}},       {'_', {0, 0, 0, 0, 0, 0, 31}},
    {'.', {0, 0, 0, 0, 0, 12, 12}},      {':', {0, 12, 12, 0, 12, 12, 0}},    {',', {0, 0, 0, 0, 12, 4, 8}},
    {'(', {2, 4, 8, 8, 8, 4, 2}},        {')', {8, 4, 2, 2, 2, 4, 8}},        {'/', {1, 1, 2, 4, 8, 16, 16}},
    {'%', {24, 25, 2, 4, 8, 19, 3}},     {'?', {14, 17, 1, 2, 4, 0, 4}},
};

const Glyph& GlyphOf(char c) {
  const char u = char(std::toupper(static_cast<unsigned char>(c)));
  for (const Glyph& g : kFont)
    if (g.c == u) return g;
  return kFont[sizeof kFont / sizeof kFont[0] - 1];
}

// Fills the rectangle [x0, x1) × [y0, y1), cut to the image, with `color` at `opacity`.
void FillRect(RgbImage* image, int x0, int y0, int x1, int y1, std::array<std::uint8_t, 3> color, double opacity) {
  for (int v = std::max(0, y0); v < std::min(image->height, y1); ++v)
    for (int u = std::max(0, x0); u < std::min(image->width, x1); ++u) {
      std::uint8_t* p = image->px(u, v);
      for (int c = 0; c < 3; ++c) p[c] = std::uint8_t(std::lround((1 - opacity) * p[c] + opacity * color[c]));
    }
}

}  // namespace

void DrawLegend(RgbImage* image, const std::vector<LegendEntry>& entries) {
  if (entries.empty()) return;
  // Glyphs at scale 2 on small images, 3 from 1000 px wide; a swatch of one line height.
  const int s = image->width >= 1000 ? 3 : 2;
  const int line = 9 * s, pad = 2 * s;
  std::size_t longest = 0;
  for (const LegendEntry& e : entries) longest = std::max(longest, e.text.size());
  const int width = pad + line + pad + int(longest) * 6 * s + pad;
  const int height = pad + int(entries.size()) * line + pad;
  FillRect(image, 0, 0, width, height, {0, 0, 0}, 0.7);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int y = pad + int(i) * line;
    FillRect(image, pad, y + s, pad + line - 2 * s, y + line - s, entries[i].color, 1.0);
    int x = pad + line + pad;
    for (char c : entries[i].text) {
      const Glyph& g = GlyphOf(c);
      for (int r = 0; r < 7; ++r)
        for (int b = 0; b < 5; ++b)
          if (g.rows[r] & (16 >> b)) FillRect(image, x + b * s, y + s + r * s, x + (b + 1) * s, y + s + (r + 1) * s, {255, 255, 255}, 1.0);
      x += 6 * s;
    }
  }
}

RgbImage ShadeDepth(const DepthImage& depth) {
  RgbImage img(depth.width, depth.height);
  float lo = INFINITY, hi = 0;
  for (float z : depth.data)
    if (z > 0) lo = std::min(lo, z), hi = std::max(hi, z);
  const float range = hi > lo ? hi - lo : 1.f;
  for (int v = 0; v < depth.height; ++v)
    for (int u = 0; u < depth.width; ++u) {
      const float z = depth.at(u, v);
      const std::uint8_t g = z > 0 ? std::uint8_t(60 + 195 * (1 - (z - lo) / range)) : 0;
      std::uint8_t* p = img.px(u, v);
      p[0] = p[1] = p[2] = g;
    }
  return img;
}

void DrawPoseOverlay(RgbImage* image, const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj,
                     const Camera& camera, std::array<std::uint8_t, 3> color) {
  DepthImage z(camera.width, camera.height, 0.f);
  std::vector<int> mask;
  RenderDepth(mesh, T_cam_obj, camera, &z, &mask, 1);
  const int w = std::min(image->width, camera.width), h = std::min(image->height, camera.height);
  auto inside = [&](int u, int v) {
    return u >= 0 && v >= 0 && u < w && v < h && mask[std::size_t(v) * camera.width + u] == 1;
  };
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      if (!inside(u, v)) continue;
      const bool edge = !inside(u - 1, v) || !inside(u + 1, v) || !inside(u, v - 1) || !inside(u, v + 1);
      std::uint8_t* p = image->px(u, v);
      for (int c = 0; c < 3; ++c)
        p[c] = edge ? color[c] : std::uint8_t(0.65 * p[c] + 0.35 * color[c]);
    }
}

}  // namespace posefilter
