// posefilter/auto_prior.h — a stage 1 without a detector (`--prior auto`): candidate object
// regions found in the depth image alone, turned into detections for the filter's prior.
//
// Method (docs/ALGORITHM.md, "No detector"):
//   1. the support surfaces (FindSupportSurfaces: the floor, a table, a chair's tablet, a
//      shelf's boards) and the large planar structure (walls) are found and their pixels
//      taken out;
//   2. each remaining valid pixel is measured against the support just below it
//      (SupportSurfaces::Below); those between min_height_m and max_height_m above it (all
//      remaining valid pixels when there is no support; none that stand over no support) are
//      grouped into regions: 4-connected pixels whose depths differ by at most
//      max_step_fraction · z;
//   3. regions of fewer than min_pixels pixels are dropped;
//   4. for each object (name, diameter in metres), every region gives detections of the
//      object's projected size s = diameter · f / z (z the region's median depth): a region
//      that fits in fit_factor · s is one detection (its bounding box); a larger region (objects
//      that touch) is covered by s × s boxes on a grid of stride s / 2, each kept where region
//      pixels fill at least min_fill of it. Scores: fit_score for a region that fits (less
//      for a region much smaller than s, see full_size), and tile_score times the box's fill
//      for a tile (times tile_weight_when_one_fits where another of the objects fits the
//      whole region: it is more likely that object than several touching ones).
//   5. for each object with a PPF model (posefilter/ppf.h), point-pair-feature voting over
//      each region's points gives pose proposals: each becomes a pose seed of the object
//      (SceneInput::seeds, score = its votes relative to the object's best proposal) and a
//      detection (the box of the model's points projected at the pose, score proposal_score
//      times that relative score), so a small object on a larger one's face, which step 4
//      sees only as a tile of the larger region, gets its own box and starting poses.
// The detections go into PriorFromDetections like a detector's; the filter's niches keep the
// hypotheses apart until the fine threshold ranks them. Deterministic; metres, pixels.
// BuildStage1 (posefilter/stage1.h, Stage1Kind::kAuto) makes the stage 1 of `--prior auto`
// from ProposeAuto: each object's PPF model, the prior of the detections, the pose seeds.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/option_rows.h"
#include "posefilter/ppf.h"
#include "posefilter/prior.h"
#include "posefilter/support_plane.h"

namespace posefilter {

struct AutoPriorOptions {
  SupportSurfaceOptions surfaces;    // step 1's support surfaces (FindSupportSurfaces)
  double min_height_m = 0.004;       // above the support's band: lower points are the support's, m
  double max_height_m = 0.6;         // higher points above their support are not objects, m
  double max_step_fraction = 0.03;   // neighbours in one region: |Δz| ≤ this · z, (0, 1]
  int min_pixels = 40;               // smaller regions are noise, ≥ 1
  double fit_factor = 1.2;           // a region within fit_factor · s on both sides is one box, ≥ 1
  double min_fill = 0.2;             // a tile is kept where region pixels fill this much, (0, 1]
  double fit_score = 0.9;            // detection scores, (0, 1]
  double tile_score = 0.6;
  // A region that fits but spans less than full_size · s scores less, in proportion, down to
  // min_size_weight · fit_score: it is a smaller object, or a sliver of this one.
  double full_size = 0.6;
  double min_size_weight = 0.25;
  // Tiles of a region that one of the objects fits whole score this fraction of the above.
  double tile_weight_when_one_fits = 0.15;
  PpfOptions ppf;                    // step 5's voting
  double proposal_score = 0.9;       // detection score of an object's best proposal, (0, 1]
  int max_seeds = 24;                // pose seeds kept per object (most votes first), ≥ 1
  bool IsValid(std::string* why) const;
};

// AutoPriorOptions' own fields (not the nested surfaces' and PPF options) as rows
// (posefilter/option_rows.h): CLI flag, Python keyword, range, help. IsValid checks their ranges
// from these rows, then min_height_m < max_height_m and the nested options' IsValid.
std::span<const OptionInfo> AutoPriorOptionTable();

// One region of step 2–3: pixel bounding box [x0, x1) × [y0, y1), pixel count, median depth.
struct CandidateRegion {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int pixels = 0;
  double median_z = 0;  // metres
  int support = -1;     // the support most of its pixels stand on (index into SupportSurfaces::patches), −1 none
};

// Steps 1–3. `labels` (optional) receives width × height region indices + 1 (0 = no region).
// Throws Error on invalid options or a depth image whose size differs from the camera's.
std::vector<CandidateRegion> FindCandidateRegions(const DepthImage& depth, const Camera& camera,
                                                  const AutoPriorOptions& opt = {},
                                                  std::vector<int>* labels = nullptr);
// The same with the support surfaces found already (FindSupportSurfaces with opt.surfaces).
std::vector<CandidateRegion> FindCandidateRegions(const DepthImage& depth, const Camera& camera,
                                                  const SupportSurfaces& surfaces, const AutoPriorOptions& opt,
                                                  std::vector<int>* labels = nullptr);

// Step 4 for the objects (name, diameter in metres, > 0): the detections, by region then
// object. Empty when there is no region (nothing stands above the table): the caller reports
// "no candidates". Throws Error on invalid options or an object without a positive diameter.
std::vector<Detection> AutoDetections(const DepthImage& depth, const Camera& camera,
                                      const std::vector<std::pair<std::string, double>>& objects,
                                      const AutoPriorOptions& opt = {});

// One object the stage 1 looks for.
struct AutoObject {
  std::string name;
  double diameter = 0;            // metres, > 0
  const PpfModel* ppf = nullptr;  // step 5's model (LoadOrBuildPpfModel); nullptr = steps 1–4 only
};

// Steps 1–5: the detections (step 4's, then one per pose proposal) and, per object (in the
// objects' order), its pose seeds, most votes first (at most opt.max_seeds). Throws Error as
// AutoDetections does.
struct AutoProposals {
  std::vector<Detection> detections;
  std::vector<std::vector<PoseSeed>> seeds;
};
AutoProposals ProposeAuto(const DepthImage& depth, const Camera& camera, const std::vector<AutoObject>& objects,
                          const AutoPriorOptions& opt = {});

}  // namespace posefilter
