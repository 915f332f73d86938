// Fuzz target: LoadMesh (include/posefilter/mesh.h) on a .obj file — the assimp path of LoadMesh (OBJ and every other non-PLY format): the input is written to a .obj file, so assimp's OBJ importer reads it (a "ply" magic line still routes it to the PLY parser).
// Seeds: fuzz/corpus/mesh_obj_fuzz/.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "posefilter/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static posefilter_fuzz::ScratchFile file("mesh", ".obj");
  const std::string& path = file.Write(data, size);
  posefilter_fuzz::ReadOrError(path, [&] {
    const posefilter::Mesh mesh = posefilter::LoadMesh(path, 1.0);
    std::string why;
    posefilter_fuzz::Require(mesh.IsValid(&why), "a loaded mesh is valid (Mesh::IsValid)");
  });
  return 0;
}
