// A mesh packed into one byte string and back: see mesh_blob.h for the layout.

#include "io/mesh_blob.h"

#include <cstdint>
#include <cstring>

#include <lz4.h>
#include <lz4hc.h>
#include <stdexcept>

#include "core/error.h"

namespace ecv {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "mesh blobs are written in the host's byte order");

constexpr char kMagic[8] = {'E', 'C', 'V', 'M', 'E', 'S', 'H', '1'};
constexpr uint32_t kHasNormals = 1U, kHasTexcoords = 2U, kHasColors = 4U;

class BlobWriter {
 public:
  void Bytes(const void* data, size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    out_.insert(out_.end(), bytes, bytes + size);
  }
  void U32(uint32_t value) { Bytes(&value, sizeof(value)); }
  void I32(int32_t value) { Bytes(&value, sizeof(value)); }
  void F32(float value) { Bytes(&value, sizeof(value)); }
  void String(const std::string& text) {
    U32(static_cast<uint32_t>(text.size()));
    Bytes(text.data(), text.size());
  }
  template <typename Vector>
  void Array(const std::vector<Vector>& values) {  // Eigen fixed-size vectors of float or int, packed
    if (!values.empty()) Bytes(values.front().data(), values.size() * sizeof(Vector));
  }
  std::vector<unsigned char> Take() { return std::move(out_); }

 private:
  std::vector<unsigned char> out_;
};

class BlobReader {
 public:
  BlobReader(const unsigned char* data, size_t size, std::string source)
      : data_(data), size_(size), source_(std::move(source)) {}

  const unsigned char* Bytes(size_t size, const char* field) {
    if (size > size_ - offset_) {
      ThrowInputError(source_, field, std::to_string(size) + " more bytes of the mesh",
                      std::to_string(size_ - offset_) + " left at byte " + std::to_string(offset_));
    }
    const unsigned char* at = data_ + offset_;
    offset_ += size;
    return at;
  }
  uint32_t U32(const char* field) { return Read<uint32_t>(field); }
  int32_t I32(const char* field) { return Read<int32_t>(field); }
  float F32(const char* field) { return Read<float>(field); }
  std::string String(const char* field) {
    const uint32_t size = U32(field);
    return {reinterpret_cast<const char*>(Bytes(size, field)), size};
  }
  template <typename Vector>
  std::vector<Vector> Array(size_t count, const char* field) {
    if (count > (size_ - offset_) / sizeof(Vector)) Bytes(count * sizeof(Vector), field);  // throws: cut short
    std::vector<Vector> values(count);
    if (count > 0) std::memcpy(values.front().data(), Bytes(count * sizeof(Vector), field), count * sizeof(Vector));
    return values;
  }
  /// A count of items that take at least `min_bytes` each: more than the bytes left can hold is corrupt.
  uint32_t Count(const char* field, size_t min_bytes) {
    const uint32_t count = U32(field);
    if (count > (size_ - offset_) / min_bytes) {
      ThrowInputError(source_, field, "at most " + std::to_string((size_ - offset_) / min_bytes) + " in the bytes left",
                      std::to_string(count));  // a corrupt count: nothing is allocated for it
    }
    return count;
  }
  bool AtEnd() const { return offset_ == size_; }
  const std::string& source() const { return source_; }

 private:
  template <typename T>
  T Read(const char* field) {
    T value;
    std::memcpy(&value, Bytes(sizeof(T), field), sizeof(T));
    return value;
  }

  const unsigned char* data_;
  size_t size_;
  size_t offset_ = 0;
  std::string source_;
};

// A texture as its size and its RGB rows compressed with LZ4-HC: about as small as a PNG of YCB's textures and
// decoded 15x faster (bench/EXPERIMENTS.md, 2026-11-25, "textures stored as PNG").
void WriteTexture(BlobWriter& writer, const cv::Mat& texture, const MeshBlobOptions& options) {
  if (texture.empty()) {
    writer.U32(0);
    return;
  }
  cv::Mat image = CapTextureSize(texture, options.max_texture_size);
  if (!image.isContinuous()) image = image.clone();
  const int raw = static_cast<int>(image.total() * 3);
  std::vector<char> packed(static_cast<size_t>(LZ4_compressBound(raw)));
  const int size = LZ4_compress_HC(reinterpret_cast<const char*>(image.data), packed.data(), raw,
                                   static_cast<int>(packed.size()), options.lz4_level);
  if (size <= 0) throw std::runtime_error("LZ4 could not compress a texture of " + std::to_string(raw) + " bytes");
  writer.U32(static_cast<uint32_t>(image.cols));
  writer.U32(static_cast<uint32_t>(image.rows));
  writer.U32(static_cast<uint32_t>(size));
  writer.Bytes(packed.data(), static_cast<size_t>(size));
}

