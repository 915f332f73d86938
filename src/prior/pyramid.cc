// Pyramid layout, box coding, the stage-1 post-process (thesis §7.1, §7.3, eq. 7.1–7.2 [ALGORITHM.md]) and
// raw pyramid file I/O. See include/posefilter/prior.h for the conventions.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/option_check.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/prior.h"

namespace posefilter {
namespace {

std::string RawFieldName(int field, int num_classes) {
  if (field < num_classes) return "class logit " + std::to_string(field);
  static const char* kNames[] = {"tx", "ty", "tw", "th", "confidence c"};
  return kNames[field - num_classes];
}

void CheckLayoutAndClasses(const PyramidLayout& layout, const std::vector<std::string>& classes,
                           const char* what) {
  std::string why;
  if (!layout.IsValid(&why)) throw Error(std::string(what) + ": invalid pyramid layout: " + why);
  if (int(classes.size()) != layout.num_classes) {
    throw Error(std::string(what) + ": " + std::to_string(classes.size()) +
                " class names given but the layout has num_classes = " +
                std::to_string(layout.num_classes));
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Layout

PyramidLayout PyramidLayout::Thesis(int image_width, int image_height, int num_classes) {
  PyramidLayout l;
  l.image_width = image_width;
  l.image_height = image_height;
  l.num_classes = num_classes;
  const int grids[3][2] = {{15, 20}, {30, 40}, {60, 80}};
  for (const auto& g : grids) {
    PyramidLevel lev;
    lev.rows = g[0];
    lev.cols = g[1];
    lev.anchor_w = 4.0 * image_width / g[1];   // 4 strides: 128, 64, 32 px at 640 wide
    lev.anchor_h = 4.0 * image_height / g[0];  // 128, 64, 32 px at 480 high
    l.levels.push_back(lev);
  }
  return l;
}

int PyramidLayout::CellCount() const {
  int n = 0;
  for (const auto& l : levels) n += l.rows * l.cols;
  return n;
}

int PyramidLayout::LevelOffset(int level) const {
  if (level < 0 || level >= int(levels.size())) {
    throw Error("pyramid: level " + std::to_string(level) + " out of range [0, " +
                std::to_string(levels.size()) + ")");
  }
  int off = 0;
  for (int l = 0; l < level; ++l) off += levels[l].rows * levels[l].cols;
  return off;
}

int PyramidLayout::LevelOf(int cell) const {
  int level = 0, row = 0, col = 0;
  CellRowCol(cell, &level, &row, &col);
  return level;
}

void PyramidLayout::CellRowCol(int cell, int* level, int* row, int* col) const {
  int c = cell;
  if (c >= 0) {
    for (int l = 0; l < int(levels.size()); ++l) {
      const int n = levels[l].rows * levels[l].cols;
      if (c < n) {
        *level = l;
        *row = c / levels[l].cols;
        *col = c % levels[l].cols;
        return;
      }
      c -= n;
    }
  }
  throw Error("pyramid: cell " + std::to_string(cell) + " out of range [0, " +
              std::to_string(CellCount()) + ")");
}

int PyramidLayout::CellIndex(int level, int row, int col) const {
  const int off = LevelOffset(level);  // checks level
  const PyramidLevel& l = levels[level];
  if (row < 0 || row >= l.rows || col < 0 || col >= l.cols) {
    throw Error("pyramid: (row " + std::to_string(row) + ", col " + std::to_string(col) +
                ") outside level " + std::to_string(level) + "'s " + std::to_string(l.rows) +
                "×" + std::to_string(l.cols) + " grid");
  }
  return off + row * l.cols + col;
}

double PyramidLayout::StrideX(int level) const {
  LevelOffset(level);
  return double(image_width) / levels[level].cols;
}

double PyramidLayout::StrideY(int level) const {
  LevelOffset(level);
  return double(image_height) / levels[level].rows;
}

Box PyramidLayout::AnchorBox(int cell) const {
  int level = 0, row = 0, col = 0;
  CellRowCol(cell, &level, &row, &col);
  const PyramidLevel& l = levels[level];
  Box b;
  // Centre of the pixels the cell covers (pixel centres at integer coordinates).
  b.cx = (col + 0.5) * StrideX(level) - 0.5;
  b.cy = (row + 0.5) * StrideY(level) - 0.5;
  b.w = l.anchor_w;
  b.h = l.anchor_h;
  return b;
}

bool PyramidLayout::IsValid(std::string* why) const {
  if (image_width < 1 || image_height < 1) {
    return Fail(why, "image_width and image_height must be ≥ 1 (got " +
                         std::to_string(image_width) + "×" + std::to_string(image_height) + ")");
  }
  if (num_classes < 1) return Fail(why, "num_classes must be ≥ 1");
  if (levels.empty()) return Fail(why, "levels must not be empty");
  long long cells = 0;
  for (size_t i = 0; i < levels.size(); ++i) {
    const PyramidLevel& l = levels[i];
    const std::string name = "level " + std::to_string(i);
    if (l.rows < 1 || l.cols < 1) return Fail(why, name + ": rows and cols must be ≥ 1");
    if (l.rows > image_height || l.cols > image_width) {
      return Fail(why, name + ": grid finer than a pixel (" + std::to_string(l.rows) + "×" +
                           std::to_string(l.cols) + " over " + std::to_string(image_width) +
                           "×" + std::to_string(image_height) + ")");
    }
    if (!std::isfinite(l.anchor_w) || !std::isfinite(l.anchor_h) || l.anchor_w <= 0 ||
        l.anchor_h <= 0) {
      return Fail(why, name + ": anchor_w and anchor_h must be finite and > 0");
    }
    cells += (long long)l.rows * l.cols;
  }
  if (cells * (num_classes + 5) > (1LL << 31) / 8) return Fail(why, "pyramid too large");
  return true;
}

// ---------------------------------------------------------------------------------------
// Boxes

Box DecodeBoxUnclipped(const Box& a, const float raw[4]) {
  Box b;
  b.cx = a.cx + double(raw[0]) * a.w;
  b.cy = a.cy + double(raw[1]) * a.h;
  b.w = a.w * std::exp(double(raw[2]));
  b.h = a.h * std::exp(double(raw[3]));
  return b;
}

Box ClipBox(const Box& in, int image_width, int image_height, double max_box_px) {
  Box b = in;
  // exp() may give inf for a huge raw size; std::clamp handles it (NaN is rejected earlier).
  b.w = std::clamp(b.w, 1.0, std::max(1.0, max_box_px));
  b.h = std::clamp(b.h, 1.0, std::max(1.0, max_box_px));
  b.cx = std::clamp(b.cx, 0.0, double(std::max(0, image_width - 1)));
  b.cy = std::clamp(b.cy, 0.0, double(std::max(0, image_height - 1)));
  return b;
}

Box DecodeBox(const Box& anchor, const float raw[4], int image_width, int image_height,
              double max_box_px) {
  return ClipBox(DecodeBoxUnclipped(anchor, raw), image_width, image_height, max_box_px);
}

void EncodeBox(const Box& a, const Box& b, float raw[4]) {
  if (!(std::isfinite(b.w) && std::isfinite(b.h) && b.w > 0 && b.h > 0 &&
        std::isfinite(b.cx) && std::isfinite(b.cy))) {
    throw Error("EncodeBox: box must be finite with width and height > 0");
  }
  if (!(a.w > 0 && a.h > 0)) throw Error("EncodeBox: anchor width and height must be > 0");
  raw[0] = float((b.cx - a.cx) / a.w);
  raw[1] = float((b.cy - a.cy) / a.h);
  raw[2] = float(std::log(b.w / a.w));
  raw[3] = float(std::log(b.h / a.h));
}

namespace {
double IntersectionArea(const Box& a, const Box& b) {
  const double ix = std::min(a.cx + a.w / 2, b.cx + b.w / 2) - std::max(a.cx - a.w / 2, b.cx - b.w / 2);
  const double iy = std::min(a.cy + a.h / 2, b.cy + b.h / 2) - std::max(a.cy - a.h / 2, b.cy - b.h / 2);
  return ix > 0 && iy > 0 ? ix * iy : 0;
}
}  // namespace

double BoxIoU(const Box& a, const Box& b) {
  const double inter = IntersectionArea(a, b);
  if (inter <= 0) return 0;
  const double uni = a.w * a.h + b.w * b.h - inter;
  return uni > 0 ? inter / uni : 0;
}

double BoxCoverage(const Box& anchor, const Box& box) {
  const double area = anchor.w * anchor.h;
  if (!(area > 0)) return 0;
  return std::min(1.0, IntersectionArea(anchor, box) / area);
}

// ---------------------------------------------------------------------------------------
// Post-process

bool PostProcessOptions::IsValid(std::string* why) const {
  if (!std::isfinite(max_box_px) || max_box_px < 1) {
    return Fail(why, "max_box_px must be finite and ≥ 1 pixel");
  }
  return true;
}

int Prior::ClassIndex(const std::string& name) const {
  for (size_t i = 0; i < classes.size(); ++i)
    if (classes[i] == name) return int(i);
  return -1;
}

double Prior::ClassMass(int cls) const {
  if (cls < 0 || cls >= layout.num_classes) {
    throw Error("prior: class index " + std::to_string(cls) + " out of range");
  }
  double s = 0;
  const int n = layout.CellCount();
  for (int c = 0; c < n; ++c) s += Prob(c, cls);
  return s;
}

Prior PostProcessPyramid(const std::vector<float>& raw, const PyramidLayout& layout,
                         const std::vector<std::string>& classes,
                         const PostProcessOptions& opt) {
  CheckLayoutAndClasses(layout, classes, "post-process");
  std::string why;
  if (!opt.IsValid(&why)) throw Error("post-process options: " + why);
  const int cells = layout.CellCount();
  const int nc = layout.num_classes;
  const int per = layout.RawValuesPerCell();
  if (raw.size() != size_t(cells) * per) {
    throw Error("post-process: raw pyramid holds " + std::to_string(raw.size()) +
                " values, expected " + std::to_string(size_t(cells) * per) + " (" +
                std::to_string(cells) + " cells × " + std::to_string(per) + ")");
  }
  for (size_t i = 0; i < raw.size(); ++i) {
    if (!std::isfinite(raw[i])) {
      throw Error("post-process: raw pyramid value " + std::to_string(i) + " (cell " +
                  std::to_string(i / per) + ", " + RawFieldName(int(i % per), nc) +
                  ") is not finite");
    }
  }

  Prior p;
  p.layout = layout;
  p.classes = classes;
  p.boxes.resize(cells);
  p.prob.resize(size_t(cells) * nc);
  std::vector<double> e(nc);
  for (int cell = 0; cell < cells; ++cell) {
    const float* r = &raw[size_t(cell) * per];
    // eq. 7.2 [ALGORITHM.md] as softmax(p)·sigmoid(−c): subtract the max logit so e^{p_j − m} ≤ 1.
    double m = r[0];
    for (int j = 1; j < nc; ++j) m = std::max(m, double(r[j]));
    double sum = 0;
    for (int j = 0; j < nc; ++j) sum += e[j] = std::exp(double(r[j]) - m);
    // eq. 7.1 [ALGORITHM.md]: 1/(1 + e^c) = sigmoid(−c), evaluated without overflow for either sign of c.
    const double c = r[nc + 4];
    const double sig = c > 0 ? std::exp(-c) / (1 + std::exp(-c)) : 1 / (1 + std::exp(c));
    const double scale = sig / sum;
    for (int j = 0; j < nc; ++j) p.prob[size_t(cell) * nc + j] = float(e[j] * scale);
    p.boxes[cell] = DecodeBox(layout.AnchorBox(cell), r + nc, layout.image_width,
                              layout.image_height, opt.max_box_px);
  }
  return p;
}

Prior UniformPrior(const PyramidLayout& layout, const std::vector<std::string>& classes,
                   double max_box_px) {
  CheckLayoutAndClasses(layout, classes, "uniform prior");
  if (!std::isfinite(max_box_px) || max_box_px < 1) {
    throw Error("uniform prior: max_box_px must be finite and ≥ 1 pixel");
  }
  Prior p;
  p.layout = layout;
  p.classes = classes;
  const int cells = layout.CellCount();
  p.prob.assign(size_t(cells) * layout.num_classes, float(1.0 / cells));
  p.boxes.resize(cells);
  const float zero[4] = {0, 0, 0, 0};
  for (int c = 0; c < cells; ++c) {
    p.boxes[c] = DecodeBox(layout.AnchorBox(c), zero, layout.image_width, layout.image_height,
                           max_box_px);
  }
  return p;
}

// ---------------------------------------------------------------------------------------
// Raw file I/O (float32 little-endian, no header)

namespace {

// The file's little-endian float32 values to this machine's order and back (a no-op on
// little-endian machines).
void SwapLittleEndian(std::vector<float>* values) {
  if constexpr (std::endian::native == std::endian::big) {
    for (float& f : *values) {
      std::uint32_t u;
      std::memcpy(&u, &f, 4);
      u = (u >> 24) | ((u >> 8) & 0xff00u) | ((u << 8) & 0xff0000u) | (u << 24);
      std::memcpy(&f, &u, 4);
    }
  }
}

}  // namespace

std::vector<float> ReadRawPyramid(const std::string& path, const PyramidLayout& layout) {
  std::string why;
  if (!layout.IsValid(&why)) throw Error(path + ": invalid pyramid layout: " + why);
  const size_t n = size_t(layout.CellCount()) * layout.RawValuesPerCell();
  const size_t expected = n * sizeof(float);
  const std::string expect_msg = "expected " + std::to_string(expected) + " bytes (" +
                                 std::to_string(layout.CellCount()) + " cells × " +
                                 std::to_string(layout.RawValuesPerCell()) + " float32)";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(path + ": raw pyramid file not found or not a regular file; " + expect_msg);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open raw pyramid file");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0 || size_t(size) != expected) {
    throw Error(path + ": raw pyramid file holds " + std::to_string(size) + " bytes, " +
                expect_msg);
  }
  in.seekg(0);
  std::vector<float> raw(n);
  in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(expected));
  if (!in) throw Error(path + ": read error in raw pyramid file");
  SwapLittleEndian(&raw);
  const int per = layout.RawValuesPerCell();
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(raw[i])) {
      throw Error(path + ": raw pyramid value " + std::to_string(i) + " (cell " +
                  std::to_string(i / per) + ", " +
                  RawFieldName(int(i % per), layout.num_classes) + ") is NaN or infinite");
    }
  }
  return raw;
}

