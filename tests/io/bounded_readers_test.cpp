// Readers bounded on any file (issue 57): image sizes read from the header before decoding, lengths against the
// file's size, regular files only, and each bad value reported against the file that holds it.

#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <matio.h>
#include <opencv2/imgcodecs.hpp>

#include "io/files.h"
#include "io/frame_io.h"
#include "io/glb_check.h"
#include "io/image_header.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"
#include "support/input_error.h"
#include "support/test_data.h"

namespace ecv {
namespace {

namespace fs = std::filesystem;
using test::InputErrorMessage;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kDemoFrame = std::string(ECV_SOURCE_DIR) + "/models/frame/000001";

std::string BigEndian(uint32_t value, int bytes) {
  std::string text;
  for (int i = bytes - 1; i >= 0; --i) text.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
  return text;
}

std::string LittleEndian(uint32_t value, int bytes) {
  std::string text;
  for (int i = 0; i < bytes; ++i) text.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
  return text;
}

// A PNG's signature and IHDR chunk (CRC left 0: the header is refused before anything checks it), no image data.
std::string PngHeader(uint32_t width, uint32_t height, int bit_depth, int colour_type) {
  return std::string("\x89PNG\r\n\x1a\n", 8) + BigEndian(13, 4) + "IHDR" + BigEndian(width, 4) + BigEndian(height, 4) +
         static_cast<char>(bit_depth) + static_cast<char>(colour_type) + std::string(3, '\0') + BigEndian(0, 4);
}

// A JPEG's start of image, an APP0 segment and a baseline frame header (SOF0) of 3 components.
std::string JpegHeader(uint32_t width, uint32_t height) {
  return std::string("\xFF\xD8\xFF\xE0", 4) + BigEndian(16, 2) + std::string("JFIF\0\1\1\0\0\1\0\1\0\0", 14) +
         std::string("\xFF\xC0", 2) + BigEndian(17, 2) + '\x08' + BigEndian(height, 2) + BigEndian(width, 2) + '\x03' +
         std::string(9, '\x01');
}

// A little-endian TIFF whose first IFD gives width, length (LONG), bits per sample and samples per pixel (SHORT).
std::string TiffHeader(uint32_t width, uint32_t height, uint32_t bits = 16, uint32_t samples = 4) {
  std::string text = std::string("II*\0", 4) + LittleEndian(8, 4) + LittleEndian(4, 2);
  const auto entry = [&](uint32_t tag, uint32_t type, uint32_t value) {
    text += LittleEndian(tag, 2) + LittleEndian(type, 2) + LittleEndian(1, 4) + LittleEndian(value, 4);
  };
  entry(256, 4, width);
  entry(257, 4, height);
  entry(258, 3, bits);
  entry(277, 3, samples);
  return text + LittleEndian(0, 4);
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(BoundedReaders, ImageHeadersGiveTheSizeOfPngJpegAndTiffFiles) {
  const ImageHeader color = ReadImageHeader(FileBytes(kDemoFrame + "-color.png"));
  EXPECT_EQ(color.format, ImageFormat::kPng);
  EXPECT_EQ(color.width, 640U);
  EXPECT_EQ(color.height, 480U);
  const ImageHeader depth = ReadImageHeader(FileBytes(kDemoFrame + "-depth.png"));
  EXPECT_EQ(depth.bytes_per_pixel, 2);  // 16-bit grey
  const std::string texture = std::string(ECV_SOURCE_DIR) + "/models/meshes/003_cracker_box/003_cracker_box.jpg";
  const ImageHeader jpeg = ReadImageHeader(FileBytes(texture));
  EXPECT_EQ(jpeg.format, ImageFormat::kJpeg);
  EXPECT_EQ(cv::Size(static_cast<int>(jpeg.width), static_cast<int>(jpeg.height)), cv::imread(texture).size());
  const test::TemporaryDirectory directory;
  const std::string tiff = directory.File("small.tif");
  ASSERT_TRUE(cv::imwrite(tiff, cv::Mat(5, 7, CV_16UC1, cv::Scalar(1000))));
  const ImageHeader tiff_header = ReadImageHeader(FileBytes(tiff));
  EXPECT_EQ(tiff_header.format, ImageFormat::kTiff);
  EXPECT_EQ(tiff_header.width, 7U);
  EXPECT_EQ(tiff_header.height, 5U);
  EXPECT_EQ(tiff_header.bytes_per_pixel, 2);
  EXPECT_EQ(ReadDepthImage(tiff, 1000.0).size(), cv::Size(7, 5));  // what the header allows is decoded
  EXPECT_EQ(ReadImageHeader(PngHeader(640, 480, 8, 2).substr(0, 20)).format, ImageFormat::kUnknown);  // cut short
  EXPECT_EQ(ReadImageHeader("GIF89a...").format, ImageFormat::kUnknown);
}

// A header that claims a huge image is refused by every file reader of images, naming the file and the bound, before
// anything is decoded: a valid 20000 x 20000 16-bit PNG of 1 MB would take 2.4 GB (tests/app/cli_test.cpp measures).
TEST(BoundedReaders, ImagesClaimingMoreThan8192PixelsASideAreRefusedFromTheirHeader) {
  const test::TemporaryDirectory directory;
  const std::string png = directory.File("huge.png"), jpeg = directory.File("huge.jpg"),
                    tiff = directory.File("huge.tif");
  WriteBytes(png, PngHeader(20000, 20000, 16, 0));
  WriteBytes(jpeg, JpegHeader(60000, 60000));
  WriteBytes(tiff, TiffHeader(20000, 20000));
  EXPECT_THAT(InputErrorMessage([&] { ReadDepthImage(png, 1000.0); }),
              AllOf(HasSubstr(png + ": depth image: expected a PNG of 1 to 8192 pixels a side, got 20000 x 20000")));
  EXPECT_THAT(InputErrorMessage([&] { ReadColorImage(jpeg); }),
              HasSubstr(jpeg + ": colour image: expected a JPG of 1 to 8192 pixels a side, got 60000 x 60000"));
  EXPECT_THAT(InputErrorMessage([&] { ReadColorImage(tiff); }),
              HasSubstr(tiff + ": colour image: expected a TIFF of 1 to 8192 pixels a side, got 20000 x 20000"));
  WriteBytes(directory.File("wide.tif"), TiffHeader(8192, 8192, 32, 4));  // within the sides, 16 bytes a pixel: 1 GB
  EXPECT_THAT(InputErrorMessage([&] { ReadColorImage(directory.File("wide.tif")); }),
              HasSubstr("expected a TIFF of at most 512 MB decoded"));

  // A label image of a pasted object.
  const std::string prefix = directory.File("000001");
  for (const char* suffix : {"-color.png", "-depth.png", "-meta.mat"})
    fs::copy_file(kDemoFrame + suffix, prefix + suffix);
  WriteBytes(prefix + "-label.png", PngHeader(20000, 20000, 8, 0));
  const LoadedFrame frame = LoadYcbvFrame(kDemoFrame);
  EXPECT_THAT(InputErrorMessage([&] { PasteYcbvObject(frame, prefix, frame.ground_truth.at(0).object_name); }),
              HasSubstr(prefix + "-label.png: label: expected a PNG of 1 to 8192 pixels a side, got 20000 x 20000"));

  // A mesh's texture.
  const std::string mesh = directory.File("textured.obj");
  WriteBytes(directory.File("textured.mtl"), "newmtl skin\nmap_Kd huge.jpg\n");
  WriteBytes(mesh,
             "mtllib textured.mtl\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl skin\n"
             "f 1/1 2/2 3/3\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadMesh(mesh); }),
              HasSubstr(jpeg + ": texture: expected a JPG of 1 to 8192 pixels a side, got 60000 x 60000"));
  WriteBytes(directory.File("textured.mtl"), "newmtl skin\nmap_Kd small.tif\n");  // the same mesh, a small texture
  ASSERT_TRUE(cv::imwrite(directory.File("small.tif"), cv::Mat(4, 4, CV_8UC3, cv::Scalar(10, 20, 30))));
  const TriangleMesh loaded = LoadMesh(mesh);
  EXPECT_EQ(loaded.materials.at(static_cast<size_t>(loaded.parts.at(0).material)).texture.size(), cv::Size(4, 4));
}

// A GLB whose chunk claims 4 GB is refused before assimp allocates it; a well-formed one passes the check.
TEST(BoundedReaders, GlbChunkLengthsAreCheckedAgainstTheFile) {
  const test::TemporaryDirectory directory;
  const std::string json = R"({"asset":{"version":"2.0"}} )";  // padded to a multiple of 4 bytes
  const auto glb = [&](uint32_t chunk_length) {
    const std::string body = LittleEndian(chunk_length, 4) + "JSON" + json;
    return "glTF" + LittleEndian(2, 4) + LittleEndian(static_cast<uint32_t>(12 + body.size()), 4) + body;
  };
  const std::string good = directory.File("good.glb"), bad = directory.File("bad.glb");
  WriteBytes(good, glb(static_cast<uint32_t>(json.size())));
  WriteBytes(bad, glb(0xFFFFFFF0U));
  EXPECT_NO_THROW(CheckGlbFile(good));
  EXPECT_THAT(InputErrorMessage([&] { LoadMesh(bad); }),
              HasSubstr(bad + ": GLB chunk 0 length: expected at most the 28 bytes left of the file's length, got "
                              "4294967280"));
  const std::string longer = directory.File("longer.glb");  // a header length past the file's end
  std::string bytes = glb(static_cast<uint32_t>(json.size()));
  bytes.replace(8, 4, LittleEndian(1 << 30, 4));
  WriteBytes(longer, bytes);
  EXPECT_THAT(InputErrorMessage([&] { LoadMesh(longer); }),
              HasSubstr(longer + ": GLB length: expected at most the file's " + std::to_string(bytes.size())));
}

// A FIFO would make a reader wait for ever, a link to /dev/zero feed it without end, a folder fail deep inside the
// standard library: each is refused by name before it is read.
TEST(BoundedReaders, OnlyRegularFilesAreRead) {
  const test::TemporaryDirectory directory;
  const auto fifo = [&](const std::string& name) {
    const std::string path = directory.File(name);
    EXPECT_EQ(mkfifo(path.c_str(), 0600), 0) << path;
    return path;
  };
  const std::string pipe = "expected a regular file, got a named pipe (FIFO)";
  const std::string mesh_fifo = fifo("pipe.obj"), json_fifo = fifo("pipe.json"), png_fifo = fifo("pipe.png");
  const std::string pcd_fifo = fifo("pipe.pcd");
  EXPECT_THAT(InputErrorMessage([&] { LoadMesh(mesh_fifo); }), HasSubstr(mesh_fifo + ": mesh: " + pipe));
  EXPECT_THAT(InputErrorMessage([&] { LoadFrameJson(json_fifo); }), HasSubstr(json_fifo + ": JSON file: " + pipe));
  EXPECT_THAT(InputErrorMessage([&] { ReadColorImage(png_fifo); }), HasSubstr(png_fifo + ": colour image: " + pipe));
  EXPECT_THAT(InputErrorMessage([&] { LoadPcdFrame(pcd_fifo); }), HasSubstr(pcd_fifo + ": PCD: " + pipe));

  // A material library that is a FIFO would hold the mesh importer until its timeout.
  const std::string obj = directory.File("fifo-material.obj"), mtl = fifo("fifo.mtl");
  WriteBytes(obj, "mtllib fifo.mtl\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 3\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadMesh(obj); }), HasSubstr(mtl + ": material library: " + pipe));

  const std::string zero = directory.File("zero.ply");
  fs::create_symlink("/dev/zero", zero);
  EXPECT_THAT(InputErrorMessage([&] { LoadMesh(zero); }),
              HasSubstr(zero + ": mesh: expected a regular file, got a device"));

  // Folders in the place of a BOP scene's scene_gt.json and of a YCB-Video meta file.
  const fs::path scene = directory.path() / "scene";
  fs::create_directories(scene / "rgb");
  fs::create_directories(scene / "depth");
  fs::create_directories(scene / "scene_gt.json");
  fs::copy_file(kDemoFrame + "-color.png", scene / "rgb" / "000001.png");
  fs::copy_file(kDemoFrame + "-depth.png", scene / "depth" / "000001.png");
  WriteBytes((scene / "scene_camera.json").string(),
             R"({"1": {"cam_K": [1066.778, 0, 312.9869, 0, 1067.487, 241.3109, 0, 0, 1], "depth_scale": 0.1}})");
  EXPECT_THAT(InputErrorMessage([&] { LoadBopFrame(scene.string(), 1); }),
              HasSubstr((scene / "scene_gt.json").string() + ": JSON file: expected a regular file, got a directory"));
  const std::string prefix = directory.File("000001");
  for (const char* suffix : {"-color.png", "-depth.png"}) fs::copy_file(kDemoFrame + suffix, prefix + suffix);
  fs::create_directories(prefix + "-meta.mat");
  EXPECT_THAT(InputErrorMessage([&] { LoadYcbvFrame(prefix); }),
              HasSubstr(prefix + "-meta.mat: meta: expected a regular file, got a directory"));
}

// A depth scale of 0 or below, intrinsics of 0 or NaN and images of two sizes are errors of the file that holds them
// (the frame JSON, the meta file, scene_camera.json), not of the depth image or the frame's prefix.
TEST(BoundedReaders, BadValuesAreNamedInTheFileThatHoldsThem) {
  const test::TemporaryDirectory directory;
  const std::string json = directory.File("frame.json");
  const auto frame_json = [&](const std::string& depth, double depth_scale, double fx) {
    WriteJsonFile(json, {{"color", kDemoFrame + "-color.png"},
                         {"depth", depth},
                         {"depth_scale", depth_scale},
                         {"camera", {fx, 1067.487, 312.9869, 241.3109}}});
    return InputErrorMessage([&] { LoadFrameJson(json); });
  };
  const std::string depth = kDemoFrame + "-depth.png";
  for (const double scale : {0.0, -10000.0}) {
    EXPECT_THAT(frame_json(depth, scale, 1066.778),
                AllOf(HasSubstr(json + ": depth_scale: expected a finite positive scale"), Not(HasSubstr(depth))));
  }
  EXPECT_THAT(frame_json(depth, 10000, 0.0), HasSubstr(json + ": camera: expected fx and fy finite and positive"));
  const std::string small = directory.File("small-depth.png");
  ASSERT_TRUE(cv::imwrite(small, cv::Mat(240, 320, CV_16UC1, cv::Scalar(10000))));
  EXPECT_THAT(frame_json(small, 10000, 1066.778),
              HasSubstr(json + ": depth image size: expected 640x480 as the colour image (" + kDemoFrame +
                        "-color.png), got 320x240 (" + small + ")"));

  // A YCB-Video meta file.
  const std::string prefix = directory.File("000001");
  for (const char* suffix : {"-color.png", "-depth.png"}) fs::copy_file(kDemoFrame + suffix, prefix + suffix);
  const auto meta = [&](double factor_depth, double fx) {
    mat_t* file = Mat_CreateVer((prefix + "-meta.mat").c_str(), nullptr, MAT_FT_MAT5);
    const auto write = [&](const char* name, std::vector<size_t> dims, std::vector<double> values) {
      matvar_t* variable =
          Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, static_cast<int>(dims.size()), dims.data(), values.data(), 0);
      Mat_VarWrite(file, variable, MAT_COMPRESSION_NONE);
      Mat_VarFree(variable);
    };
    write("intrinsic_matrix", {3, 3}, {fx, 0, 0, 0, 1067.487, 0, 312.9869, 241.3109, 1});
    write("factor_depth", {1, 1}, {factor_depth});
    write("cls_indexes", {1, 1}, {2});
    write("poses", {3, 4, 1}, {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1});  // column-major [I | (0, 0, 1)]
    Mat_Close(file);
    return InputErrorMessage([&] { LoadYcbvFrame(prefix); });
  };
  EXPECT_THAT(meta(0.0, 1066.778), HasSubstr(prefix + "-meta.mat: factor_depth: expected a finite positive scale"));
  EXPECT_THAT(meta(10000, std::nan("")),
              AllOf(HasSubstr(prefix + "-meta.mat: intrinsic_matrix: expected fx and fy finite and positive"),
                    HasSubstr("fx nan")));

  // A BOP scene's scene_camera.json: a depth scale of 0 is said as such (1000 / 0 would be "inf").
  const fs::path scene = directory.path() / "scene";
  fs::create_directories(scene / "rgb");
  fs::create_directories(scene / "depth");
  fs::copy_file(kDemoFrame + "-color.png", scene / "rgb" / "000001.png");
  fs::copy_file(kDemoFrame + "-depth.png", scene / "depth" / "000001.png");
  const std::string camera = (scene / "scene_camera.json").string();
  const auto bop = [&](double fx, double depth_scale) {
    WriteJsonFile(
        camera, {{"1", {{"cam_K", {fx, 0, 312.9869, 0, 1067.487, 241.3109, 0, 0, 1}}, {"depth_scale", depth_scale}}}});
    return InputErrorMessage([&] { LoadBopFrame(scene.string(), 1); });
  };
  EXPECT_THAT(bop(1066.778, 0.0), AllOf(HasSubstr(camera + ": depth_scale (image 1): expected a finite positive scale"),
                                        HasSubstr("got 0"), Not(HasSubstr("inf"))));
  EXPECT_THAT(bop(-1.0, 0.1), HasSubstr(camera + ": cam_K (image 1): expected fx and fy finite and positive"));
}

}  // namespace
}  // namespace ecv
