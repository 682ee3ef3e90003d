// Renderer tests on real data (issue 3): the YCB cracker box at its ground-truth pose against the real
// YCB-Video frame, rendered depth on the mesh surface, vertex colours of an LM-O model, errors, repeatability.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "render/renderer.h"
#include "render/view_sampling.h"
#include "support/test_data.h"

namespace ecv {
namespace {

// object_from_mesh of `object` from derived/google16k_to_ycbv.txt (p_ycbv = R p_g16k + t).
Eigen::Isometry3d Google16kToYcbv(const std::string& object) {
  return ReadTransformTable(test::DataPath("ycbv_subset/derived/google16k_to_ycbv.txt")).at(object);
}

TriangleMesh LoadCrackerBox() {
  MeshLoadOptions options;
  options.object_from_mesh = Google16kToYcbv("003_cracker_box");
  return LoadMesh(test::DataPath("ycbv_subset/ycb_google16k_textured/003_cracker_box_textured.obj"), options);
}

TriangleMesh LoadLmoCan() {
  MeshLoadOptions options;
  options.metres_per_unit = 0.001;
  return LoadMesh(test::DataPath("lmo_subset/data/bop/lmo/models/obj_000005.ply"), options);
}

struct YcbFrame {
  LoadedFrame frame;
  Eigen::Isometry3d camera_from_object;
};

YcbFrame LoadFrame0001() {
  YcbFrame result{LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001")), {}};
  for (const GroundTruth& truth : result.frame.ground_truth) {
    if (truth.object_name == "003_cracker_box") result.camera_from_object = truth.camera_from_object;
  }
  return result;
}

// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5), with its
// barycentric weights of a, b, c.
Eigen::Vector3d ClosestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c, Eigen::Vector3d* weights) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return *weights = {1, 0, 0}, a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return *weights = {0, 1, 0}, b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return *weights = {1 - v, v, 0}, a + v * ab;
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return *weights = {0, 0, 1}, c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return *weights = {1 - w, 0, w}, a + w * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return *weights = {0, 1 - w, w}, b + w * (c - b);
  }
  const double denominator = 1.0 / (va + vb + vc);
  const double v = vb * denominator, w = vc * denominator;
  return *weights = {1 - v - w, v, w}, a + ab * v + ac * w;
}

// Nearest surface point of `mesh` (object frame) to `point`: distance (metres) and the vertex colour
// interpolated there (if the mesh has vertex colours).
struct SurfacePoint {
  double distance = 1e9;
  Eigen::Vector3d color = Eigen::Vector3d::Zero();
};

// Longest triangle edge of `mesh`, metres: a triangle with a vertex farther than the best distance plus
// this cannot hold a nearer point.
double LongestEdge(const TriangleMesh& mesh) {
  double longest = 0.0;
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3i& triangle : part.triangles) {
      for (int k = 0; k < 3; ++k) {
        longest =
            std::max(longest, double((part.positions[triangle[k]] - part.positions[triangle[(k + 1) % 3]]).norm()));
      }
    }
  }
  return longest;
}

SurfacePoint NearestSurfacePoint(const TriangleMesh& mesh, const Eigen::Vector3d& point, double longest_edge) {
  SurfacePoint best;
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3i& triangle : part.triangles) {
      const Eigen::Vector3d a = part.positions[triangle[0]].cast<double>();
      if ((a - point).norm() > best.distance + longest_edge) continue;
      Eigen::Vector3d weights;
      const Eigen::Vector3d closest = ClosestOnTriangle(point, a, part.positions[triangle[1]].cast<double>(),
                                                        part.positions[triangle[2]].cast<double>(), &weights);
      const double distance = (closest - point).norm();
      if (distance >= best.distance) continue;
      best.distance = distance;
      if (part.colors.empty()) continue;
      best.color = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) best.color += weights[k] * part.colors[triangle[k]].cast<double>();
    }
  }
  return best;
}

