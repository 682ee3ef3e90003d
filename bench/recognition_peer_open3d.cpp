// The Open3D recognition peer: its global registration recipe (FPFH, feature RANSAC, ICP) through
// bench/recognition_open3d.py, one process per frame; input and output through files in a scratch folder.

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "bench_util.h"
#include "core/pose.h"
#include "recognition_peers.h"

namespace ecv::bench {
namespace {

void WriteFloats(const std::filesystem::path& path, const float* values, size_t count) {
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(values), static_cast<std::streamsize>(count * sizeof(float)));
  if (!file) throw std::runtime_error("could not write " + path.string());
}

class Open3dPeer : public RecognitionPeer {
 public:
  Open3dPeer(const std::vector<PeerModel>& models, const PeerOptions& options, std::string python, std::string script)
      : options_(options),
        python_(std::move(python)),
        script_(std::move(script)),
        directory_(std::filesystem::temp_directory_path() / ("ecv_open3d_peer_" + std::to_string(getpid()))) {
    options_.Check();
    std::filesystem::create_directories(directory_);
    for (size_t k = 0; k < models.size(); ++k) {
      std::vector<float> rows;  // x y z nx ny nz per point
      for (size_t i = 0; i < models[k].points.size(); ++i) {
        rows.insert(rows.end(), models[k].points[i].data(), models[k].points[i].data() + 3);
        rows.insert(rows.end(), models[k].normals[i].data(), models[k].normals[i].data() + 3);
      }
      WriteFloats(directory_ / ("model_" + std::to_string(k) + ".bin"), rows.data(), rows.size());
      Model model;
      model.name = models[k].name;
      VoxelDownsample(models[k].points, {}, options_.voxel_m, &model.points, nullptr);
      models_.push_back(std::move(model));
    }
  }

  ~Open3dPeer() override {
    std::error_code ignored;
    std::filesystem::remove_all(directory_, ignored);
  }

  Open3dPeer(const Open3dPeer&) = delete;
  Open3dPeer& operator=(const Open3dPeer&) = delete;

  PeerResult Recognize(const RgbdFrame& frame) override {
    const cv::Mat depth = frame.depth.isContinuous() ? frame.depth : frame.depth.clone();
    WriteFloats(directory_ / "depth.bin", depth.ptr<float>(), depth.total());
    {
      std::ofstream camera(directory_ / "camera.txt");
      camera.precision(12);
      camera << depth.cols << ' ' << depth.rows << ' ' << frame.camera.fx << ' ' << frame.camera.fy << ' '
             << frame.camera.cx << ' ' << frame.camera.cy << '\n';
    }
    const std::filesystem::path output = directory_ / "result.txt";
    std::filesystem::remove(output);
    const PeerOptions& o = options_;
    const std::string command =
        "OMP_NUM_THREADS=1 " + ShellQuoted(python_) + " " + ShellQuoted(script_) + " " +
        ShellQuoted(directory_.string()) + " " + ShellQuoted(output.string()) + " --voxel " + Fixed(o.voxel_m, 6) +
        " --normal-radius " + Fixed(o.normal_radius_m, 6) + " --fpfh-radius " + Fixed(o.fpfh_radius_m, 6) +
        " --iterations " + std::to_string(o.open3d_iterations) + " --confidence " + Fixed(o.open3d_confidence, 6) +
        " --distance " + Fixed(o.inlier_distance_m, 6) + " --similarity " + Fixed(o.pcl_similarity, 6) +
        " --icp-iterations " + std::to_string(o.icp_iterations) + " --seed " + std::to_string(o.seed);
    const int code = RunShellCommand(command);
    if (code != 0) throw std::runtime_error(script_ + " failed (exit code " + std::to_string(code) + ")");

    PeerResult result;
    std::ifstream file(output);
    file >> result.scene_ms >> result.scene_points;
    result.time_ms = result.scene_ms;
    const std::vector<Eigen::Vector3f> scene_points = SceneCloud(frame, options_.voxel_m);
    const RadiusGrid scene_grid(scene_points, static_cast<float>(options_.inlier_distance_m));
    for (const Model& model : models_) {
      double time_ms = 0.0, fitness = 0.0;
      Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
      file >> time_ms >> fitness;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) file >> matrix(r, c);
      }
      if (!file) throw std::runtime_error(output.string() + ": no pose for " + model.name);
      result.time_ms += time_ms;
      if (fitness <= 0.0) continue;  // Open3D always returns a pose; fitness 0: not one inlier
      Detection detection;
      detection.model = model.name;
      detection.camera_from_object = RigidFromMatrix(matrix, output.string(), model.name);
      detection.inlier_fraction = InlierFraction(model.points, detection.camera_from_object, scene_grid);
      KeepIfAccepted(detection, options_, &result);
    }
    std::sort(result.detections.begin(), result.detections.end(),
              [](const Detection& a, const Detection& b) { return a.score > b.score; });
    return result;
  }

 private:
  struct Model {
    std::string name;
    std::vector<Eigen::Vector3f> points;  // voxelised, object frame: what the inlier share is counted on
  };

  PeerOptions options_;
  std::string python_, script_;
  std::filesystem::path directory_;
  std::vector<Model> models_;
};

}  // namespace

std::unique_ptr<RecognitionPeer> MakeOpen3dPeer(const std::vector<PeerModel>& models, const PeerOptions& options,
                                                const std::string& python, const std::string& script,
                                                std::string* problem) {
  if (RunShellCommand(ShellQuoted(python) + " -c 'import open3d' > /dev/null 2>&1") != 0) {
    *problem = "Open3D cannot be imported by " + python + " (install: apt-get install -y python3-open3d); skipped";
    return nullptr;
  }
  return std::make_unique<Open3dPeer>(models, options, python, script);
}

}  // namespace ecv::bench
