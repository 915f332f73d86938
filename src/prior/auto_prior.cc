// prior/auto_prior.cc — stage 1 without a detector: candidate regions above the support plane
// and the detections they give each object (posefilter/auto_prior.h).
#include "posefilter/auto_prior.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "posefilter/error.h"
#include "posefilter/render.h"

namespace posefilter {

std::vector<CandidateRegion> FindCandidateRegions(const DepthImage& depth, const Camera& camera,
                                                  const AutoPriorOptions& opt, std::vector<int>* labels_out) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("auto prior: " + why);
  if (depth.width != camera.width || depth.height != camera.height)
    throw Error("auto prior: the depth image's size differs from the camera's");
  return FindCandidateRegions(depth, camera, FindSupportSurfaces(depth, camera, opt.surfaces), opt, labels_out);
}

std::vector<CandidateRegion> FindCandidateRegions(const DepthImage& depth, const Camera& camera,
                                                  const SupportSurfaces& surfaces, const AutoPriorOptions& opt,
                                                  std::vector<int>* labels_out) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("auto prior: " + why);
  if (depth.width != camera.width || depth.height != camera.height)
    throw Error("auto prior: the depth image's size differs from the camera's");
  const int W = depth.width, H = depth.height;
  // Foreground: valid pixels off every patch, standing min_height_m–max_height_m above the band
  // of the support just below them (every valid pixel off the patches without a support).
  const std::vector<int> on = SupportSurfacePixels(depth, camera, surfaces, opt.surfaces);
  std::vector<std::uint8_t> fg(std::size_t(W) * H, 0);
  std::vector<std::int8_t> support_of(std::size_t(W) * H, -1);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const float z = depth.at(u, v);
      const std::size_t i = std::size_t(v) * W + u;
      if (!(z > 0) || on[i]) continue;
      if (surfaces.supports > 0) {
        const Eigen::Vector3d p = camera.Backproject(u, v, z);
        const int s = surfaces.Below(p, opt.surfaces, opt.max_height_m);
        if (s < 0) continue;
        const SupportSurface& surface = surfaces.patches[std::size_t(s)];
        const double h = surface.plane.Height(p);
        if (h < surface.Band(z, opt.surfaces) + opt.min_height_m || h > opt.max_height_m) continue;
        support_of[i] = std::int8_t(std::min(s, 127));
      }
      fg[i] = 1;
    }
  // 4-connected regions of foreground pixels with small depth steps (iterative flood fill).
  std::vector<int> label(std::size_t(W) * H, 0);
  std::vector<CandidateRegion> regions;
  std::vector<int> stack, members;
  std::vector<float> zs;
  int next = 0;
  for (int start = 0; start < W * H; ++start) {
    if (!fg[std::size_t(start)] || label[std::size_t(start)] != 0) continue;
    ++next;
    members.clear();
    stack.assign(1, start);
    label[std::size_t(start)] = next;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      members.push_back(i);
      const int u = i % W, v = i / W;
      const float z = depth.data[std::size_t(i)];
      const int nbr[4][2] = {{u - 1, v}, {u + 1, v}, {u, v - 1}, {u, v + 1}};
      for (const auto& n : nbr) {
        if (n[0] < 0 || n[1] < 0 || n[0] >= W || n[1] >= H) continue;
        const int j = n[1] * W + n[0];
        if (!fg[std::size_t(j)] || label[std::size_t(j)] != 0) continue;
        if (std::fabs(depth.data[std::size_t(j)] - z) > opt.max_step_fraction * z) continue;
        label[std::size_t(j)] = next;
        stack.push_back(j);
      }
    }
    if (int(members.size()) < opt.min_pixels) {
      for (int i : members) label[std::size_t(i)] = -1;  // dropped: noise
      continue;
    }
    CandidateRegion r{W, H, 0, 0, int(members.size()), 0, -1};
    zs.clear();
    std::vector<int> votes(std::size_t(std::max(0, surfaces.supports)), 0);
    for (int i : members)
      if (support_of[std::size_t(i)] >= 0) ++votes[std::size_t(support_of[std::size_t(i)])];
    if (!votes.empty()) r.support = int(std::max_element(votes.begin(), votes.end()) - votes.begin());
    for (int i : members) {
      const int u = i % W, v = i / W;
      r.x0 = std::min(r.x0, u), r.y0 = std::min(r.y0, v), r.x1 = std::max(r.x1, u + 1), r.y1 = std::max(r.y1, v + 1);
      zs.push_back(depth.data[std::size_t(i)]);
    }
    std::nth_element(zs.begin(), zs.begin() + zs.size() / 2, zs.end());
    r.median_z = zs[zs.size() / 2];
    regions.push_back(r);
    for (int i : members) label[std::size_t(i)] = int(regions.size());
  }
  if (labels_out) {
    for (int& l : label) l = std::max(l, 0);
    *labels_out = std::move(label);
  }
  return regions;
}

