// prior/ppf_cache.cc — the on-disk cache of PPF models and the meshes' content hash
// (posefilter/ppf.h).
//
// File layout (little-endian, as the host writes it; a file from another byte order fails its
// checks and is rebuilt):
//   char[8]  magic "PFPPF\0\0\2"
//   u64      mesh content hash
//   f64      distance_step (option)    i32 angle_bins, max_bucket (options)
//   f64      diameter, step (metres)   i32 distance_bins
//   u64      point count P, entry count E
//   P × 6 f32  points (p, n)
//   (KeyCount + 1) × u32 offsets
//   E × (u16 reference, u16 alpha)
//   u64      FNV-1a hash of every byte above
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "core/option_check.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/ppf.h"

namespace posefilter {

namespace {

constexpr char kMagic[8] = {'P', 'F', 'P', 'P', 'F', 0, 0, 2};

// 64-bit FNV-1a of n bytes, continuing from h.
constexpr std::uint64_t kFnvStart = 1469598103934665603ull;
std::uint64_t Fnv(const void* p, std::size_t n, std::uint64_t h = kFnvStart) {
  const unsigned char* c = static_cast<const unsigned char*>(p);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  return h;
}

template <typename T>
void Put(std::string* out, const T& v) {
  out->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

// The options a model's table depends on, as they are stored in the header (and hashed into
// the file name): distance_step f64, angle_bins i32, max_bucket i32.
std::string ModelOptionBytes(const PpfOptions& opt) {
  std::string s;
  Put(&s, opt.distance_step);
  Put(&s, std::int32_t(opt.angle_bins));
  Put(&s, std::int32_t(opt.max_bucket));
  return s;
}

// The cache file of the mesh with content hash `mesh_hash`.
std::string CachePath(std::uint64_t mesh_hash, const PpfOptions& opt, const std::string& cache_dir) {
  const std::string options = ModelOptionBytes(opt);
  char name[64];
  std::snprintf(name, sizeof(name), "ppf-%016llx-%08llx.bin", (unsigned long long)mesh_hash,
                (unsigned long long)(Fnv(options.data(), options.size()) & 0xffffffffull));
  return (std::filesystem::path(cache_dir) / name).string();
}

std::string Serialize(const PpfModel& m, const PpfOptions& opt) {
  std::string s(kMagic, sizeof(kMagic));
  Put(&s, m.mesh_hash);
  s += ModelOptionBytes(opt);
  Put(&s, m.diameter);
  Put(&s, m.step);
  Put(&s, std::int32_t(m.distance_bins));
  Put(&s, std::uint64_t(m.points.size()));
  Put(&s, std::uint64_t(m.entries.size()));
  for (const OrientedPoint& q : m.points) {
    s.append(reinterpret_cast<const char*>(q.p.data()), 3 * sizeof(float));
    s.append(reinterpret_cast<const char*>(q.n.data()), 3 * sizeof(float));
  }
  s.append(reinterpret_cast<const char*>(m.offsets.data()), m.offsets.size() * sizeof(std::uint32_t));
  for (const PpfEntry& e : m.entries) {
    Put(&s, e.reference);
    Put(&s, e.alpha);
  }
  Put(&s, Fnv(s.data(), s.size()));
  return s;
}

// Reads bytes of a cache file in order; every read checks that the bytes are there.
class Reader {
 public:
  explicit Reader(const std::string& s) : s_(s) {}
  template <typename T>
  bool Get(T* v) {
    if (s_.size() - pos_ < sizeof(T)) return false;
    std::memcpy(v, s_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  // The next out->size() bytes into *out.
  bool GetBytes(std::string* out) {
    if (s_.size() - pos_ < out->size()) return false;
    out->assign(s_, pos_, out->size());
    pos_ += out->size();
    return true;
  }
  std::size_t left() const { return s_.size() - pos_; }

 private:
  const std::string& s_;
  std::size_t pos_ = 0;
};

// The model in `bytes` if it is whole and made from `mesh_hash` with `opt`; else false and why.
bool Deserialize(const std::string& bytes, std::uint64_t mesh_hash, const PpfOptions& opt, PpfModel* m,
                 std::string* why) {
  if (bytes.size() < sizeof(kMagic) + 8 || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    return Fail(why, "not a posefilter PPF cache file");
  std::uint64_t stored_sum = 0;
  std::memcpy(&stored_sum, bytes.data() + bytes.size() - 8, 8);
  if (Fnv(bytes.data(), bytes.size() - 8) != stored_sum) return Fail(why, "checksum mismatch (damaged or cut short)");
  Reader r(bytes);
  char magic[8];
  const std::string options = ModelOptionBytes(opt);
  std::string stored_options(options.size(), '\0');
  std::int32_t distance_bins = 0;
  std::uint64_t points = 0, entries = 0;
  r.Get(&magic);
  if (!r.Get(&m->mesh_hash) || !r.GetBytes(&stored_options) || !r.Get(&m->diameter) || !r.Get(&m->step) ||
      !r.Get(&distance_bins) || !r.Get(&points) || !r.Get(&entries))
    return Fail(why, "header cut short");
  if (m->mesh_hash != mesh_hash) return Fail(why, "made from another mesh");
  if (stored_options != options) return Fail(why, "made with other options");
  m->angle_bins = opt.angle_bins;
  m->distance_bins = distance_bins;
  if (!(m->diameter > 0) || !(m->step > 0) || distance_bins < 1 || distance_bins > 1000)
    return Fail(why, "bad header values");
  const std::size_t keys = std::size_t(m->KeyCount()) + 1;
  if (points > PpfModel::kMaxPoints || r.left() != points * 24 + keys * 4 + entries * 4 + 8)
    return Fail(why, "size does not match its header");
  m->points.resize(points);
  for (OrientedPoint& q : m->points)
    for (int k = 0; k < 6; ++k) r.Get(k < 3 ? &q.p[k] : &q.n[k - 3]);
  m->offsets.resize(keys);
  for (std::uint32_t& o : m->offsets) r.Get(&o);
  m->entries.resize(entries);
  for (PpfEntry& e : m->entries) {
    r.Get(&e.reference);
    r.Get(&e.alpha);
    if (e.reference >= points) return Fail(why, "entry points past the model's points");
  }
  if (m->offsets.front() != 0 || m->offsets.back() != entries) return Fail(why, "offsets do not span the entries");
  for (std::size_t k = 1; k < keys; ++k)
    if (m->offsets[k] < m->offsets[k - 1]) return Fail(why, "offsets are not ordered");
  return true;
}

}  // namespace

std::string DefaultPpfCacheDir() {
  if (const char* d = std::getenv("POSEFILTER_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return (std::filesystem::path(d) / "posefilter").string();
  if (const char* d = std::getenv("HOME"); d && *d) return (std::filesystem::path(d) / ".cache" / "posefilter").string();
  return "";
}

std::uint64_t MeshContentHash(const Mesh& mesh) {
  const std::uint64_t counts[2] = {mesh.vertices.size(), mesh.faces.size()};
  std::uint64_t h = Fnv(counts, sizeof(counts));
  for (const Eigen::Vector3f& v : mesh.vertices) h = Fnv(v.data(), 3 * sizeof(float), h);
  for (const auto& f : mesh.faces) h = Fnv(f.data(), 3 * sizeof(std::uint32_t), h);
  return h;
}

std::string PpfCachePath(const Mesh& mesh, const PpfOptions& opt, const std::string& cache_dir) {
  return CachePath(MeshContentHash(mesh), opt, cache_dir);
}

PpfModel LoadOrBuildPpfModel(const Mesh& mesh, const PpfOptions& opt, const std::string& cache_dir,
                             std::string* status) {
  auto say = [&](const std::string& s) {
    if (status) *status = s;
  };
  if (cache_dir.empty()) {
    say("built");
    return BuildPpfModel(mesh, opt);
  }
  const std::uint64_t mesh_hash = MeshContentHash(mesh);
  const std::string path = CachePath(mesh_hash, opt, cache_dir);
  std::string rebuilt;
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) {
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    PpfModel m;
    std::string why;
    if (in.good() || in.eof()) {
      if (Deserialize(bytes, mesh_hash, opt, &m, &why)) {
        say("loaded");
        return m;
      }
    } else {
      why = "unreadable";
    }
    rebuilt = why;
  }
  PpfModel m = BuildPpfModel(mesh, opt);
  std::string note = rebuilt.empty() ? "built" : "rebuilt (" + rebuilt + ")";
  try {
    std::filesystem::create_directories(cache_dir, ec);
    if (ec) throw Error(cache_dir + ": " + ec.message());
    const std::string bytes = Serialize(m, opt);
    WriteFileAtomically(path, [&](std::ostream& os) { os.write(bytes.data(), std::streamsize(bytes.size())); });
  } catch (const Error& e) {
    note += std::string(" (cache not written: ") + e.what() + ")";
  }
  say(note);
  return m;
}

}  // namespace posefilter