// Pixels of `mask` on a grid of `step`, plus every `step`-th pixel of its boundary.
std::vector<cv::Point> SamplePixels(const cv::Mat& mask, int step) {
  std::vector<cv::Point> pixels;
  int boundary = 0;
  for (int v = 1; v + 1 < mask.rows; ++v) {
    for (int u = 1; u + 1 < mask.cols; ++u) {
      if (mask.at<uint8_t>(v, u) == 0) continue;
      const bool edge = !mask.at<uint8_t>(v - 1, u) || !mask.at<uint8_t>(v + 1, u) || !mask.at<uint8_t>(v, u - 1) ||
                        !mask.at<uint8_t>(v, u + 1);
      if ((edge && boundary++ % step == 0) || (u % step == 0 && v % step == 0)) pixels.emplace_back(u, v);
    }
  }
  return pixels;
}

double Median(std::vector<double> values) {
  if (values.empty()) return NAN;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

TEST(RenderTest, CrackerBoxAtGroundTruthMatchesRealDepthAndLabel) {
  const YcbFrame ycb = LoadFrame0001();
  ASSERT_FALSE(ycb.camera_from_object.matrix().isIdentity()) << "no ground truth for 003_cracker_box";
  Renderer renderer;
  const MeshId box = renderer.AddMesh(LoadCrackerBox());
  const RgbdFrame& frame = ycb.frame.rgbd;
  const RenderResult rendered = renderer.Render(box, frame.camera, ycb.camera_from_object);

  const cv::Mat label_image =
      cv::imread(test::DataPath("ycbv_subset/Example-Scenes/0001/000001-label.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(label_image.size(), rendered.mask.size());
  const cv::Mat label = label_image == 2;  // cls_index 2 = 003_cracker_box
  std::vector<double> differences;
  for (int v = 0; v < label.rows; ++v) {
    for (int u = 0; u < label.cols; ++u) {
      const float real = frame.depth.at<float>(v, u);
      if (rendered.mask.at<uint8_t>(v, u) && label.at<uint8_t>(v, u) && real > 0.0F) {
        differences.push_back(std::abs(rendered.depth.at<float>(v, u) - real));
      }
    }
  }
  ASSERT_GT(differences.size(), 5000U);
  EXPECT_LT(Median(differences), 0.01) << "median |rendered - real depth| in metres";
  const double intersection = cv::countNonZero(rendered.mask & label);
  const double iou = intersection / cv::countNonZero(rendered.mask | label);
  EXPECT_GT(iou, 0.75);
  // The rendered depth is 0 exactly where the mask is.
  EXPECT_EQ(cv::countNonZero(rendered.depth > 0), cv::countNonZero(rendered.mask));
}

TEST(RenderTest, RenderedDepthBackProjectsOntoTheMesh) {
  const YcbFrame ycb = LoadFrame0001();
  const TriangleMesh mesh = LoadCrackerBox();
  Renderer renderer;
  const PinholeCamera& camera = ycb.frame.rgbd.camera;
  const RenderResult rendered = renderer.Render(renderer.AddMesh(mesh), camera, ycb.camera_from_object);
  const std::vector<cv::Point> pixels = SamplePixels(rendered.mask, 9);
  ASSERT_GT(pixels.size(), 300U);
  const Eigen::Isometry3d object_from_camera = ycb.camera_from_object.inverse();
  const double longest_edge = LongestEdge(mesh);
  std::vector<double> distances;
  for (const cv::Point& pixel : pixels) {
    const Eigen::Vector3d point =
        camera.BackProject(Eigen::Vector2d(pixel.x, pixel.y), rendered.depth.at<float>(pixel.y, pixel.x));
    distances.push_back(NearestSurfacePoint(mesh, object_from_camera * point, longest_edge).distance);
  }
  EXPECT_LT(*std::max_element(distances.begin(), distances.end()), 0.001) << "every point within 1 mm";
  // Far tighter in fact: a half-pixel offset of the projection gives about 0.2 mm here.
  EXPECT_LT(Median(distances), 2e-5);
}

TEST(RenderTest, VertexColouredPlyRendersWithItsColours) {
  const TriangleMesh mesh = LoadLmoCan();
  ASSERT_EQ(mesh.Coloring(mesh.parts.at(0)), MeshColoring::kVertexColor);
  Renderer renderer;
  const PinholeCamera camera{572.4114, 573.57043, 325.2611, 242.04899, 640, 480};
  ViewSamplingOptions sampling;
  sampling.num_views = 3;
  const BoundingSphere sphere = ComputeBoundingSphere(mesh);
  const MeshId can = renderer.AddMesh(mesh);
  const double longest_edge = LongestEdge(mesh);
  for (const Eigen::Isometry3d& camera_from_object : SampleViews(sphere, camera, sampling)) {
    const RenderResult rendered = renderer.Render(can, camera, camera_from_object);
    Eigen::Vector3d rendered_sum = Eigen::Vector3d::Zero(), expected_sum = Eigen::Vector3d::Zero();
    double absolute_error = 0.0;
    const std::vector<cv::Point> pixels = SamplePixels(rendered.mask, 12);
    ASSERT_GT(pixels.size(), 100U);
    for (const cv::Point& pixel : pixels) {
      const cv::Vec3b rgb = rendered.color.at<cv::Vec3b>(pixel.y, pixel.x);
      const Eigen::Vector3d color = Eigen::Vector3d(rgb[0], rgb[1], rgb[2]) / 255.0;
      const Eigen::Vector3d point =
          camera.BackProject(Eigen::Vector2d(pixel.x, pixel.y), rendered.depth.at<float>(pixel.y, pixel.x));
      const Eigen::Vector3d expected =
          NearestSurfacePoint(mesh, camera_from_object.inverse() * point, longest_edge).color;
      rendered_sum += color;
      expected_sum += expected;
      absolute_error += (color - expected).cwiseAbs().mean();
    }
    const double n = static_cast<double>(pixels.size());
    EXPECT_LT((rendered_sum / n - expected_sum / n).cwiseAbs().maxCoeff(), 0.005) << "mean colour, RGB in [0, 1]";
    EXPECT_LT(absolute_error / n, 0.005) << "mean per-pixel colour error, RGB in [0, 1] (8-bit rounding: 0.001)";
  }
}

TEST(RenderTest, MeshWithoutTrianglesIsAnInputError) {
  TriangleMesh mesh;
  mesh.name = "points_only";
  mesh.parts.resize(1);
  mesh.parts[0].positions = {{0, 0, 0}, {0.1F, 0, 0}, {0, 0.1F, 0}};
  Renderer renderer;
  try {
    renderer.AddMesh(mesh);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("points_only"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("triangles"), std::string::npos) << error.what();
  }
  mesh.parts[0].triangles = {{0, 1, 3}};  // index out of range
  EXPECT_THROW(renderer.AddMesh(mesh), InputError);
}

// An image side past kMaxRenderSide is refused by name before anything is allocated; kMaxRenderSide itself renders.
TEST(RenderTest, ImageSidesBeyondTheBoundAreAnInputError) {
  TriangleMesh mesh;
  mesh.name = "triangle";
  mesh.parts.resize(1);
  mesh.parts[0].positions = {{0, 0, 0}, {0.1F, 0, 0}, {0, 0.1F, 0}};
  mesh.parts[0].triangles = {{0, 1, 2}};
  Renderer renderer;
  const MeshId triangle = renderer.AddMesh(mesh);
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  camera_from_object.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);
  const PinholeCamera wide{500.0, 500.0, 10.0, 0.0, kMaxRenderSide, 1};
  EXPECT_EQ(renderer.Render(triangle, wide, camera_from_object).depth.cols, kMaxRenderSide);
  for (const PinholeCamera& camera : {PinholeCamera{500.0, 500.0, 10.0, 0.0, kMaxRenderSide + 1, 1},
                                      PinholeCamera{500.0, 500.0, 0.0, 10.0, 1, 16384}}) {
    try {
      renderer.Render(triangle, camera, camera_from_object);
      ADD_FAILURE() << camera.width << "x" << camera.height << " was rendered";
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()), "render camera: width/height: expected at most 8192 pixels, got " +
                                               std::to_string(camera.width) + "x" + std::to_string(camera.height));
    }
  }
}

