// Fuzz target: LoadMesh (include/posefilter/mesh.h) on a .ply file — posefilter's own strict PLY parser (ascii, binary little/big endian): LoadMesh picks it for a .ply path or a file starting with the "ply" magic line.
// Seeds: fuzz/corpus/mesh_ply_fuzz/.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "posefilter/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static posefilter_fuzz::ScratchFile file("mesh", ".ply");
  const std::string& path = file.Write(data, size);
  posefilter_fuzz::ReadOrError(path, [&] {
    const posefilter::Mesh mesh = posefilter::LoadMesh(path, 1.0);
    std::string why;
    posefilter_fuzz::Require(mesh.IsValid(&why), "a loaded mesh is valid (Mesh::IsValid)");
  });
  return 0;
}
