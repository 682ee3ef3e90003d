// The view pairs of the discriminative benchmark (issue 5):
// (a) recognition: the textured mesh (those of the recognition libraries: the google16k meshes and the YCB-Video
//     banana) rendered from the library's sampled view nearest to the ground truth, against the real frame;
// (b) hard: the mustard bottle in videos 0001 and 0002;
// (c) easy: frames 1 and 19 of one video, and two renders 30 degrees apart;
// and (a) again against the whole real frame, clutter included.

#include "discriminative_data.h"

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "core/pose.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "render/renderer.h"
#include "render/view_sampling.h"

namespace ecv::bench {
namespace {

// The google16k meshes with textures, moved into the YCB-Video object frames, and the one YCB-Video model whose
// texture came through (the banana, already in its frame), as the recognition libraries hold them.
const char* const kGoogle16k[] = {"003_cracker_box",    "004_sugar_box",   "005_tomato_soup_can",
                                  "006_mustard_bottle", "009_gelatin_box", "010_potted_meat_can"};
const char* const kYcbvTextured[] = {"011_banana"};
constexpr int kLibraryViews = 100;

std::string FramePrefix(const std::string& data, const std::string& video, int frame) {
  char text[64];
  std::snprintf(text, sizeof(text), "/ycbv_subset/Example-Scenes/%s/%06d", video.c_str(), frame);
  return data + text;
}

Eigen::Isometry3d Google16kToYcbv(const std::string& data, const std::string& object) {
  return ReadTransformTable(data + "/ycbv_subset/derived/google16k_to_ycbv.txt").at(object);
}

// Real views of every object of one frame.
std::map<std::string, ObjectView> RealViews(const std::string& data, const std::string& video, int frame) {
  const std::string prefix = FramePrefix(data, video, frame);
  const LoadedFrame loaded = LoadYcbvFrame(prefix);
  const cv::Mat label = cv::imread(prefix + "-label.png", cv::IMREAD_UNCHANGED);
  std::map<std::string, ObjectView> views;
  for (const GroundTruth& truth : loaded.ground_truth) {
    views[truth.object_name] = {video + "/" + std::to_string(frame), loaded.rgbd, label == truth.object_id,
                                truth.camera_from_object};
  }
  return views;
}

// Renders the textured meshes; the library is `kLibraryViews` views over the sphere.
class MeshViews {
 public:
  MeshViews(const std::string& data, const PinholeCamera& camera, double library_distance_m, Shading shading)
      : camera_(camera) {
    render_options_.shading = shading;
    for (const char* object : kGoogle16k) {
      MeshLoadOptions options;
      options.object_from_mesh = Google16kToYcbv(data, object);
      Add(object, LoadMesh(data + "/ycbv_subset/ycb_google16k_textured/" + object + "_textured.obj", options),
          library_distance_m);
    }
    for (const char* object : kYcbvTextured) {
      Add(object, LoadMesh(data + "/ycbv_subset/models/" + object + "/textured_simple.obj"), library_distance_m);
    }
  }

  bool Has(const std::string& object) const { return meshes_.count(object) > 0; }
  std::vector<std::string> Objects() const {
    std::vector<std::string> objects;
    for (const auto& [object, mesh] : meshes_) objects.push_back(object);
    return objects;
  }

  ObjectView Render(const std::string& object, const Eigen::Isometry3d& camera_from_object, const std::string& name) {
    const RenderResult rendered = renderer_.Render(meshes_.at(object), camera_, camera_from_object, render_options_);
    ObjectView view{name, {rendered.color, rendered.depth, camera_, name}, rendered.mask, camera_from_object};
    return view;
  }

  // The library view whose viewing direction is nearest to that of `camera_from_object`.
  ObjectView NearestLibraryView(const std::string& object, const Eigen::Isometry3d& camera_from_object) {
    const Eigen::Vector3d centre = spheres_.at(object).center_object;
    auto direction = [&](const Eigen::Isometry3d& pose) {
      return (pose.inverse().translation() - centre).normalized();
    };
    const Eigen::Vector3d target = direction(camera_from_object);
    const std::vector<Eigen::Isometry3d>& views = library_.at(object);
    size_t best = 0;
    for (size_t i = 1; i < views.size(); ++i) {
      if (direction(views[i]).dot(target) > direction(views[best]).dot(target)) best = i;
    }
    return Render(object, views[best], "library view " + std::to_string(best));
  }

