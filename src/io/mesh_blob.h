#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace ecv {

/// How a mesh is packed into one self-contained byte string (EncodeMeshBlob), e.g. to keep it in a model library.
struct MeshBlobOptions {
  /// Textures larger than this (pixels per side) are stored downscaled (CapTextureSize, the renderer's own cap): a
  /// verification render covers a few hundred pixels of a model. 0 keeps them as they are.
  int max_texture_size = 2048;
  /// LZ4-HC level of the textures' RGB rows (lossless), 1 (fastest to write) to 12 (smallest); decoding is as fast
  /// at any level. At 9 YCB's textures (2048 x 2048) take 1.1-1.5 MB, less than as PNG (1.3-1.7 MB).
  int lz4_level = 9;

  void Check() const;
};

/// The mesh as bytes: the header "ECVMESH1", its name, materials (diffuse colour, texture as width, height and its
/// RGB rows compressed by LZ4-HC), and each part's vertex arrays (float32) and triangles (int32), little-endian.
/// Round-trips through DecodeMeshBlob exactly: the same vertices, triangles and materials, and the textures' pixels as
/// stored (after the size cap).
std::vector<unsigned char> EncodeMeshBlob(const TriangleMesh& mesh, const MeshBlobOptions& options = {});

/// The mesh of EncodeMeshBlob's bytes; without `with_textures` the materials' textures are left empty (not
/// decompressed), e.g. for geometry alone. Throws InputError naming `source` and the field for bytes that are cut
/// short, of another format, or inconsistent (a triangle's index beyond its part's vertices, an unknown material,
/// a texture that does not decode).
TriangleMesh DecodeMeshBlob(const unsigned char* data, size_t size, const std::string& source,
                            bool with_textures = true);

}  // namespace ecv
