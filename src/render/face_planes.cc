// Per-mesh data of the cpu engine's back-face pre-cull (see face_planes.h).
#include "render/face_planes.h"

#include <cmath>
#include <limits>
#include <string>

#include "posefilter/error.h"

namespace posefilter::render {

float RoundUpToFloat(double x) {
  float f = float(x);
  if (double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

FacePlanes BuildFacePlanes(const ScoreKernelParams& mesh) {
  const float* const vertices = mesh.vertices;
  const std::uint32_t* const faces = mesh.faces;
  const int num_vertices = mesh.num_vertices, num_faces = mesh.num_faces;
  if (num_vertices < 0 || num_faces < 0 || (num_vertices > 0 && !vertices) || (num_faces > 0 && !faces))
    throw Error("face planes: mesh pointers/counts are invalid (vertices/faces)");
  FacePlanes p;
  p.vertices = vertices;
  p.faces = faces;
  p.num_vertices = num_vertices;
  p.num_faces = num_faces;
  const std::size_t padded = (std::size_t(num_faces) + 15) / 16 * 16;
  for (auto* v : {&p.nx, &p.ny, &p.nz, &p.len}) v->assign(padded, 0.f);
  p.d.assign(padded, std::numeric_limits<float>::infinity());  // padding: never kept
  for (auto* v : {&p.i0, &p.i1, &p.i2}) v->assign(padded, 0u);

  double r2 = 0;
  for (int i = 0; i < num_vertices; ++i) {
    const float* v = vertices + 3 * std::size_t(i);
    if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]))) {
      r2 = std::numeric_limits<double>::infinity();
      break;
    }
    r2 = std::fmax(r2, double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
  }
  // Rounded up: |v| ≤ radius for every vertex despite the double rounding of the sum.
  p.radius = std::sqrt(r2) * (1 + 1e-12);

  for (int f = 0; f < num_faces; ++f) {
    const std::uint32_t* ix = faces + 3 * std::size_t(f);
    for (int q = 0; q < 3; ++q)
      if (ix[q] >= std::uint32_t(num_vertices))
        throw Error("face planes: face " + std::to_string(f) + " has a vertex index out of range");
    const float* a = vertices + 3 * std::size_t(ix[0]);
    const float* b = vertices + 3 * std::size_t(ix[1]);
    const float* c = vertices + 3 * std::size_t(ix[2]);
    // Edges and N in double (differences of floats: exact for coordinates of similar size;
    // the kernel's margin allows a relative error of 2^-20 in s anyway).
    const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double e2[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
    const double e3[3] = {double(c[0]) - b[0], double(c[1]) - b[1], double(c[2]) - b[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    auto norm = [](const double* e) { return std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]); };
    const double len = std::fmax(norm(e1), std::fmax(norm(e2), norm(e3))) * (1 + 1e-12);
    p.nx[f] = float(n[0]);
    p.ny[f] = float(n[1]);
    p.nz[f] = float(n[2]);
    p.d[f] = float(n[0] * a[0] + n[1] * a[1] + n[2] * a[2]);
    p.len[f] = RoundUpToFloat(len);
    p.max_len = std::fmax(p.max_len, double(p.len[f]));
    p.i0[f] = ix[0];
    p.i1[f] = ix[1];
    p.i2[f] = ix[2];
  }
  return p;
}

}  // namespace posefilter::render
