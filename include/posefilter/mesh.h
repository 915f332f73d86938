// posefilter/mesh.h — triangle meshes of the objects to look for.
//
// Vertices are in the object frame, metres. Faces index vertices; front faces wind
// counter-clockwise seen from outside (outward normal = (v1−v0)×(v2−v0)), the convention of
// PLY/OBJ exports and of the back-face culling in render/ (2·Area ≤ 0 culled, §6.2).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace posefilter {

struct Mesh {
  std::string name;                                  // object/class name
  std::vector<Eigen::Vector3f> vertices;             // object frame, metres
  std::vector<std::array<std::uint32_t, 3>> faces;   // vertex indices, CCW from outside

  // Largest coordinate any object may have (metres): a mesh beyond it is in the wrong units.
  static constexpr float kMaxCoordinate = 1000.f;

  // Non-empty, every index in range, every coordinate finite and within ±kMaxCoordinate, and
  // at least one face of non-zero area.
  bool IsValid(std::string* why) const;
  // Largest distance between two vertices, metres: exact (O(V²)) up to 4096 vertices;
  // above that, exact over a deterministic 4096-vertex subsample (a lower bound).
  double Diameter() const;
  Eigen::Vector3f Min() const;  // axis-aligned bounds, object frame
  Eigen::Vector3f Max() const;
};

// Loads .ply/.obj/.stl (anything assimp reads) and triangulates it; coordinates are multiplied
// by unit_scale (e.g. 0.001 for millimetre models). Throws Error naming the file when it is
// missing, not a regular file, larger than kMaxMeshBytes, unreadable, holds no triangles, or
// needs more memory than the process can get. The name defaults to the file's stem.
Mesh LoadMesh(const std::string& path, double unit_scale = 1.0);
// The largest mesh file LoadMesh reads: 512 MiB. An object model for pose estimation is a few
// MB (the BOP YCB-V models are 1–8 MB); a loader holds several times the file in memory.
inline constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t(512) << 20;
// Writes a binary little-endian PLY (float x,y,z; uchar-count int faces). Throws Error on I/O.
void SaveMeshPly(const Mesh& mesh, const std::string& path);

}  // namespace posefilter
