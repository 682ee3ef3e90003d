// The binary seeds of make_corpus.sh, made from real files: small crops of a frame and of an organized cloud, a
// YCB-Video meta trimmed to the variables LoadYcbvFrame reads, a trimmed mesh in the formats no real file of ours
// has, a stored mesh blob and an ONI recording.
//
//   ecv_fuzz_seeds png-pair COLOR.png DEPTH.png OUT     32 x 24 crops joined by kPartSeparator
//   ecv_fuzz_seeds ycbv-meta META.mat OUT_DIR           MATLAB v5, v5 compressed and v7.3 (HDF5)
//   ecv_fuzz_seeds pcd CLOUD.pcd OUT_DIR                a 16 x 12 crop (or 192 points) as ascii, binary, compressed
//   ecv_fuzz_seeds mesh-formats MESH OUT_DIR            fuzz_mesh inputs: extension digit, then the file
//   ecv_fuzz_seeds mesh-blob MESH OUT                   EncodeMeshBlob with textures capped at 8 pixels
//   ecv_fuzz_seeds oni COLOR.png DEPTH.png OUT          an ONI recording of two 16 x 12 crops (OniWriter)

#include <matio.h>

#include <array>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/oni_writer.h"
#include "fuzz_util.h"
#include "io/mesh_blob.h"
#include "io/mesh_io.h"

namespace {
namespace fs = std::filesystem;

std::string Encode(const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error("cannot encode a PNG");
  return {bytes.begin(), bytes.end()};
}

// The centre 32 x 24 pixels of each image, colour then depth.
void PngPair(const std::string& color_path, const std::string& depth_path, const std::string& out) {
  const cv::Mat color = cv::imread(color_path, cv::IMREAD_UNCHANGED);
  const cv::Mat depth = cv::imread(depth_path, cv::IMREAD_UNCHANGED);
  if (color.empty() || depth.empty()) throw std::runtime_error("cannot read " + color_path + " or " + depth_path);
  const cv::Rect centre(color.cols / 2 - 16, color.rows / 2 - 12, 32, 24);
  ecv::fuzz::WriteFile(out, Encode(color(centre)) + ecv::fuzz::kPartSeparator + Encode(depth(centre)));
}

void YcbvMeta(const std::string& path, const fs::path& out_dir) {
  mat_t* in = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  if (in == nullptr) throw std::runtime_error("cannot open " + path);
  const std::array<std::pair<const char*, mat_ft>, 3> versions = {
      {{"v5", MAT_FT_MAT5}, {"v5-compressed", MAT_FT_MAT5}, {"v73", MAT_FT_MAT73}}};
  for (const auto& [name, version] : versions) {
    const std::string file = (out_dir / (std::string("seed-meta-") + name + ".mat")).string();
    mat_t* out = Mat_CreateVer(file.c_str(), nullptr, version);
    if (out == nullptr) throw std::runtime_error("cannot create " + file);
    for (const char* variable : {"intrinsic_matrix", "factor_depth", "cls_indexes", "poses"}) {
      matvar_t* value = Mat_VarRead(in, variable);
      if (value == nullptr) throw std::runtime_error(path + " has no " + variable);
      const matio_compression compression =
          std::string(name) == "v5-compressed" ? MAT_COMPRESSION_ZLIB : MAT_COMPRESSION_NONE;
      Mat_VarWrite(out, value, compression);
      Mat_VarFree(value);
    }
    Mat_Close(out);
  }
  Mat_Close(in);
}

// The cloud's own fields, cropped: 16 x 12 points around the centre of an organized cloud, else its first 192 points.
void Pcd(const std::string& path, const fs::path& out_dir) {
  pcl::PCLPointCloud2 cloud;
  if (pcl::io::loadPCDFile(path, cloud) < 0) throw std::runtime_error("cannot read " + path);
  pcl::PCLPointCloud2 crop = cloud;
  crop.width = cloud.height > 1 ? 16 : std::min<uint32_t>(192, cloud.width);
  crop.height = cloud.height > 1 ? 12 : 1;
  crop.row_step = crop.width * cloud.point_step;
  crop.data.clear();
  for (uint32_t v = 0; v < crop.height; ++v) {
    const uint32_t row = cloud.height > 1 ? cloud.height / 2 + v : 0, column = cloud.height > 1 ? cloud.width / 2 : 0;
    const auto first = cloud.data.begin() + row * cloud.row_step + column * cloud.point_step;
    crop.data.insert(crop.data.end(), first, first + crop.row_step);
  }
  const std::string stem = (out_dir / ("seed-" + fs::path(path).stem().string())).string();
  pcl::PCDWriter writer;
  if (writer.writeASCII(stem + "-ascii.pcd", crop) < 0 || writer.writeBinary(stem + "-binary.pcd", crop) < 0 ||
      writer.writeBinaryCompressed(stem + "-compressed.pcd", crop) < 0) {
    throw std::runtime_error("cannot write " + stem + "-*.pcd");
  }
}

std::string Base64(const unsigned char* data, size_t size) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string text;
  for (size_t i = 0; i < size; i += 3) {
    const uint32_t chunk = (uint32_t{data[i]} << 16) | (i + 1 < size ? uint32_t{data[i + 1]} << 8 : 0U) |
                           (i + 2 < size ? uint32_t{data[i + 2]} : 0U);
    for (size_t k = 0; k < 4; ++k) text += i + k <= size ? kDigits[(chunk >> (18 - 6 * k)) & 63U] : '=';
  }
  return text;
}