void WriteRawPyramid(const std::vector<float>& raw, const PyramidLayout& layout,
                     const std::string& path) {
  std::string why;
  if (!layout.IsValid(&why)) throw Error(path + ": invalid pyramid layout: " + why);
  const size_t n = size_t(layout.CellCount()) * layout.RawValuesPerCell();
  if (raw.size() != n) {
    throw Error(path + ": raw pyramid to write holds " + std::to_string(raw.size()) +
                " values, expected " + std::to_string(n));
  }
  std::vector<float> out = raw;
  SwapLittleEndian(&out);
  WriteFileAtomically(path, [&](std::ostream& o) {
    o.write(reinterpret_cast<const char*>(out.data()), std::streamsize(n * sizeof(float)));
  });
}

std::vector<std::string> YcbVideoClassNames() {
  return {"002_master_chef_can", "003_cracker_box",     "004_sugar_box",
          "005_tomato_soup_can", "006_mustard_bottle",  "007_tuna_fish_can",
          "008_pudding_box",     "009_gelatin_box",     "010_potted_meat_can",
          "011_banana",          "019_pitcher_base",    "021_bleach_cleanser",
          "024_bowl",            "025_mug",             "035_power_drill",
          "036_wood_block",      "037_scissors",        "040_large_marker",
          "051_large_clamp",     "052_extra_large_clamp", "061_foam_brick"};
}

}  // namespace posefilter
