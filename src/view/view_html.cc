// src/view/view_html.cc — the viewer's HTML page (posefilter/view.h): the scene as JSON with
// base64 binary arrays, three.js and the viewer script (src/view/viewer.js) inlined.
//
// Data layout (the contract with viewer.js; every array little-endian, base64):
//   camera  {fx, fy, cx, cy, width, height}
//   cloud   {step, w, h, depth: float32 w·h (metres, 0 = missing), rgb: uint8 w·h·3}: pixel
//           (step·j, step·i) of the frame at grid cell (i, j)
//   planes  [{corners: 4 × [x, y, z] camera frame, normal}]
//   objects [{name, weight, estimate: 16 numbers (4×4 row-major, object → camera), gt: the
//           same or null, centre: mesh box centre (object frame), vertices: float32 V·3,
//           faces: uint32 F·3, sets: [{run, iteration, count, total, best}],
//           points: float32 (Σ count)·3 (each particle's box centre, camera frame),
//           weights: uint16 Σ count (weight · 65535), top_k, top: float32 sets·top_k·12
//           (3×4 row-major object → camera of the best top_k of each set; unused slots zero)}]
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/overlay.h"
#include "posefilter/pose.h"
#include "posefilter/view.h"
#include "view/assets.h"

namespace posefilter {
namespace {

using nlohmann::json;

std::string Base64(const void* data, std::size_t n) {
  static const char kTable[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* b = static_cast<const std::uint8_t*>(data);
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  for (std::size_t i = 0; i < n; i += 3) {
    const std::uint32_t v = std::uint32_t(b[i]) << 16 | (i + 1 < n ? std::uint32_t(b[i + 1]) << 8 : 0u) |
                            (i + 2 < n ? std::uint32_t(b[i + 2]) : 0u);
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += i + 1 < n ? kTable[(v >> 6) & 63] : '=';
    out += i + 2 < n ? kTable[v & 63] : '=';
  }
  return out;
}

template <class T>
std::string Base64(const std::vector<T>& v) {
  return Base64(v.data(), v.size() * sizeof(T));
}

json Matrix4(const Eigen::Isometry3d& T) {
  json m = json::array();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m.push_back(T.matrix()(r, c));
  return m;
}

json Point(const Eigen::Vector3d& p) { return json::array({p.x(), p.y(), p.z()}); }

// The subsampled depth and colours of the point cloud.
json CloudJson(const ViewScene& s, const ViewOptions& o) {
  const int W = s.camera.width, H = s.camera.height;
  int step = 1;
  while (std::int64_t((W + step - 1) / step) * ((H + step - 1) / step) > o.max_points) ++step;
  const int w = (W + step - 1) / step, h = (H + step - 1) / step;
  const RgbImage shade = s.rgb.data.empty() ? ShadeDepth(s.depth) : RgbImage();
  const RgbImage& colours = s.rgb.data.empty() ? shade : s.rgb;
  std::vector<float> depth(std::size_t(w) * h);
  std::vector<std::uint8_t> rgb(std::size_t(w) * h * 3);
  for (int i = 0; i < h; ++i)
    for (int j = 0; j < w; ++j) {
      const int u = j * step, v = i * step;
      const std::size_t k = std::size_t(i) * w + j, src = std::size_t(v) * W + u;
      depth[k] = s.depth.data[src];
      std::memcpy(&rgb[3 * k], &colours.data[3 * src], 3);
    }
  return {{"step", step}, {"w", w}, {"h", h}, {"depth", Base64(depth)}, {"rgb", Base64(rgb)}};
}

// The plane as a rectangle over the pixels on it: its in-plane extent between the 2nd and 98th
// percentiles of those pixels' points along two axes of the plane.
json PlaneJson(const ViewScene& s, const SupportPlane& plane) {
  const std::vector<std::uint8_t> on = SupportPlanePixels(s.depth, s.camera, plane);
  const Eigen::Vector3d n = plane.normal.normalized();
  const Eigen::Vector3d a = (std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).cross(n).normalized();
  const Eigen::Vector3d b = n.cross(a);
  std::vector<double> ua, ub;
  const int W = s.camera.width;
  for (std::size_t k = 0; k < on.size(); k += 7) {  // a sparse, fixed sample of the plane's pixels
    if (!on[k]) continue;
    const double z = s.depth.data[k], u = double(k % std::size_t(W)), v = double(k / std::size_t(W));
    const Eigen::Vector3d p((u - s.camera.cx) * z / s.camera.fx, (v - s.camera.cy) * z / s.camera.fy, z);
    ua.push_back(a.dot(p));
    ub.push_back(b.dot(p));
  }
  if (ua.size() < 3) return nullptr;
  auto range = [](std::vector<double>& x, double* lo, double* hi) {
    std::sort(x.begin(), x.end());
    *lo = x[std::size_t(0.02 * double(x.size() - 1))];
    *hi = x[std::size_t(0.98 * double(x.size() - 1))];
  };
  double a0, a1, b0, b1;
  range(ua, &a0, &a1);
  range(ub, &b0, &b1);
  const Eigen::Vector3d o = -plane.offset * n;  // the plane's point nearest the camera centre
  json corners = json::array();
  for (const auto& [x, y] : {std::pair{a0, b0}, {a1, b0}, {a1, b1}, {a0, b1}}) corners.push_back(Point(o + x * a + y * b));
  return {{"corners", corners}, {"normal", Point(n)}};
}

json ObjectJson(const ViewScene& s, const ViewObject& obj, const ViewOptions& o, double keep_fraction) {
  Mesh storage;
  const Mesh& mesh = MeshAtLod(obj.mesh, o.max_mesh_faces, &storage);
  std::vector<float> vertices;
  for (const auto& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
  std::vector<std::uint32_t> faces;
  for (const auto& f : mesh.faces) faces.insert(faces.end(), f.begin(), f.end());
  Eigen::Vector3f lo = mesh.vertices[0], hi = lo;
  for (const auto& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const Eigen::Vector3d centre = (0.5f * (lo + hi)).cast<double>();

  std::vector<float> points, top;
  std::vector<std::uint16_t> weights;
  json sets = json::array();
  const int k_top = o.top_poses;
  for (const ParticleSet& set : obj.particles) {
    const std::size_t total = set.poses.size();
    const std::size_t count = std::min(total, std::size_t(std::ceil(keep_fraction * double(total))));
    for (std::size_t i = 0; i < count; ++i) {  // best first: the kept ones are the best
      const Eigen::Isometry3d T = s.camera.base_to_camera * PoseToTransform(set.poses[i]);
      const Eigen::Vector3d p = T * centre;
      points.insert(points.end(), {float(p.x()), float(p.y()), float(p.z())});
      weights.push_back(std::uint16_t(std::lround(std::clamp(set.weights[i], 0.0, 1.0) * 65535)));
    }
    for (int i = 0; i < k_top; ++i) {
      if (std::size_t(i) >= total) {
        top.insert(top.end(), 12, 0.f);
        continue;
      }
      const Eigen::Matrix4d M = (s.camera.base_to_camera * PoseToTransform(set.poses[std::size_t(i)])).matrix();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) top.push_back(float(M(r, c)));
    }
    sets.push_back({{"run", set.run},
                    {"iteration", set.iteration},
                    {"count", count},
                    {"total", total},
                    {"best", set.weights.empty() ? 0.0 : set.weights[0]}});
  }
  return {{"name", obj.name},
          {"weight", obj.weight},
          {"estimate", Matrix4(obj.T_cam_obj)},
          {"gt", obj.gt_T_cam_obj ? Matrix4(*obj.gt_T_cam_obj) : json(nullptr)},
          {"centre", Point(centre)},
          {"vertices", Base64(vertices)},
          {"faces", Base64(faces)},
          {"sets", sets},
          {"points", Base64(points)},
          {"weights", Base64(weights)},
          {"top_k", k_top},
          {"top", Base64(top)}};
}

void CheckScene(const ViewScene& s) {
  std::string why;
  if (!s.camera.IsValid(&why)) throw Error("view: camera: " + why);
  const auto size = [](int w, int h) { return std::to_string(w) + "x" + std::to_string(h); };
  const std::string cam = size(s.camera.width, s.camera.height);
  if (s.depth.width != s.camera.width || s.depth.height != s.camera.height ||
      s.depth.data.size() != std::size_t(s.depth.width) * std::size_t(s.depth.height))
    throw Error("view: the depth image is " + size(s.depth.width, s.depth.height) + " but the camera is " + cam);
  if (!s.rgb.data.empty() && (s.rgb.width != s.camera.width || s.rgb.height != s.camera.height ||
                              s.rgb.data.size() != std::size_t(s.rgb.width) * std::size_t(s.rgb.height) * 3))
    throw Error("view: the RGB image is " + size(s.rgb.width, s.rgb.height) + " but the camera is " + cam);
  for (const ViewObject& o : s.objects) {
    if (!o.mesh.IsValid(&why)) throw Error("view: mesh of '" + o.name + "': " + why);
    for (const ParticleSet& set : o.particles)
      if (set.poses.size() != set.weights.size())
        throw Error("view: a particle set of '" + o.name + "' has " + std::to_string(set.poses.size()) + " poses but " +
                    std::to_string(set.weights.size()) + " weights");
  }
}

// JSON text safe inside a <script> element: every '<' (which JSON has only inside strings)
// as the escape \u003c, so neither "</script>" nor "<!--" can end or change the element.
std::string ScriptSafe(const std::string& json_text) {
  std::string out;
  out.reserve(json_text.size());
  for (char c : json_text) {
    if (c == '<') out += "\\u003c";
    else out += c;
  }
  return out;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

}  // namespace

bool ViewOptions::IsValid(std::string* why) const {
  std::string w;
  if (max_points < 1) w = "max_points must be >= 1";
  else if (max_mesh_faces != 0 && max_mesh_faces < 4) w = "max_mesh_faces must be 0 or >= 4";
  else if (top_poses < 0 || top_poses > 100) w = "top_poses must be in [0, 100]";
  else if (max_particles < 0) w = "max_particles must be >= 0";
  if (why) *why = w;
  return w.empty();
}

bool ViewerAvailable() { return !view::ThreeJs().empty(); }

std::string ViewHtml(const ViewScene& scene, const ViewOptions& options) {
  if (!ViewerAvailable())
    throw Error("this build has no viewer: libjs-three (three.js) was not found when it was configured "
                "(apt-get install libjs-three, then reconfigure and rebuild)");
  std::string why;
  if (!options.IsValid(&why)) throw Error("view: " + why);
  CheckScene(scene);
  std::size_t total = 0;
  for (const ViewObject& o : scene.objects)
    for (const ParticleSet& set : o.particles) total += set.poses.size();
  const double keep = total > std::size_t(options.max_particles) ? double(options.max_particles) / double(total) : 1.0;
  json data = {{"title", scene.title},
               {"camera",
                {{"fx", scene.camera.fx},
                 {"fy", scene.camera.fy},
                 {"cx", scene.camera.cx},
                 {"cy", scene.camera.cy},
                 {"width", scene.camera.width},
                 {"height", scene.camera.height}}},
               {"cloud", CloudJson(scene, options)},
               {"planes", json::array()},
               {"objects", json::array()}};
  for (const SupportPlane& p : scene.planes)
    if (p.found)
      if (json j = PlaneJson(scene, p); !j.is_null()) data["planes"].push_back(j);
  for (const ViewObject& o : scene.objects) data["objects"].push_back(ObjectJson(scene, o, options, keep));

  std::string html;
  const std::string_view three = view::ThreeJs(), script = view::ViewerJs();
  html.reserve(three.size() + script.size() + 4096);
  html += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>";
  html += HtmlEscape(scene.title.empty() ? std::string("posefilter view") : scene.title);
  html +=
      "</title>\n<style>\n"
      "html,body{margin:0;height:100%;overflow:hidden;background:#111;color:#ddd;font:13px sans-serif}\n"
      "canvas{display:block}\n"
      "#panel{position:absolute;top:8px;left:8px;background:rgba(20,20,20,.85);padding:8px 10px;border-radius:4px;"
      "max-width:360px}\n"
      "#panel input[type=range]{width:100%}\n#panel .row{margin:3px 0}\n"
      "#legend{height:10px;background:linear-gradient(to right,#30123b,#4686fb,#1ae4b6,#a2fc3c,#fabb39,#e4460a)}\n"
      "#error{position:absolute;bottom:8px;left:8px;color:#f66}\n"
      "</style></head><body>\n<script type=\"application/json\" id=\"posefilter-data\">";
  html += ScriptSafe(data.dump());
  html += "</script>\n<script>\n";
  html.append(three);
  html += "\n</script>\n<script>\n";
  html.append(script);
  html += "\n</script>\n</body></html>\n";
  return html;
}

void WriteViewHtml(const ViewScene& scene, const std::string& path, const ViewOptions& options) {
  const std::string html = ViewHtml(scene, options);
  WriteFileAtomically(path, [&](std::ostream& os) { os.write(html.data(), std::streamsize(html.size())); });
}

}  // namespace posefilter
