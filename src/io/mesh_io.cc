// io/mesh_io.cc — mesh files: loading (strict PLY reader, assimp for the rest) and binary PLY
// writing (the type and its geometry: src/core/mesh.cc).
#include "posefilter/mesh.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

#include "posefilter/error.h"
#include "posefilter/file_io.h"

namespace posefilter {

namespace {

// Appends the little-endian bytes of a 32-bit value (PLY binary_little_endian).
void PutLe32(std::string& out, std::uint32_t u) {
  for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((u >> (8 * b)) & 0xffu));
}

}  // namespace

namespace {

// ---- PLY reader ------------------------------------------------------------------------------
// Strict reader of ascii / binary_little_endian / binary_big_endian PLY: every read is bounds-
// checked, counts are checked against the bytes left, and any malformed input throws Error.
// Uses element "vertex" (properties x, y, z of any scalar type) and element "face" (list
// "vertex_indices" or "vertex_index"); other elements and properties are skipped. Polygons
// with n > 3 corners are fan-triangulated (as aiProcess_Triangulate does for convex faces);
// faces with fewer than 3 corners are dropped. Vertices no triangle uses are dropped.

enum class PlyFormat { kAscii, kBinaryLe, kBinaryBe };

enum class PlyType { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType count_type = PlyType::kU8;  // lists only
  PlyType type = PlyType::kF32;       // scalar type, or the list items' type
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> props;
};

int PlyTypeSize(PlyType t) {
  switch (t) {
    case PlyType::kI8: case PlyType::kU8: return 1;
    case PlyType::kI16: case PlyType::kU16: return 2;
    case PlyType::kI32: case PlyType::kU32: case PlyType::kF32: return 4;
    case PlyType::kF64: return 8;
  }
  return 1;
}

bool ParsePlyType(const std::string& s, PlyType* t) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::kI8},    {"int8", PlyType::kI8},     {"uchar", PlyType::kU8},
      {"uint8", PlyType::kU8},   {"short", PlyType::kI16},   {"int16", PlyType::kI16},
      {"ushort", PlyType::kU16}, {"uint16", PlyType::kU16},  {"int", PlyType::kI32},
      {"int32", PlyType::kI32},  {"uint", PlyType::kU32},    {"uint32", PlyType::kU32},
      {"float", PlyType::kF32},  {"float32", PlyType::kF32}, {"double", PlyType::kF64},
      {"float64", PlyType::kF64}};
  for (const auto& [name, type] : kNames) {
    if (s == name) {
      *t = type;
      return true;
    }
  }
  return false;
}

class PlyParser {
 public:
  PlyParser(const std::string& path, std::string bytes) : path_(path), bytes_(std::move(bytes)) {}

