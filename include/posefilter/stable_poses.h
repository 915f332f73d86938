// posefilter/stable_poses.h — how a rigid object comes to rest on a table: its convex hull,
// its centre of mass, and the hull faces it can stand on, each with the probability of
// landing on it.
//
// A face of the convex hull is a *stable pose* when the centre of mass, projected along the
// face's normal, falls inside the face (the object then rests on it without tipping). The
// probability of a stable pose is the fraction of random drops that end on it: the object
// is dropped with a uniformly random orientation, first touches the table with the hull
// face that the downward ray from the centre of mass crosses (so a face is hit with the
// probability of its solid angle seen from the centre of mass, over 4π), and, while that
// face is not stable, tips over the edge the projected centre of mass lies furthest beyond
// onto the neighbouring face (the quasi-static model of Goldberg et al. 1999, "Part pose
// statistics"). Computed exactly, face by face (no sampling).
//
// Frames and units: the object frame of the mesh, metres. A pose's T_table_obj maps the
// object frame to a table frame whose z axis is the table's up normal and whose origin is
// the point of the table below the centre of mass: the resting face lies in z = 0, the
// object above it. Any rotation about the table's z axis is the same stable pose.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "posefilter/mesh.h"

namespace posefilter {

// The convex hull of a point set (Debian's libqhull_r), coplanar triangles merged into
// convex polygons.
struct ConvexHull {
  std::vector<Eigen::Vector3d> vertices;  // hull vertices, metres
  struct Face {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // outward unit normal
    double offset = 0;          // plane normal·x + offset = 0 (inside: < 0)
    std::vector<int> polygon;   // vertex indices, counter-clockwise seen from outside
    double area = 0;            // m²
  };
  std::vector<Face> faces;
  double volume = 0;            // m³
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // of the solid hull
};

// Throws Error (naming `what`) when the points are fewer than 4, not finite, or span no
// volume (all on a plane or a line).
ConvexHull ComputeConvexHull(const std::vector<Eigen::Vector3d>& points, const std::string& what = "points");

// Centre of mass of the mesh as a solid of uniform density (signed tetrahedra), object
// frame, metres. Meshes that do not enclose a volume (open or inconsistently
// wound, so that the signed volume is below a quarter of the hull's) use the centroid of
// the solid convex hull instead. Throws Error like ComputeConvexHull.
Eigen::Vector3d CentreOfMass(const Mesh& mesh);

struct StablePose {
  Eigen::Isometry3d T_table_obj = Eigen::Isometry3d::Identity();  // object → table frame
  int face = -1;               // index into the hull's faces of the resting face
  double probability = 0;      // probability of coming to rest here; all poses sum to 1
  double com_height_m = 0;     // height of the centre of mass above the table, metres
};

struct StablePoseOptions {
  // Poses with a smaller probability are left out (the others are
  // renormalised), [0, 1).
  double min_probability = 0.0;
  bool IsValid(std::string* why) const;
};

// The stable poses of `mesh`, most probable first. Throws Error on invalid options or a
// mesh without volume (naming the mesh).
std::vector<StablePose> ComputeStablePoses(const Mesh& mesh, const StablePoseOptions& options = {});

}  // namespace posefilter
