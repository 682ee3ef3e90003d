// A mesh file read by LoadMesh (missing textures allowed, as --allow-missing-textures): the input's first byte picks
// the extension, '0'-'8' for .obj .ply .gltf .glb .stl .off .fbx .dae .3ds (other bytes wrap around); the rest is
// the file.

#include <array>

#include "fuzz_util.h"
#include "io/mesh_io.h"

// LoadMesh imports in the program ecvpose-mesh-import, which ends with this process (PR_SET_PDEATHSIG) and whose crash
// reaches LoadMesh as an error: libFuzzer sees only what LoadMesh throws.
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::array<const char*, 9> kExtensions = {".obj", ".ply", ".gltf", ".glb", ".stl",
                                                         ".off", ".fbx", ".dae",  ".3ds"};
  if (size == 0) return 0;
  const unsigned char pick = static_cast<unsigned char>(data[0] - '0');
  const std::string path = (ecv::fuzz::ScratchDir() / "mesh").string() + kExtensions[pick % kExtensions.size()];
  ecv::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data) + 1, size - 1));
  ecv::MeshLoadOptions options;
  options.allow_missing_textures = true;
  options.import_timeout_s = 5.0;  // a hanging importer is ended (an InputError) before libFuzzer's 10 s timeout
  std::vector<std::string> warnings;
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::LoadMesh(path, options, &warnings); });
  std::filesystem::remove(path);
  return 0;
}