  Mesh Parse(double unit_scale) {
    ParseHeader();
    std::vector<Eigen::Vector3f> verts;
    std::vector<std::array<std::uint64_t, 3>> tris;  // unchecked indices
    bool have_vertex = false;
    for (const PlyElement& el : elements_) {
      const bool is_vertex = el.name == "vertex";
      const bool is_face = el.name == "face";
      int ix = -1, iy = -1, iz = -1, iface = -1;
      for (size_t k = 0; k < el.props.size(); ++k) {
        const PlyProperty& p = el.props[k];
        if (is_vertex && !p.is_list) {
          if (p.name == "x") ix = int(k);
          if (p.name == "y") iy = int(k);
          if (p.name == "z") iz = int(k);
        }
        if (is_face && p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
          iface = int(k);
        }
      }
      if (is_vertex) {
        if (ix < 0 || iy < 0 || iz < 0) Fail("element \"vertex\" lacks property x, y or z");
        have_vertex = true;
        verts.reserve(static_cast<size_t>(el.count));
      }
      if (is_face && iface < 0) Fail("element \"face\" lacks the list \"vertex_indices\"");
      std::vector<double> corners;
      for (std::uint64_t e = 0; e < el.count; ++e) {
        double xyz[3] = {0, 0, 0};
        for (size_t k = 0; k < el.props.size(); ++k) {
          const PlyProperty& p = el.props[k];
          if (!p.is_list) {
            const double v = ReadScalar(p.type);
            if (int(k) == ix) xyz[0] = v;
            if (int(k) == iy) xyz[1] = v;
            if (int(k) == iz) xyz[2] = v;
            continue;
          }
          const double n = ReadScalar(p.count_type);
          if (!std::isfinite(n) || n < 0 || n != std::floor(n)) Fail("bad list length");
          // Each item takes at least one byte (binary) or one character plus a separator.
          // Compared as a double first: a float/double count can exceed the uint64 range.
          if (n > static_cast<double>(bytes_.size() - pos_)) Fail("list length exceeds the file (truncated?)");
          const std::uint64_t count = static_cast<std::uint64_t>(n);
          const bool keep = int(k) == iface;
          if (keep) corners.clear();
          for (std::uint64_t c = 0; c < count; ++c) {
            const double idx = ReadScalar(p.type);
            if (keep) corners.push_back(idx);
          }
          if (keep) {
            for (double idx : corners) {
              if (idx < 0 || idx != std::floor(idx) || idx > 4294967295.0) {
                Fail("face " + std::to_string(e) + " has an invalid vertex index");
              }
            }
            for (size_t c = 2; c < corners.size(); ++c) {  // fan: (0, c−1, c)
              tris.push_back({std::uint64_t(corners[0]), std::uint64_t(corners[c - 1]),
                              std::uint64_t(corners[c])});
            }
          }
        }
        if (is_vertex) {
          verts.emplace_back(static_cast<float>(xyz[0] * unit_scale),
                             static_cast<float>(xyz[1] * unit_scale),
                             static_cast<float>(xyz[2] * unit_scale));
        }
      }
    }
    if (!have_vertex) Fail("no element \"vertex\"");
    // Keep the vertices some triangle uses, in file order.
    std::vector<std::uint32_t> remap(verts.size(), 0);
    for (size_t f = 0; f < tris.size(); ++f) {
      for (std::uint64_t idx : tris[f]) {
        if (idx >= verts.size()) {
          Fail("a face indexes vertex " + std::to_string(idx) + " but the file has " +
               std::to_string(verts.size()) + " vertices");
        }
        remap[idx] = 1;
      }
    }
    Mesh mesh;
    for (size_t i = 0; i < verts.size(); ++i) {
      if (remap[i] != 0) {
        remap[i] = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.push_back(verts[i]);
      }
    }
    mesh.faces.reserve(tris.size());
    for (const auto& t : tris) mesh.faces.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
    return mesh;
  }

 private:
  [[noreturn]] void Fail(std::string what) const {
    for (char& c : what) {  // quoted file bytes: keep the message one printable line
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
    }
    if (what.size() > 200) what = what.substr(0, 200) + "...";
    throw Error(path_ + ": malformed PLY: " + what);
  }