cv::Mat ReadTexture(BlobReader& reader, bool decode) {
  const uint32_t width = reader.U32("texture width");
  if (width == 0) return {};
  const uint32_t height = reader.U32("texture height");
  const uint32_t size = reader.U32("texture size");
  const char* packed = reinterpret_cast<const char*>(reader.Bytes(size, "texture"));
  if (!decode) return {};
  constexpr uint32_t kMaxSide = 1U << 15;
  if (width > kMaxSide || height == 0 || height > kMaxSide) {
    ThrowInputError(reader.source(), "texture size", "1 to 32768 pixels a side",
                    std::to_string(width) + " x " + std::to_string(height));
  }
  // LZ4 packs at most about 255 bytes into one: a texture that claims more pixels than its bytes can hold is
  // refused before its pixels are allocated.
  if (static_cast<uint64_t>(width) * height * 3 > 255ULL * size + 64) {
    ThrowInputError(reader.source(), "texture",
                    "LZ4 data of " + std::to_string(width) + " x " + std::to_string(height) + " RGB pixels",
                    std::to_string(size) + " bytes, too few for them");
  }
  cv::Mat rgb(static_cast<int>(height), static_cast<int>(width), CV_8UC3);
  const int raw = static_cast<int>(rgb.total() * 3);
  if (LZ4_decompress_safe(packed, reinterpret_cast<char*>(rgb.data), static_cast<int>(size), raw) != raw) {
    ThrowInputError(reader.source(), "texture",
                    "LZ4 data of " + std::to_string(width) + " x " + std::to_string(height) + " RGB pixels",
                    "bytes that do not decode to that");
  }
  return rgb;
}

void WritePart(BlobWriter& writer, const MeshPart& part) {
  writer.I32(part.material);
  writer.U32(static_cast<uint32_t>(part.positions.size()));
  writer.U32((part.normals.empty() ? 0U : kHasNormals) | (part.texcoords.empty() ? 0U : kHasTexcoords) |
             (part.colors.empty() ? 0U : kHasColors));
  writer.U32(static_cast<uint32_t>(part.triangles.size()));
  writer.Array(part.positions);
  writer.Array(part.normals);
  writer.Array(part.texcoords);
  writer.Array(part.colors);
  writer.Array(part.triangles);
}

MeshPart ReadPart(BlobReader& reader, size_t num_materials) {
  MeshPart part;
  part.material = reader.I32("part material");
  if (part.material < -1 || part.material >= static_cast<int>(num_materials)) {
    ThrowInputError(reader.source(), "part material", "-1 or a material index below " + std::to_string(num_materials),
                    std::to_string(part.material));
  }
  const size_t vertices = reader.U32("part vertices");
  const uint32_t arrays = reader.U32("part arrays");
  const size_t triangles = reader.U32("part triangles");
  part.positions = reader.Array<Eigen::Vector3f>(vertices, "positions");
  if ((arrays & kHasNormals) != 0) part.normals = reader.Array<Eigen::Vector3f>(vertices, "normals");
  if ((arrays & kHasTexcoords) != 0) part.texcoords = reader.Array<Eigen::Vector2f>(vertices, "texcoords");
  if ((arrays & kHasColors) != 0) part.colors = reader.Array<Eigen::Vector3f>(vertices, "colors");
  part.triangles = reader.Array<Eigen::Vector3i>(triangles, "triangles");
  for (const Eigen::Vector3i& triangle : part.triangles) {
    if (triangle.minCoeff() < 0 || triangle.maxCoeff() >= static_cast<int>(vertices)) {
      ThrowInputError(reader.source(), "triangles", "vertex indices below " + std::to_string(vertices),
                      std::to_string(triangle.minCoeff()) + ".." + std::to_string(triangle.maxCoeff()));
    }
  }
  return part;
}

}  // namespace

void MeshBlobOptions::Check() const {
  if (max_texture_size < 0) {
    ThrowInputError("mesh blob options", "max_texture_size", ">= 0 pixels (0: no cap)",
                    std::to_string(max_texture_size));
  }
  if (lz4_level < 1 || lz4_level > LZ4HC_CLEVEL_MAX) {
    ThrowInputError("mesh blob options", "lz4_level", "1 to " + std::to_string(LZ4HC_CLEVEL_MAX),
                    std::to_string(lz4_level));
  }
}

std::vector<unsigned char> EncodeMeshBlob(const TriangleMesh& mesh, const MeshBlobOptions& options) {
  options.Check();
  BlobWriter writer;
  writer.Bytes(kMagic, sizeof(kMagic));
  writer.String(mesh.name);
  writer.U32(static_cast<uint32_t>(mesh.materials.size()));
  for (const MeshMaterial& material : mesh.materials) {
    writer.String(material.name);
    for (int c = 0; c < 3; ++c) writer.F32(material.diffuse_color[c]);
    writer.String(material.texture_path);
    WriteTexture(writer, material.texture, options);
  }
  writer.U32(static_cast<uint32_t>(mesh.parts.size()));
  for (const MeshPart& part : mesh.parts) WritePart(writer, part);
  return writer.Take();
}

TriangleMesh DecodeMeshBlob(const unsigned char* data, size_t size, const std::string& source, bool with_textures) {
  BlobReader reader(data, size, source);
  if (size < sizeof(kMagic) || std::memcmp(reader.Bytes(sizeof(kMagic), "header"), kMagic, sizeof(kMagic)) != 0) {
    ThrowInputError(source, "header", "a mesh of format ECVMESH1");
  }
  TriangleMesh mesh;
  mesh.name = reader.String("name");
  mesh.materials.resize(reader.Count("materials", 24));  // name, colour, path, texture size
  for (MeshMaterial& material : mesh.materials) {
    material.name = reader.String("material name");
    for (int c = 0; c < 3; ++c) material.diffuse_color[c] = reader.F32("diffuse colour");
    material.texture_path = reader.String("texture path");
    material.texture = ReadTexture(reader, with_textures);
  }
  const uint32_t parts = reader.Count("parts", 16);  // material, vertices, arrays, triangles
  for (uint32_t p = 0; p < parts; ++p) mesh.parts.push_back(ReadPart(reader, mesh.materials.size()));
  if (!reader.AtEnd()) ThrowInputError(source, "end", "the mesh's last byte after its last part");
  return mesh;
}

}  // namespace ecv
