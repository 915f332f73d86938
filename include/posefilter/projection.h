// posefilter/projection.h — where a mesh lands in the image: the bounding box of its projected
// silhouette (e.g. to make a stage-1 detection from a ground-truth pose).
//
// Pixel coordinates as in prior.h / camera.h: the centre of pixel (i, j) is (u, v) = (i, j),
// so pixel i spans [i − 0.5, i + 0.5].
#pragma once

#include <Eigen/Geometry>

#include "posefilter/camera.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"

namespace posefilter {

// The bounding box of the pixels `mesh` covers when rendered alone at T_cam_obj (object →
// camera, metres) with RenderDepth's rules (render.h: pixel centres sampled, back faces culled,
// triangles with a vertex closer than the near plane skipped): the full, unoccluded silhouette,
// clipped to the image. With covered columns u0..u1 and rows v0..v1:
//   cx = (u0 + u1)/2, cy = (v0 + v1)/2, w = u1 − u0 + 1, h = v1 − v0 + 1   (pixels),
// i.e. the box spans the covered pixels' full extent [u0 − 0.5, u1 + 0.5] × [v0 − 0.5, v1 + 0.5].
// Returns a box with w = h = 0 when no pixel is covered (object behind the camera, outside the
// image, or seen only from the back). Throws Error if the camera or the mesh is invalid
// (naming the constraint and the mesh's name).
Box ProjectedBox(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera);

}  // namespace posefilter