  void ParseHeader() {
    // Header lines end with "\n" (or "\r\n"); the header must close within 1 MiB.
    const size_t limit = std::min<size_t>(bytes_.size(), 1 << 20);
    std::vector<std::string> lines;
    size_t p = 0;
    for (;;) {
      const size_t nl = bytes_.find('\n', p);
      if (nl == std::string::npos || nl >= limit) Fail("header does not end with \"end_header\"");
      std::string line = bytes_.substr(p, nl - p);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      p = nl + 1;
      if (lines.empty() && line != "ply") Fail("missing the \"ply\" magic line");
      if (line == "end_header") break;
      lines.push_back(line);
    }
    pos_ = p;
    bool have_format = false;
    for (size_t i = 1; i < lines.size(); ++i) {
      std::istringstream ls(lines[i]);
      std::string word;
      ls >> word;
      if (word.empty() || word == "comment" || word == "obj_info") continue;
      if (word == "format") {
        std::string fmt, version;
        ls >> fmt >> version;
        if (fmt == "ascii") format_ = PlyFormat::kAscii;
        else if (fmt == "binary_little_endian") format_ = PlyFormat::kBinaryLe;
        else if (fmt == "binary_big_endian") format_ = PlyFormat::kBinaryBe;
        else Fail("unknown format \"" + fmt + "\"");
        have_format = true;
      } else if (word == "element") {
        PlyElement el;
        std::string count;
        ls >> el.name >> count;
        if (el.name.empty() || count.empty() ||
            count.find_first_not_of("0123456789") != std::string::npos || count.size() > 18) {
          Fail("bad element line \"" + lines[i] + "\"");
        }
        el.count = std::stoull(count);
        elements_.push_back(el);
      } else if (word == "property") {
        if (elements_.empty()) Fail("property before any element");
        PlyProperty prop;
        std::string type;
        ls >> type;
        if (type == "list") {
          std::string count_type, item_type;
          ls >> count_type >> item_type >> prop.name;
          prop.is_list = true;
          if (!ParsePlyType(count_type, &prop.count_type) || !ParsePlyType(item_type, &prop.type)) {
            Fail("bad property line \"" + lines[i] + "\"");
          }
        } else {
          ls >> prop.name;
          if (!ParsePlyType(type, &prop.type)) Fail("bad property line \"" + lines[i] + "\"");
        }
        if (prop.name.empty()) Fail("bad property line \"" + lines[i] + "\"");
        elements_.back().props.push_back(prop);
      } else {
        Fail("unknown header line \"" + lines[i] + "\"");
      }
    }
    if (!have_format) Fail("missing the \"format\" line");
    // Cheap guard against absurd counts before allocating or looping: every element with
    // properties needs at least one byte per instance.
    std::uint64_t min_bytes = 0;
    for (PlyElement& el : elements_) {
      if (el.props.empty()) {
        el.count = 0;  // nothing to read
        continue;
      }
      if (el.count > bytes_.size() - pos_ || min_bytes + el.count > bytes_.size() - pos_) {
        Fail("element \"" + el.name + "\" has more entries than the file holds (truncated?)");
      }
      min_bytes += el.count;
    }
  }

  double ReadScalar(PlyType t) {
    if (format_ == PlyFormat::kAscii) return ReadAscii(t);
    const int n = PlyTypeSize(t);
    if (bytes_.size() - pos_ < size_t(n)) Fail("unexpected end of file (truncated?)");
    std::uint64_t u = 0;
    for (int b = 0; b < n; ++b) {
      const std::uint64_t byte = static_cast<unsigned char>(bytes_[pos_ + b]);
      if (format_ == PlyFormat::kBinaryLe) u |= byte << (8 * b);
      else u = (u << 8) | byte;
    }
    pos_ += n;
    switch (t) {
      case PlyType::kI8: return static_cast<std::int8_t>(u);
      case PlyType::kU8: return static_cast<std::uint8_t>(u);
      case PlyType::kI16: return static_cast<std::int16_t>(u);
      case PlyType::kU16: return static_cast<std::uint16_t>(u);
      case PlyType::kI32: return static_cast<std::int32_t>(u);
      case PlyType::kU32: return static_cast<std::uint32_t>(u);
      case PlyType::kF32: return std::bit_cast<float>(static_cast<std::uint32_t>(u));
      case PlyType::kF64: return std::bit_cast<double>(u);
    }
    return 0;
  }