namespace {

void CheckDiameters(const std::vector<std::pair<std::string, double>>& objects) {
  for (const auto& [name, diameter] : objects)
    if (!(diameter > 0 && std::isfinite(diameter)))
      throw Error("auto prior: object '" + name + "' has no positive diameter");
}

// Step 4 over the regions of FindCandidateRegions (labels: its region indices + 1).
std::vector<Detection> RegionDetections(const DepthImage& depth, const Camera& camera,
                                        const std::vector<std::pair<std::string, double>>& objects,
                                        const AutoPriorOptions& opt, const std::vector<CandidateRegion>& regions,
                                        const std::vector<int>& labels) {
  const int W = depth.width;
  // The fraction of the box [x0, x1) × [y0, y1) (cut to the image) that region pixels fill.
  auto fill = [&](int region, int x0, int y0, int x1, int y1) {
    int n = 0;
    for (int v = std::max(0, y0); v < std::min(depth.height, y1); ++v)
      for (int u = std::max(0, x0); u < std::min(W, x1); ++u) n += labels[std::size_t(v) * W + u] == region + 1;
    return double(n) / double(std::max(1, (x1 - x0) * (y1 - y0)));
  };
  std::vector<Detection> out;
  for (std::size_t k = 0; k < regions.size(); ++k) {
    const CandidateRegion& r = regions[k];
    const int rw = r.x1 - r.x0, rh = r.y1 - r.y0;
    auto projected = [&](double diameter) { return diameter * std::max(camera.fx, camera.fy) / r.median_z; };  // px
    auto fits = [&](double s) { return rw <= opt.fit_factor * s && rh <= opt.fit_factor * s; };
    // Whether one of the objects fits the whole region: then a smaller object's tiles on it are
    // less likely (the region is more likely that one object than several touching ones).
    bool one_fits = false;
    for (const auto& o : objects) one_fits = one_fits || fits(projected(o.second));
    const double tile_weight = one_fits ? opt.tile_weight_when_one_fits : 1.0;
    for (const auto& [name, diameter] : objects) {
      const double s = projected(diameter);
      if (fits(s)) {
        // A region much smaller than the object is a smaller object or a sliver of this one.
        const double size = std::max(rw, rh) / s;
        const double score = opt.fit_score * std::clamp(size / opt.full_size, opt.min_size_weight, 1.0);
        out.push_back({name, score, double(r.x0), double(r.y0), double(rw), double(rh)});
        continue;
      }
      // Touching objects: s × s tiles at stride s / 2 over the region's box, centred on it.
      const int side = std::max(1, int(std::lround(s))), stride = std::max(1, side / 2);
      const int nx = std::max(1, int(std::ceil(double(rw - side) / stride)) + 1);
      const int ny = std::max(1, int(std::ceil(double(rh - side) / stride)) + 1);
      const double ox = r.x0 + 0.5 * (rw - (double(nx - 1) * stride + side));
      const double oy = r.y0 + 0.5 * (rh - (double(ny - 1) * stride + side));
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const int x0 = int(std::lround(ox + i * stride)), y0 = int(std::lround(oy + j * stride));
          const double f = fill(int(k), x0, y0, x0 + side, y0 + side);
          if (f >= opt.min_fill)
            out.push_back({name, opt.tile_score * tile_weight * std::min(1.0, f), double(x0), double(y0), double(side),
                           double(side)});
        }
    }
  }
  return out;
}

}  // namespace

