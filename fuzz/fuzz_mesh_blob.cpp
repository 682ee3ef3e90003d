// A stored mesh (the bytes of EncodeMeshBlob, as kept in a model library) decoded by DecodeMeshBlob, with and without
// its textures.

#include "fuzz_util.h"
#include "io/mesh_blob.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::DecodeMeshBlob(data, size, "fuzz input", false); });
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::DecodeMeshBlob(data, size, "fuzz input", true); });
  return 0;
}
