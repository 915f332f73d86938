// posefilter/mesh_simplify.h — level of detail (LOD): a mesh simplified to a face budget.
//
// The score kernel's cost grows with the faces it transforms and rasterizes (docs/ALGORITHM.md §5);
// the thesis downsamples its models to ≤ 1024 vertices (§7.1). SimplifyMesh reduces a mesh with
// meshoptimizer's edge-collapse simplifier (topology-preserving: a closed mesh stays closed where
// the simplifier can reach the budget that way); only when that stops short of the budget does it
// fall back to meshoptimizer's "sloppy" vertex-clustering simplifier, which ignores topology (the
// report says so). Vertices keep their object-frame coordinates (the simplified mesh uses a subset
// of the input's vertex positions), faces keep their CCW winding, so the renderer's back-face
// culling still holds.
#pragma once

#include <string>

#include "posefilter/mesh.h"

namespace posefilter {

// The smallest face budget accepted: a tetrahedron, the smallest closed mesh.
inline constexpr int kMinSimplifyFaces = 4;

struct SimplifyOptions {
  // Largest geometric error the edge-collapse pass may introduce, as a fraction of the mesh's
  // extent (meshoptimizer's relative error, ≈ the largest bounding-box side), in (0, 1].
  // 1 = no limit: simplify down to the budget.
  double max_relative_error = 1.0;
  // When the edge-collapse pass cannot reach the budget within max_relative_error (topology
  // or error limit), use the sloppy clustering pass instead of failing.
  bool allow_sloppy = true;
  // Names the violated constraint.
  bool IsValid(std::string* why) const;
};

// What SimplifyMesh did. Errors are in metres, object frame.
struct SimplifyReport {
  int faces_in = 0, faces_out = 0;        // triangle counts before / after
  int vertices_in = 0, vertices_out = 0;  // vertex counts before / after (after welding and compaction)
  // meshoptimizer's own error estimate of the collapses, converted to metres (relative error ×
  // meshopt_simplifyScale); 0 when the mesh was returned unchanged.
  double error_m = 0;
  // Measured: largest distance from an input vertex to the simplified surface (one-sided
  // Hausdorff distance over the input vertices; over a deterministic 4096-vertex subsample
  // above that), metres; 0 when unchanged.
  double max_distance_m = 0;
  bool unchanged = false;  // the mesh had ≤ max_faces faces and was returned as it was
  bool sloppy = false;     // the topology-ignoring fallback was used
};

// `mesh` reduced to at most `max_faces` triangles (name kept). A mesh with ≤ max_faces faces is
// returned unchanged (an exact copy). Coincident vertices (as in meshes loaded with per-face
// vertices) are welded before simplifying, and degenerate triangles dropped after it.
// Throws Error naming the mesh when max_faces < kMinSimplifyFaces, the options or the mesh are
// invalid, or the budget cannot be reached (sloppy pass disallowed or still above it).
Mesh SimplifyMesh(const Mesh& mesh, int max_faces, const SimplifyOptions& options = {},
                  SimplifyReport* report = nullptr);

// The mesh a renderer should use for a face budget (FilterOptions::render.lod_max_faces): `mesh`
// itself when max_faces ≤ 0 (full mesh), when the mesh already has ≤ max_faces faces, or when
// the arguments are invalid (max_faces < kMinSimplifyFaces or an invalid mesh — the caller's
// own validation reports those); otherwise SimplifyMesh(mesh, max_faces) stored in *storage.
const Mesh& MeshAtLod(const Mesh& mesh, int max_faces, Mesh* storage);

}  // namespace posefilter