TEST(RenderTest, CullingBackFacesOfAClosedMeshKeepsTheImage) {
  const YcbFrame ycb = LoadFrame0001();
  const TriangleMesh mesh = LoadCrackerBox();
  ASSERT_TRUE(mesh.IsClosedOutward());
  Renderer renderer;
  const MeshId box = renderer.AddMesh(mesh);
  const PinholeCamera& camera = ycb.frame.rgbd.camera;
  RenderOptions culled;
  culled.cull_back_faces = true;
  const RenderResult all = renderer.Render(box, camera, ycb.camera_from_object);
  const RenderResult front = renderer.Render(box, camera, ycb.camera_from_object, culled);
  const int pixels = cv::countNonZero(all.mask);
  ASSERT_GT(pixels, 5000);
  // Only where a front and a back face meet on the silhouette may a pixel change.
  EXPECT_LE(cv::countNonZero(all.mask != front.mask), pixels / 1000);
  const cv::Mat both = all.mask & front.mask;
  EXPECT_LT(cv::norm(all.depth, front.depth, cv::NORM_INF, both), 1e-6) << "the same surface, not the far side";
  EXPECT_EQ(cv::norm(all.color, front.color, cv::NORM_INF, both), 0.0);

  // Turned inside out, the culled box shows its far side: the faces nearest the camera now turn away from it.
  TriangleMesh inside_out = mesh;
  for (MeshPart& part : inside_out.parts) {
    for (Eigen::Vector3i& triangle : part.triangles) std::swap(triangle.y(), triangle.z());
  }
  const RenderResult far = renderer.Render(renderer.AddMesh(inside_out), camera, ycb.camera_from_object, culled);
  const cv::Mat seen = all.mask & far.mask;
  ASSERT_GT(cv::countNonZero(seen), pixels * 9 / 10);
  cv::Mat deeper = far.depth > all.depth + 0.01F;
  EXPECT_GT(cv::countNonZero(deeper & seen), cv::countNonZero(seen) * 9 / 10);
}