  double ReadAscii(PlyType t) {
    while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    if (pos_ >= bytes_.size()) Fail("unexpected end of file (truncated?)");
    const char* begin = bytes_.data() + pos_;
    const char* end = bytes_.data() + bytes_.size();
    const char* tok_end = begin;
    while (tok_end < end && !std::isspace(static_cast<unsigned char>(*tok_end))) ++tok_end;
    double v = 0;
    const auto [ptr, ec] = std::from_chars(begin, tok_end, v);
    if (ec != std::errc() || ptr != tok_end) {
      Fail("bad number \"" + std::string(begin, std::min<size_t>(tok_end - begin, 32)) + "\"");
    }
    if (t != PlyType::kF32 && t != PlyType::kF64 && v != std::floor(v)) {
      Fail("integer property holds \"" + std::string(begin, tok_end) + "\"");
    }
    pos_ = static_cast<size_t>(tok_end - bytes_.data());
    return v;
  }

  const std::string& path_;
  std::string bytes_;
  size_t pos_ = 0;
  PlyFormat format_ = PlyFormat::kAscii;
  std::vector<PlyElement> elements_;
};

Mesh LoadPly(const std::string& path, double unit_scale) {
  std::ifstream is(path, std::ios::binary);
  if (!is) throw Error(path + ": cannot open mesh file");
  std::ostringstream ss;
  ss << is.rdbuf();
  if (is.bad()) throw Error(path + ": cannot read mesh file");
  return PlyParser(path, ss.str()).Parse(unit_scale);
}

// assimp opens the files a mesh names (an OBJ's "mtllib", a glTF's buffers) through its IO
// system. This one opens regular files only: an mtllib naming a directory made assimp 5.2 leak
// the stream it had opened and fail the whole load (found by fuzz/mesh_obj_fuzz), and one naming
// /dev/zero or a FIFO could stall it. A refused material file is a missing one to assimp: it
// falls back to its default material (posefilter uses the geometry alone).
class RegularFilesIOSystem : public Assimp::DefaultIOSystem {
 public:
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    std::error_code ec;
    if (file == nullptr || !std::filesystem::is_regular_file(file, ec)) return nullptr;
    return Assimp::DefaultIOSystem::Open(file, mode);
  }
};

// Everything but PLY goes through assimp (see LoadMesh for why PLY does not).
Mesh LoadWithAssimp(const std::string& path, double unit_scale) {
  Assimp::Importer importer;
  importer.SetIOHandler(new RegularFilesIOSystem);  // the importer owns and deletes it
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
  if (scene == nullptr) {
    // assimp's message may quote file bytes: keep it one printable line of bounded length.
    std::string why = importer.GetErrorString();
    for (char& c : why) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
    }
    if (why.size() > 200) why = why.substr(0, 200) + "...";
    throw Error(path + ": cannot read mesh (" + why + ")");
  }
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mRootNode == nullptr) {
    throw Error(path + ": mesh file holds no triangles");
  }

  Mesh mesh;

  // Depth-first over the node tree; each node's meshes are placed by the product of the
  // transforms from the root down to it (assimp matrices are row-major, column vectors).
  struct Item {
    const aiNode* node;
    aiMatrix4x4 to_root;
  };
  std::vector<Item> stack{{scene->mRootNode, scene->mRootNode->mTransformation}};
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    for (unsigned c = 0; c < item.node->mNumChildren; ++c) {
      const aiNode* child = item.node->mChildren[c];
      stack.push_back({child, item.to_root * child->mTransformation});
    }
    for (unsigned k = 0; k < item.node->mNumMeshes; ++k) {
      const unsigned mesh_index = item.node->mMeshes[k];
      if (mesh_index >= scene->mNumMeshes) continue;
      const aiMesh* am = scene->mMeshes[mesh_index];
      if (am == nullptr || (am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
      // Only vertices referenced by a triangle are kept (points/lines are dropped).
      std::vector<std::uint32_t> remap(am->mNumVertices, std::numeric_limits<std::uint32_t>::max());
      for (unsigned f = 0; f < am->mNumFaces; ++f) {
        const aiFace& face = am->mFaces[f];
        if (face.mNumIndices != 3) continue;
        std::array<std::uint32_t, 3> tri{};
        bool ok = true;
        for (int j = 0; j < 3; ++j) {
          const unsigned vi = face.mIndices[j];
          if (vi >= am->mNumVertices) {
            ok = false;
            break;
          }
          if (remap[vi] == std::numeric_limits<std::uint32_t>::max()) {
            if (mesh.vertices.size() >= std::numeric_limits<std::uint32_t>::max() - 1) {
              throw Error(path + ": mesh has too many vertices");
            }
            const aiVector3D p = item.to_root * am->mVertices[vi];
            remap[vi] = static_cast<std::uint32_t>(mesh.vertices.size());
            mesh.vertices.emplace_back(static_cast<float>(p.x * unit_scale),
                                       static_cast<float>(p.y * unit_scale),
                                       static_cast<float>(p.z * unit_scale));
          }
          tri[j] = remap[vi];
        }
        if (!ok) throw Error(path + ": mesh face indexes a vertex out of range");
        mesh.faces.push_back(tri);
      }
    }
  }
  return mesh;
}

}  // namespace

