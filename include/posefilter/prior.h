// posefilter/prior.h — the stage-1 prior: a per-cell, per-class probability heatmap with a box
// per cell (thesis §7.1, §7.3; docs/ALGORITHM.md §2), in its three forms:
//   1. raw pyramid output (thesis format) → PostProcessPyramid;
//   2. 2D detections (class, score, box)  → DetectionsToRawPyramid → PostProcessPyramid;
//   3. none                               → UniformPrior.
//
// Pixel coordinates: the camera's (camera.h, OpenCV): the centre of pixel (i, j) is (u, v) =
// (i, j), so a W×H image spans [-0.5, W-0.5] × [-0.5, H-0.5]. Boxes and detections use the
// same coordinates (a BOP bbox [x, y, w, h] computed from projected points is in them).
//
// The pyramid: levels of grids laid over the whole image (thesis Fig. 7.2a; 15×20, 30×40,
// 60×80 = 6300 cells). Cells are numbered level by level, row-major within a level:
//   cell = Σ_{l' < level} rows_l'·cols_l' + row·cols + col.
// Level strides are image size / grid size (640/20 = 32 px, 16 px, 8 px for the thesis).
// Anchor of a cell: centred on the cell — cx = (col + 0.5)·stride_x − 0.5,
// cy = (row + 0.5)·stride_y − 0.5 (the centre of the pixels the cell covers) — and sized
// 4 strides (thesis layout: 128, 64, 32 px), so the three levels cover objects of ~40–200 px.
#pragma once

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace posefilter {

// A pose hypothesis from a stage 1 that proposes poses (the PPF proposals of `--prior auto`,
// posefilter/auto_prior.h): object → camera, and a score > 0 (relative: seeds are drawn in
// proportion to it).
struct PoseSeed {
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();
  double score = 1;
};

// An axis-aligned box in pixels: centre (cx, cy) and size (w, h).
struct Box {
  double cx = 0, cy = 0, w = 0, h = 0;
};

struct PyramidLevel {
  int rows = 0, cols = 0;               // grid size of the level
  double anchor_w = 0, anchor_h = 0;    // anchor box size, pixels
};

struct PyramidLayout {
  int image_width = 640, image_height = 480;  // pixels
  int num_classes = 21;                       // class logits per cell
  std::vector<PyramidLevel> levels;           // coarse to fine

  // The thesis pyramid (15×20, 30×40, 60×80) over an image of the given size, anchors 4
  // strides wide and high (128, 64, 32 px at 640×480).
  static PyramidLayout Thesis(int image_width = 640, int image_height = 480,
                              int num_classes = 21);

  int CellCount() const;                          // Σ rows·cols
  int RawValuesPerCell() const { return num_classes + 5; }
  // Cell ↔ (level, row, col). Out-of-range arguments throw Error.
  int LevelOf(int cell) const;
  void CellRowCol(int cell, int* level, int* row, int* col) const;
  int CellIndex(int level, int row, int col) const;
  int LevelOffset(int level) const;               // index of the level's first cell
  double StrideX(int level) const;                // image_width / cols, pixels
  double StrideY(int level) const;                // image_height / rows, pixels
  // The cell's anchor: centred on the cell, sized (anchor_w, anchor_h) of its level.
  Box AnchorBox(int cell) const;
  // True when image size, num_classes and every level (rows, cols ≥ 1 and not finer than a
  // pixel, anchors finite and > 0) are sensible, and there is at least one level.
  bool IsValid(std::string* why) const;
};

// Raw values per cell for the thesis's 21 classes: 21 logits + 4 box params + 1 confidence.
inline constexpr int kRawValuesPerCell = 26;

// Raw pyramid layout (thesis Fig. 7.2b): per cell, in cell order, num_classes class logits
// p_j, then 4 raw box parameters (tx, ty, tw, th), then 1 confidence c:
//   raw[cell·(num_classes+5) + j]               p_j
//   raw[cell·(num_classes+5) + num_classes + k] tx, ty, tw, th for k = 0..3
//   raw[cell·(num_classes+5) + num_classes + 4] c

struct PostProcessOptions {
  double max_box_px = 200;  // decoded box width/height are clipped to this (§7.1), pixels, > 0
  bool IsValid(std::string* why) const;
};

// The post-processed prior: what stage 2 consumes.
struct Prior {
  PyramidLayout layout;
  std::vector<std::string> classes;  // class names, size layout.num_classes
  std::vector<Box> boxes;            // per cell: decoded and clipped box, pixels
  std::vector<float> prob;           // cells × num_classes: prob[cell·num_classes + j]

  float Prob(int cell, int cls) const { return prob[size_t(cell) * layout.num_classes + cls]; }
  int ClassIndex(const std::string& name) const;  // −1 if absent
  double ClassMass(int cls) const;                // Σ over cells of Prob(cell, cls)
};

// Box decoding (standard SSD/YOLO-style; the thesis does not give it), anchor a:
//   cx = a.cx + tx·a.w,  cy = a.cy + ty·a.h,  w = a.w·e^tw,  h = a.h·e^th,
// then w, h clipped to [1, max_box_px] and the centre clamped into the image, i.e. to
// [0, image_width−1] × [0, image_height−1] (so it packs in 10 bits, §7.1).
// DecodeBoxUnclipped is the formula alone; EncodeBox is its exact inverse:
//   tx = (cx − a.cx)/a.w, ty = (cy − a.cy)/a.h, tw = ln(w/a.w), th = ln(h/a.h).
// EncodeBox throws Error if the box size is not finite and positive.
Box DecodeBoxUnclipped(const Box& anchor, const float raw[4]);
Box ClipBox(const Box& box, int image_width, int image_height, double max_box_px);
Box DecodeBox(const Box& anchor, const float raw[4], int image_width = 640,
              int image_height = 480, double max_box_px = 200);
void EncodeBox(const Box& anchor, const Box& box, float raw[4]);

// Post-process (eq. 7.1–7.2 [ALGORITHM.md]), per cell:
//   Prob_j = e^{p_j} / (Σ_i e^{p_i} · (1 + e^c))  =  softmax_j(p) · sigmoid(−c),
// computed stably (max logit subtracted; sigmoid evaluated on the side that cannot
// overflow). So c acts as a *background* logit: a large c scales every class of the cell
// down, and Σ_j Prob_j = sigmoid(−c) ≤ 1. Boxes: DecodeBox with the cell's anchor.
// Throws Error on an invalid layout/options, raw.size() ≠ CellCount·(num_classes+5),
// classes.size() ≠ num_classes, or a non-finite raw value (naming cell and field).
Prior PostProcessPyramid(const std::vector<float>& raw, const PyramidLayout& layout,
                         const std::vector<std::string>& classes,
                         const PostProcessOptions& opt = {});

// Raw pyramid file: float32 little-endian, exactly CellCount·(num_classes+5) values, no
// header. Errors (missing file, wrong size, NaN/inf) name the file and the expected byte
// count / the offending cell.
std::vector<float> ReadRawPyramid(const std::string& path, const PyramidLayout& layout);
void WriteRawPyramid(const std::vector<float>& raw, const PyramidLayout& layout,
                     const std::string& path);

// One 2D detection. bbox top-left (x, y) and size (w, h), pixels (BOP convention).
struct Detection {
  std::string cls;
  double score = 0;  // in [0, 1]
  double x = 0, y = 0, w = 0, h = 0;
};

// Detections file: [{"class": name, "score": s, "bbox": [x, y, w, h]}, ...] or
// {"detections": [...]}. score must be in [0, 1], bbox finite with w, h > 0. Errors name the
// file, the entry index and the key. An empty list throws "<file> holds no detections"
// unless allow_empty (an empty prior file is almost always a mistake).
std::vector<Detection> ReadDetectionsJson(const std::string& path, bool allow_empty = false);
// Writes {"detections": [...]}.
void WriteDetectionsJson(const std::vector<Detection>& detections, const std::string& path);

struct DetectionPriorOptions {
  // Probability floor: every (cell, class) keeps exactly this probability where no detection
  // of the class overlaps the cell — low scores stay low but non-zero, nothing is
  // hard-thresholded (as the thesis's heatmap, §1.1.1; docs/ALGORITHM.md §2). In [1e-6, 1)
  // and num_classes·floor_prob < 1.
  double floor_prob = 1e-5;
  double max_box_px = 200;  // decoded box clip, pixels (as PostProcessOptions)
  bool IsValid(std::string* why) const;
};

// Detections → raw pyramid, so both prior paths share PostProcessPyramid. Per cell:
//   q_j = max(floor, max over detections d of class j of score_d · coverage(anchor, box_d)),
// coverage = area(anchor ∩ box_d) / area(anchor): the fraction of the cell's anchor the
// detection covers (1 for cells inside the box, falling off smoothly across its edge; on
// each level the class mass of a detection is ≈ score · box area / stride², so a confident
// detection holds most of the class's mass while every other cell keeps the floor).
// If Σ_j q_j > 1 the part above the floor is scaled down so Σ_j q_j = 1. Then
//   p_j = ln q_j,  c = ln((1 − T)/T) with T = Σ_j q_j (the cell's objectness ≈ the best
//   detection score there), clamped to [−16, 16] (the hw exp ROM's range),
// so that PostProcessPyramid gives back Prob_j = q_j (up to the c clamp and float32).
// Box params: EncodeBox of the detection with the highest score·coverage at the cell, where
// some detection overlaps the cell's anchor; zeros (= the anchor box) otherwise.
// Throws Error for an unknown class name (naming it), an invalid detection (naming its
// index), or invalid options/layout. An empty list gives a uniform prior (floor everywhere).
std::vector<float> DetectionsToRawPyramid(const std::vector<Detection>& detections,
                                          const PyramidLayout& layout,
                                          const std::vector<std::string>& classes,
                                          const DetectionPriorOptions& opt = {});
// = PostProcessPyramid(DetectionsToRawPyramid(...)).
Prior PriorFromDetections(const std::vector<Detection>& detections, const PyramidLayout& layout,
                          const std::vector<std::string>& classes,
                          const DetectionPriorOptions& opt = {});

// The class list of a prior made for the objects `objects` from `detections`: the objects' names
// first, then the detections' other classes, each once, in order of first appearance.
std::vector<std::string> ClassesForObjects(const std::vector<std::string>& objects,
                                           const std::vector<Detection>& detections);

// Checks detections against the objects to estimate on a width × height image. Throws Error,
// starting with `source` (the file or argument), when no object has a detection on the image (the
// prior would say nothing about any of them; the message lists both sets of names). Returns a
// warning, also starting with `source`, for each detection wholly off the image and for each
// object without a detection on it (its prior is the uniform floor).
std::vector<std::string> CheckDetectionsForObjects(const std::vector<Detection>& detections,
                                                   const std::vector<std::string>& objects, int width, int height,
                                                   const std::string& source);

// No prior: Prob = 1/CellCount for every cell and class; boxes = anchor boxes clipped.
Prior UniformPrior(const PyramidLayout& layout, const std::vector<std::string>& classes,
                   double max_box_px = 200);

// IoU of two boxes (0 when either has no area).
double BoxIoU(const Box& a, const Box& b);
// area(anchor ∩ box) / area(anchor), in [0, 1] (0 when the anchor has no area).
double BoxCoverage(const Box& anchor, const Box& box);
// Detection (top-left x, y, size w, h) → Box (centre, size).
Box DetectionBox(const Detection& d);

// The 21 YCB-Video class names in official order (002_master_chef_can … 061_foam_brick).
std::vector<std::string> YcbVideoClassNames();

}  // namespace posefilter