TEST(RenderTest, RenderingTwiceGivesIdenticalImages) {
  const YcbFrame ycb = LoadFrame0001();
  Renderer renderer;
  const MeshId box = renderer.AddMesh(LoadCrackerBox());
  const MeshId can = renderer.AddMesh(LoadLmoCan());
  const PinholeCamera& camera = ycb.frame.rgbd.camera;
  const RenderResult first = renderer.Render(box, camera, ycb.camera_from_object);
  Eigen::Isometry3d camera_from_can = Eigen::Isometry3d::Identity();
  camera_from_can.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);
  RenderOptions shaded;
  shaded.shading = Shading::kHeadlight;
  renderer.Render(can, camera, camera_from_can, shaded);  // other state in between
  const RenderResult second = renderer.Render(box, camera, ycb.camera_from_object);
  ASSERT_GT(cv::countNonZero(first.mask), 1000);
  EXPECT_EQ(cv::norm(first.color, second.color, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(first.depth, second.depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(first.mask, second.mask, cv::NORM_INF), 0.0);
  // A second renderer (its own context) gives the same images.
  Renderer other;
  const RenderResult third = other.Render(other.AddMesh(LoadCrackerBox()), camera, ycb.camera_from_object);
  EXPECT_EQ(cv::norm(first.color, third.color, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(first.depth, third.depth, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace ecv