Mesh LoadMesh(const std::string& path, double unit_scale) {
  if (!std::isfinite(unit_scale) || unit_scale <= 0) {
    throw Error(path + ": mesh unit scale must be finite and > 0 (got " +
                std::to_string(unit_scale) + ")");
  }
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(path + ": mesh file not found");
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": mesh path is not a file");
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > kMaxMeshBytes) {
    throw Error(path + ": mesh file is " + std::to_string(bytes) + " bytes, over the limit of " +
                std::to_string(kMaxMeshBytes) + " bytes (kMaxMeshBytes)");
  }

  // PLY is read by our own strict parser: assimp 5.2's PLY importer hangs or crashes on
  // truncated files (found by the truncation tests), and PLY is the format of the datasets.
  // A file is PLY when its extension is .ply or its content starts with the "ply" magic line.
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  bool is_ply = ext == ".ply";
  if (!is_ply) {
    std::ifstream is(path, std::ios::binary);
    char magic[5] = {0, 0, 0, 0, 0};
    is.read(magic, 5);
    is_ply = std::memcmp(magic, "ply\n", 4) == 0 || std::memcmp(magic, "ply\r\n", 5) == 0;
  }
  Mesh mesh = NameOutOfMemory(path, "mesh", [&] { return is_ply ? LoadPly(path, unit_scale) : LoadWithAssimp(path, unit_scale); });
  mesh.name = std::filesystem::path(path).stem().string();
  if (mesh.faces.empty()) throw Error(path + ": mesh file holds no triangles");
  std::string why;
  if (!mesh.IsValid(&why)) throw Error(path + ": invalid mesh: " + why);
  return mesh;
}

void SaveMeshPly(const Mesh& mesh, const std::string& path) {
  std::string why;
  if (!mesh.IsValid(&why)) throw Error(path + ": refusing to write an invalid mesh: " + why);
  if (mesh.vertices.size() > std::numeric_limits<std::int32_t>::max()) {
    throw Error(path + ": mesh has too many vertices for a PLY int index");
  }
  std::string out =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "comment written by posefilter; units: metres\n"
      "element vertex " + std::to_string(mesh.vertices.size()) + "\n"
      "property float x\n"
      "property float y\n"
      "property float z\n"
      "element face " + std::to_string(mesh.faces.size()) + "\n"
      "property list uchar int vertex_indices\n"
      "end_header\n";
  out.reserve(out.size() + mesh.vertices.size() * 12 + mesh.faces.size() * 13);
  for (const auto& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) PutLe32(out, std::bit_cast<std::uint32_t>(v[k]));
  }
  for (const auto& f : mesh.faces) {
    out.push_back(3);
    for (std::uint32_t idx : f) PutLe32(out, idx);
  }
  WriteFileAtomically(path, [&](std::ostream& os) { os.write(out.data(), static_cast<std::streamsize>(out.size())); });
}

}  // namespace posefilter
