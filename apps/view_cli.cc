// apps/view_cli.cc — the viewer page as the commands write it (view_cli.h).
#include "view_cli.h"

#include "posefilter/error.h"
#include "posefilter/support_plane.h"

namespace posefilter::cli {

void RequireViewer(const std::string& option) {
  if (!ViewerAvailable())
    throw Error(option + ": this build has no viewer: libjs-three (three.js) was not found when it was configured "
                "(apt-get install libjs-three, then reconfigure and rebuild)");
}

void WriteFrameView(const FrameView& frame, const std::string& path) {
  ViewScene v;
  v.title = frame.title;
  v.depth = frame.scene->depth;
  v.camera = frame.scene->camera;
  if (frame.rgb) v.rgb = *frame.rgb;
  // The same plane the filter finds (FindSupportPlane with its defaults on the full depth).
  if (frame.support_plane) v.planes.push_back(FindSupportPlane(v.depth, v.camera));
  std::vector<bool> gt_used(frame.gt.size(), false);
  for (std::size_t i = 0; i < frame.results.size(); ++i) {
    const ObjectResult& r = frame.results[i];
    ViewObject o;
    o.name = r.obj;
    o.mesh = *frame.meshes[i];
    o.T_cam_obj = r.T_cam_obj;
    o.weight = r.weight;
    if (i < frame.particles.size()) o.particles = frame.particles[i];
    int best = -1;
    double best_d = 0;
    for (std::size_t g = 0; g < frame.gt.size(); ++g) {
      if (gt_used[g] || frame.gt[g].obj != r.obj) continue;
      const double d = (frame.gt[g].T_cam_obj.translation() - r.T_cam_obj.translation()).norm();
      if (best < 0 || d < best_d) best = int(g), best_d = d;
    }
    if (best >= 0) {
      gt_used[std::size_t(best)] = true;
      o.gt_T_cam_obj = frame.gt[std::size_t(best)].T_cam_obj;
    }
    v.objects.push_back(std::move(o));
  }
  WriteViewHtml(v, path);
}

}  // namespace posefilter::cli
