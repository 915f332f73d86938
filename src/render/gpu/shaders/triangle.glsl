// triangle.glsl — one face of one particle's model, set up for rasterization inside the
// particle's window (render::RasterizeTriangle), and the test and use of one pixel centre.
// Needs common.glsl.

// A face whose three vertices passed the near-plane and off-screen tests, projected and
// snapped: x, y in 1/256 px (|x|, |y| < 2^28, so differences fit int32), iz = 1/z (1/m).
struct Face {
  int x[3], y[3];
  float iz[3];
  int64_t area2;  // twice the signed area (§6.2), exact
};

// Loads face f of particle p from the vertex records; false when a vertex is unusable.
bool LoadFace(uint f, uint p, out Face t) {
  const uint base = p * uint(pc.num_vertices);
  const ivec4 a = vrec[base + faces[3u * f]];
  const ivec4 b = vrec[base + faces[3u * f + 1u]];
  const ivec4 c = vrec[base + faces[3u * f + 2u]];
  t.x = int[3](a.x, b.x, c.x);
  t.y = int[3](a.y, b.y, c.y);
  t.iz = float[3](intBitsToFloat(a.z), intBitsToFloat(b.z), intBitsToFloat(c.z));
  t.area2 = Mul64(t.x[2] - t.x[0], t.y[1] - t.y[0]) - Mul64(t.y[2] - t.y[0], t.x[1] - t.x[0]);
  return a.w != 0 && b.w != 0 && c.w != 0;
}

// The pixel box of a front face clipped to the window, and its edge functions (eq. 6.13 [ALGORITHM.md]):
// edge k lies opposite vertex k, from Va = V[k+1] to Vb = V[k+2];
// E_k(P) = A_k·(Px − Va.x) + B_k·(Py − Va.y); a pixel with E_k = 0 belongs to the triangle only
// when the edge owns it (A > 0, or A = 0 and B > 0): min_e = 0, else 1.
struct Raster {
  int u_lo, u_hi, v_lo, v_hi;
  int A[3], B[3], xa[3], ya[3], min_e[3];
  float inv_area2;  // 1 / float(2·Area), correctly rounded
};

// False when the box is empty.
bool SetupRaster(Face t, ivec4 w, out Raster r) {
  const int min_x = min(t.x[0], min(t.x[1], t.x[2])), max_x = max(t.x[0], max(t.x[1], t.x[2]));
  const int min_y = min(t.y[0], min(t.y[1], t.y[2])), max_y = max(t.y[0], max(t.y[1], t.y[2]));
  // Pixel centres (i·256) inside the box: ceil(min/256) .. floor(max/256); >> is arithmetic.
  r.u_lo = max(w.x, -((-min_x) >> 8));
  r.u_hi = min(w.x + w.z - 1, max_x >> 8);
  r.v_lo = max(w.y, -((-min_y) >> 8));
  r.v_hi = min(w.y + w.w - 1, max_y >> 8);
  for (int k = 0; k < 3; ++k) {
    const int ka = (k + 1) % 3, kb = (k + 2) % 3;
    r.A[k] = t.y[kb] - t.y[ka];
    r.B[k] = -(t.x[kb] - t.x[ka]);
    r.xa[k] = t.x[ka];
    r.ya[k] = t.y[ka];
    r.min_e[k] = (r.A[k] > 0 || (r.A[k] == 0 && r.B[k] > 0)) ? 0 : 1;
  }
  r.inv_area2 = DivRN(1.0, float(t.area2));
  return r.u_lo <= r.u_hi && r.v_lo <= r.v_hi;
}

// E_k at the centre of pixel (u, v), exact (u·256 − Va.x fits int32 for pixels of the image).
int64_t EdgeAt(Raster r, int k, int u, int v) {
  return Mul64(r.A[k], u * 256 - r.xa[k]) + Mul64(r.B[k], v * 256 - r.ya[k]);
}

// Pixel (u, v) with edge values e: when covered, its perspective-correct 1/z (eq. 6.21–6.22 [ALGORITHM.md], the
// reference's float order) goes to the z-buffer (largest 1/z wins) or, in thesis mode, the
// fragment is compared at once.
void Fragment(Face t, Raster r, uint p, ivec4 w, int u, int v, int64_t e0, int64_t e1, int64_t e2,
              inout int64_t s[kNumSums]) {
  if (e0 < r.min_e[0] || e1 < r.min_e[1] || e2 < r.min_e[2]) return;
  precise float inv_z = ((float(e0) * t.iz[0] + float(e1) * t.iz[1]) + float(e2) * t.iz[2]) * r.inv_area2;
  if ((pc.flags & kFlagZBuffer) != 0u) {
    const uint cell = ZOffset(p) + uint(v - w.y) * uint(w.z) + uint(u - w.x);
    atomicMax(zbuf[cell], floatBitsToUint(inv_z));
  } else {
    CompareFragment(u, v, DivRN(1.0, inv_z), s);
  }
}