// A .gltf with its buffer inside (data URI), so that it is one file.
std::string EmbedGltfBuffer(const aiExportDataBlob& blob) {
  nlohmann::json gltf =
      nlohmann::json::parse(static_cast<const char*>(blob.data), static_cast<const char*>(blob.data) + blob.size);
  if (blob.next == nullptr || gltf["buffers"].size() != 1) throw std::runtime_error("glTF export: not one buffer");
  gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," +
                              Base64(static_cast<const unsigned char*>(blob.next->data), blob.next->size);
  return gltf.dump();
}

// A binary PLY of positions and faces (assimp 5.2's binary PLY writer writes colours as floats where its header says
// uchar).
std::string BinaryPly(const aiMesh& mesh) {
  std::ostringstream text;
  text << "ply\nformat binary_little_endian 1.0\nelement vertex " << mesh.mNumVertices
       << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << mesh.mNumFaces
       << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (unsigned i = 0; i < mesh.mNumVertices; ++i) text.write(reinterpret_cast<const char*>(&mesh.mVertices[i]), 12);
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    text.put(static_cast<char>(mesh.mFaces[f].mNumIndices));
    text.write(reinterpret_cast<const char*>(mesh.mFaces[f].mIndices), 4 * mesh.mFaces[f].mNumIndices);
  }
  return text.str();
}

// OFF, which assimp reads but does not write.
std::string Off(const aiMesh& mesh) {
  std::ostringstream text;
  text << "OFF\n" << mesh.mNumVertices << " " << mesh.mNumFaces << " 0\n";
  for (unsigned i = 0; i < mesh.mNumVertices; ++i) {
    text << mesh.mVertices[i].x << " " << mesh.mVertices[i].y << " " << mesh.mVertices[i].z << "\n";
  }
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    text << mesh.mFaces[f].mNumIndices;
    for (unsigned k = 0; k < mesh.mFaces[f].mNumIndices; ++k) text << " " << mesh.mFaces[f].mIndices[k];
    text << "\n";
  }
  return text.str();
}

void MeshFormats(const std::string& path, const fs::path& out_dir) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate);
  if (scene == nullptr || scene->mNumMeshes == 0) throw std::runtime_error("cannot read " + path);
  // fuzz_mesh's extension digits: 1 .ply, 2 .gltf, 3 .glb, 4 .stl, 5 .off, 6 .fbx, 7 .dae, 8 .3ds.
  const std::array<std::pair<const char*, char>, 7> formats = {
      {{"gltf2", '2'}, {"glb2", '3'}, {"stlb", '4'}, {"stl", '4'}, {"fbxa", '6'}, {"collada", '7'}, {"3ds", '8'}}};
  const std::string stem = (out_dir / ("seed-" + fs::path(path).stem().string())).string();
  Assimp::Exporter exporter;
  for (const auto& [format, digit] : formats) {
    const aiExportDataBlob* blob = exporter.ExportToBlob(scene, format);
    if (blob == nullptr) throw std::runtime_error(std::string("assimp cannot export ") + format);
    const std::string bytes = std::string(format) == "gltf2"
                                  ? EmbedGltfBuffer(*blob)
                                  : std::string(static_cast<const char*>(blob->data), blob->size);
    ecv::fuzz::WriteFile(stem + "." + format, digit + bytes);
  }
  ecv::fuzz::WriteFile(stem + ".plyb", '1' + BinaryPly(*scene->mMeshes[0]));
  ecv::fuzz::WriteFile(stem + ".off", '5' + Off(*scene->mMeshes[0]));
}

void MeshBlob(const std::string& path, const std::string& out) {
  ecv::MeshBlobOptions options;
  options.max_texture_size = 8;
  const std::vector<unsigned char> blob = ecv::EncodeMeshBlob(ecv::LoadMesh(path), options);
  ecv::fuzz::WriteFile(out, std::string(blob.begin(), blob.end()));
}

// Two frames (a crop of the real frame, then the crop next to it) in 1 mm depth units, as `ecvpose record` writes them.
void Oni(const std::string& color_path, const std::string& depth_path, const std::string& out) {
  const cv::Mat color = cv::imread(color_path, cv::IMREAD_COLOR);
  const cv::Mat depth = cv::imread(depth_path, cv::IMREAD_UNCHANGED);
  if (color.empty() || depth.type() != CV_16UC1) {
    throw std::runtime_error("cannot read " + color_path + " or " + depth_path);
  }
  ecv::OniWriterOptions options;
  options.width = 16;
  options.height = 12;
  options.depth_unit = ecv::OniDepthUnit::kMillimetre;
  ecv::OniWriter writer(out, options);
  for (const int shift : {0, 16}) {
    const cv::Rect crop(color.cols / 2 - 8 + shift, color.rows / 2 - 6, 16, 12);
    cv::Mat rgb;
    cv::cvtColor(color(crop), rgb, cv::COLOR_BGR2RGB);
    writer.Write(rgb, depth(crop) / 10);  // YCB-Video's 100 um units to millimetres
  }
  writer.Finish();
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.size() == 4 && args[0] == "png-pair") {
      PngPair(args[1], args[2], args[3]);
    } else if (args.size() == 3 && args[0] == "ycbv-meta") {
      YcbvMeta(args[1], args[2]);
    } else if (args.size() == 3 && args[0] == "pcd") {
      Pcd(args[1], args[2]);
    } else if (args.size() == 3 && args[0] == "mesh-formats") {
      MeshFormats(args[1], args[2]);
    } else if (args.size() == 3 && args[0] == "mesh-blob") {
      MeshBlob(args[1], args[2]);
    } else if (args.size() == 4 && args[0] == "oni") {
      Oni(args[1], args[2], args[3]);
    } else {
      std::cerr << "usage: see the comment at the top of fuzz/make_seeds.cpp\n";
      return 2;
    }
  } catch (const std::exception& error) {
    std::cerr << "ecv_fuzz_seeds: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