  // Two views 30 degrees apart in azimuth at 30 degrees elevation.
  std::pair<ObjectView, ObjectView> ViewsThirtyDegreesApart(const std::string& object) {
    const BoundingSphere& sphere = spheres_.at(object);
    const double distance = FitViewDistance(sphere.radius_m, camera_, 0.1);
    auto at = [&](double azimuth_deg) {
      const double azimuth = azimuth_deg * M_PI / 180.0, elevation = M_PI / 6.0;
      const Eigen::Vector3d offset(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                   std::sin(elevation));
      return LookAt(sphere.center_object + distance * offset, sphere.center_object, Eigen::Vector3d::UnitZ(),
                    Eigen::Vector3d::UnitX());
    };
    return {Render(object, at(20.0), "render azimuth 20"), Render(object, at(50.0), "render azimuth 50")};
  }

 private:
  // The mesh uploaded, and its library of kLibraryViews views over the sphere.
  void Add(const std::string& object, const TriangleMesh& mesh, double library_distance_m) {
    meshes_[object] = renderer_.AddMesh(mesh);
    spheres_[object] = ComputeBoundingSphere(mesh);
    ViewSamplingOptions sampling;
    sampling.num_views = kLibraryViews;
    sampling.distance_m = library_distance_m;
    library_[object] = SampleViews(spheres_[object], camera_, sampling);
  }

  PinholeCamera camera_;
  RenderOptions render_options_;
  Renderer renderer_;
  std::map<std::string, MeshId> meshes_;
  std::map<std::string, BoundingSphere> spheres_;
  std::map<std::string, std::vector<Eigen::Isometry3d>> library_;
};

}  // namespace

std::vector<ViewPair> LoadViewPairs(const std::string& data, double library_distance_m, Shading shading) {
  std::vector<ViewPair> pairs;
  const PinholeCamera camera = LoadYcbvFrame(FramePrefix(data, "0001", 1)).rgbd.camera;
  MeshViews meshes(data, camera, library_distance_m, shading);
  for (const std::string video : {"0000", "0001", "0002"}) {
    const bool held_out = video == "0002";
    const std::map<std::string, ObjectView> first = RealViews(data, video, 1), last = RealViews(data, video, 19);
    for (const auto& [object, view] : first) {
      pairs.push_back({"easy", object, held_out, view, last.at(object)});  // (c) frames 1 and 19
    }
    for (const int frame : {1, 7, 13, 19}) {  // (a) library view against the real frame
      for (const auto& [object, view] : RealViews(data, video, frame)) {
        if (!meshes.Has(object)) continue;
        pairs.push_back(
            {"recognition", object, held_out, meshes.NearestLibraryView(object, view.camera_from_object), view});
      }
    }
  }
  const size_t count = pairs.size();
  for (size_t i = 0; i < count; ++i) {  // (a) again, against the whole real frame
    if (pairs[i].set != "recognition") continue;
    ViewPair cluttered = pairs[i];
    cluttered.set = "recognition in clutter";
    cluttered.clutter = true;
    pairs.push_back(cluttered);
  }
  for (const int frame : {1, 7, 13, 19}) {  // (b) the mustard bottle in two videos, about 50 degrees apart
    pairs.push_back({"hard", "006_mustard_bottle", true, RealViews(data, "0001", frame).at("006_mustard_bottle"),
                     RealViews(data, "0002", frame).at("006_mustard_bottle")});
  }
  for (const std::string& object : meshes.Objects()) {  // (c) two renders 30 degrees apart
    auto [a, b] = meshes.ViewsThirtyDegreesApart(object);
    pairs.push_back({"easy", object, false, a, b});
  }
  return pairs;
}

}  // namespace ecv::bench