std::vector<Detection> AutoDetections(const DepthImage& depth, const Camera& camera,
                                      const std::vector<std::pair<std::string, double>>& objects,
                                      const AutoPriorOptions& opt) {
  CheckDiameters(objects);
  std::vector<int> labels;
  const std::vector<CandidateRegion> regions = FindCandidateRegions(depth, camera, opt, &labels);
  return RegionDetections(depth, camera, objects, opt, regions, labels);
}

AutoProposals ProposeAuto(const DepthImage& depth, const Camera& camera, const std::vector<AutoObject>& objects,
                          const AutoPriorOptions& opt) {
  std::vector<std::pair<std::string, double>> sizes;
  for (const AutoObject& o : objects) sizes.push_back({o.name, o.diameter});
  CheckDiameters(sizes);
  std::vector<int> labels;
  const std::vector<CandidateRegion> regions = FindCandidateRegions(depth, camera, opt, &labels);
  AutoProposals out;
  out.detections = RegionDetections(depth, camera, sizes, opt, regions, labels);
  out.seeds.resize(objects.size());
  // Each object's proposals, region by region: the image's normals once, each region's mask once.
  std::vector<std::vector<PoseProposal>> proposals_of(objects.size());
  const bool any_model = std::any_of(objects.begin(), objects.end(), [](const AutoObject& o) { return o.ppf; });
  const std::vector<float> normals = any_model ? ComputeSceneNormals(depth, camera, opt.ppf.threads) : std::vector<float>{};
  std::vector<std::uint8_t> mask(labels.size());
  for (std::size_t k = 0; any_model && k < regions.size(); ++k) {
    for (std::size_t i = 0; i < labels.size(); ++i) mask[i] = labels[i] == int(k) + 1;
    for (std::size_t j = 0; j < objects.size(); ++j)
      if (const PpfModel* model = objects[j].ppf)
        for (const PoseProposal& p : MatchPpf(*model, PpfScenePoints(depth, camera, normals, mask, model->step), opt.ppf))
          proposals_of[j].push_back(p);
  }
  for (std::size_t j = 0; j < objects.size(); ++j) {
    const PpfModel* model = objects[j].ppf;
    std::vector<PoseProposal>& proposals = proposals_of[j];
    if (!model || proposals.empty()) continue;
    std::stable_sort(proposals.begin(), proposals.end(),
                     [](const PoseProposal& a, const PoseProposal& b) { return a.votes > b.votes; });
    if (int(proposals.size()) > opt.max_seeds) proposals.resize(std::size_t(opt.max_seeds));
    for (const PoseProposal& p : proposals) {
      const double relative = p.votes / proposals.front().votes;
      out.seeds[j].push_back({p.T_cam_obj, relative});
      // The box of the model's points seen at the pose.
      double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
      for (const OrientedPoint& q : model->points) {
        const Eigen::Vector3d c = p.T_cam_obj * q.p.cast<double>();
        if (!(c.z() > 0)) continue;
        const Eigen::Vector2d px = camera.Project(c);
        x0 = std::min(x0, px.x()), y0 = std::min(y0, px.y()), x1 = std::max(x1, px.x()), y1 = std::max(y1, px.y());
      }
      if (x1 > x0 && y1 > y0)
        out.detections.push_back({objects[j].name, opt.proposal_score * relative, x0, y0, x1 - x0, y1 - y0});
    }
  }
  return out;
}

}  // namespace posefilter
