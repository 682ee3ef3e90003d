// colorcal_bench: the colour-matrix fit (issue 8). (1) Synthetic: how often each method recovers a known A within
// 0.08 (Frobenius) from pairs with Gaussian noise 0.01 and a share of mislabelled pairs, and its time. (2) Real
// YCB-Video: the textured meshes rendered unlit at their ground-truth poses, pairs sampled where the render's depth
// agrees with the real depth within 1 cm; the mean colour error between rendered model and real object before and
// after A, with A fitted on other frames of the same video, on another video, or on other objects. (3) --effect: the
// 10 hand-labelled pairs per model (bench/colorcal_pairs/*.csv) checked against the ground truth, and what the matrices
// of each fit variant (hand pairs / automatic pairs of one or three frames) do on held-out frames: the mean colour
// error, and the correspondence score of set (a) of discriminative_bench (library view nearest the ground truth vs
// the real frame) with the view's primitive colours mapped and the descriptors recomputed.
//
//   colorcal_bench [--trials N] [--data DIR] [--results FILE] [--no-report] [--effect] [--library-distance M]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "colorcal/color_pairs.h"
#include "colorcal/pairs_csv.h"
#include "core/error.h"
#include "core/timing.h"
#include "discriminative_data.h"
#include "ecv/matching.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "render/renderer.h"

namespace {

using ecv::Clock;
using ecv::MillisecondsSince;
using ecv::bench::Fixed;

const char* const kVideos[] = {"0000", "0001", "0002"};
const int kFrames[] = {1, 3, 5, 7, 9, 11, 13, 15, 17, 19};
// The fits compared: label and options.
std::vector<std::pair<std::string, ecv::ColorFitOptions>> Methods() {
  std::vector<std::pair<std::string, ecv::ColorFitOptions>> methods;
  for (ecv::ColorFitMethod method : {ecv::ColorFitMethod::kLeastSquares, ecv::ColorFitMethod::kTukeyIrls}) {
    ecv::ColorFitOptions options;
    options.method = method;
    methods.emplace_back(ecv::ToString(method), options);
  }
  for (double threshold : {0.06, 0.1, 0.15}) {
    ecv::ColorFitOptions options;
    options.inlier_threshold = threshold;
    methods.emplace_back("RANSAC + IRLS " + Fixed(threshold, 2), options);
  }
  ecv::ColorFitOptions unpolished;
  unpolished.polish = false;
  methods.emplace_back("RANSAC (no IRLS) 0.10", unpolished);
  return methods;
}

struct Settings {
  int trials = 200;
  std::string data = ECV_DATA_DIR;
  std::string results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  bool report = true;
  bool effect = false;              // (3) instead of (1) and (2)
  double library_distance_m = 0.9;  // (3): library views at this distance, as scripts/build_ycbv_library --distance
};

// The textured meshes of the frames, in the YCB-Video object frame: the google16k meshes moved by the table, and the
// YCB-Video banana (already in that frame).
std::map<std::string, ecv::MeshId> AddMeshes(const std::string& data, ecv::Renderer& renderer) {
  std::map<std::string, ecv::MeshId> meshes;
  for (const auto& [object, object_from_mesh] :
       ecv::ReadTransformTable(data + "/ycbv_subset/derived/google16k_to_ycbv.txt")) {
    ecv::MeshLoadOptions options;
    options.object_from_mesh = object_from_mesh;
    meshes[object] = renderer.AddMesh(
        ecv::LoadMesh(data + "/ycbv_subset/ycb_google16k_textured/" + object + "_textured.obj", options));
  }
  meshes["011_banana"] = renderer.AddMesh(ecv::LoadMesh(data + "/ycbv_subset/models/011_banana/textured_simple.obj"));
  return meshes;
}

std::string FramePrefix(const std::string& data, const std::string& video, int frame) {
  return data + "/ycbv_subset/Example-Scenes/" + video + "/" + std::to_string(1000000 + frame).substr(1);
}

// ---- (1) synthetic ----

Eigen::Matrix3d KnownMatrix() {
  Eigen::Matrix3d A;
  A << 0.92, 0.08, -0.03, 0.05, 0.81, 0.07, -0.04, 0.12, 1.10;
  return A;
}

// `count` pairs, model colours uniform in [0.05, 0.95]^3, scene = A model + N(0, 0.01^2); a share `outliers` of them
// mislabelled (scene colour of another pair).
std::vector<ecv::ColorPair> SyntheticPairs(int count, double outliers, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(0.05, 0.95);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<ecv::ColorPair> pairs(count);
  for (ecv::ColorPair& pair : pairs) {
    pair.model = {uniform(random), uniform(random), uniform(random)};
    pair.scene = KnownMatrix() * pair.model + Eigen::Vector3d(noise(random), noise(random), noise(random));
  }
  const int wrong = static_cast<int>(outliers * count + 0.5);  // the first `wrong` pairs
  for (int i = 0; i < wrong; ++i) pairs[i].scene = pairs[(i + wrong) % count].scene;
  return pairs;
}

std::string SyntheticTable(const Settings& settings) {
  std::ostringstream table;
  table << "Known A, Gaussian noise 0.01 on the scene colours, mislabelled pairs = scene colour of another pair; "
        << settings.trials
        << " seeded trials per cell: % of fits within 0.08 (Frobenius) / median error / median ms per fit.\n\n"
        << "Reference: least squares on the correctly labelled pairs only (the best a robust fit can do).\n\n"
        << "| pairs | mislabelled | reference |";
  for (const auto& [label, options] : Methods()) table << ' ' << label << " |";
  table << "\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (int count : {10, 100, 2000}) {
    for (double outliers : {0.0, 0.2, 0.4}) {
      table << "| " << count << " | " << int(outliers * 100) << " % |";
      for (int method = -1; method < int(Methods().size()); ++method) {
        ecv::ColorFitOptions options = method < 0 ? ecv::ColorFitOptions() : Methods()[method].second;
        if (method < 0) options.method = ecv::ColorFitMethod::kLeastSquares;
        int good = 0;
        std::vector<double> errors, times;
        for (int trial = 0; trial < settings.trials; ++trial) {
          std::vector<ecv::ColorPair> pairs = SyntheticPairs(count, outliers, 1000 * count + trial);
          if (method < 0) pairs.erase(pairs.begin(), pairs.begin() + static_cast<int>(outliers * count + 0.5));
          const auto start = Clock::now();
          try {
            const ecv::ColorFit fit = ecv::FitColorMatrix(pairs, options);
            errors.push_back((fit.A - KnownMatrix()).norm());
          } catch (const ecv::InputError&) {  // fewer than 3 inliers: a failure
            errors.push_back(std::numeric_limits<double>::infinity());
          }
          times.push_back(MillisecondsSince(start));
          good += errors.back() < 0.08;
        }
        table << ' ' << Fixed(100.0 * good / settings.trials, 0) << " % / " << Fixed(ecv::bench::Median(errors), 3)
              << " / " << Fixed(ecv::bench::Median(times), 3) << " ms |";
      }
      table << '\n';
    }
  }
  return table.str();
}

// ---- (2) real ----

// Pairs of one object in one frame: `fit` sampled for fitting (default PosePairOptions), `all` every pixel where the
// render lies on the object, `usable` those of them that are neither dark nor saturated (what the fit may use).
struct FramePairs {
  std::string object, video;
  int frame = 0;
  std::vector<ecv::ColorPair> fit, all, usable;
};
enum class Which { kFit, kAll, kUsable };

std::vector<FramePairs> CollectRealPairs(const Settings& settings) {
  ecv::Renderer renderer;
  std::map<std::string, ecv::MeshId> meshes = AddMeshes(settings.data, renderer);
  ecv::PosePairOptions usable;
  usable.max_pairs = 0, usable.window_radius_px = 0;
  ecv::PosePairOptions every_pixel = usable;
  every_pixel.min_value = 0.0, every_pixel.max_value = 1.0;
  std::vector<FramePairs> result;
  for (const char* video : kVideos) {
    for (int frame_id : kFrames) {
      const ecv::LoadedFrame frame = ecv::LoadYcbvFrame(FramePrefix(settings.data, video, frame_id));
      for (const ecv::GroundTruth& truth : frame.ground_truth) {
        if (!meshes.count(truth.object_name)) continue;
        const ecv::RenderResult render =
            renderer.Render(meshes[truth.object_name], frame.rgbd.camera, truth.camera_from_object);
        const cv::Mat mask = ecv::DepthAgreementMask(render.depth, frame.rgbd.depth, 0.01);
        ecv::PosePairOptions sampled;
        sampled.seed = static_cast<uint64_t>(frame_id);
        result.push_back({truth.object_name, video, frame_id,
                          ecv::ColorPairsFromPose(render.color, frame.rgbd.color, mask, sampled).pairs,
                          ecv::ColorPairsFromPose(render.color, frame.rgbd.color, mask, every_pixel).pairs,
                          ecv::ColorPairsFromPose(render.color, frame.rgbd.color, mask, usable).pairs});
      }
    }
  }
  return result;
}

// Frames 1, 5, 9, 13, 17 fit within a video; 3, 7, 11, 15, 19 are the test frames of every comparison.
bool TestFrame(int frame) {
  return frame % 4 == 3;
}

using Selector = bool (*)(const FramePairs&, const std::string& object, const std::string& video);

std::vector<ecv::ColorPair> Gather(const std::vector<FramePairs>& frames, const std::string& object,
                                   const std::string& video, Selector select, Which which = Which::kFit) {
  std::vector<ecv::ColorPair> pairs;
  for (const FramePairs& frame : frames) {
    if (!select(frame, object, video)) continue;
    const std::vector<ecv::ColorPair>& add = which == Which::kFit   ? frame.fit
                                             : which == Which::kAll ? frame.all
                                                                    : frame.usable;
    pairs.insert(pairs.end(), add.begin(), add.end());
  }
  return pairs;
}

bool InTestFrames(const FramePairs& f, const std::string& o, const std::string& v) {
  return f.object == o && f.video == v && TestFrame(f.frame);
}
bool SameVideoOtherFrames(const FramePairs& f, const std::string& o, const std::string& v) {
  return f.object == o && f.video == v && !TestFrame(f.frame);
}
bool OtherVideoSameObject(const FramePairs& f, const std::string& o, const std::string& v) {
  return f.object == o && f.video != v;
}
bool OtherVideosOtherObjects(const FramePairs& f, const std::string& o, const std::string& v) {
  return f.object != o && f.video != v;
}

// The test pixels of one object in one video: all of them, and the usable ones.
struct TestPixels {
  std::vector<ecv::ColorPair> all, usable;
  std::string Error(const Eigen::Matrix3d& A) const {
    return Fixed(ecv::MeanColorError(all, A), 3) + " / " + Fixed(ecv::MeanColorError(usable, A), 3);
  }
};

// "all / usable" mean errors after the matrix fitted on `fit_pairs`; "—" when there are none, "refused" on an error.
std::string After(const std::vector<ecv::ColorPair>& fit_pairs, const TestPixels& test,
                  const ecv::ColorFitOptions& options, std::string* note = nullptr) {
  if (fit_pairs.empty()) return "—";
  try {
    const ecv::ColorFit fit = ecv::FitColorMatrix(fit_pairs, options);
    if (note) *note = Fixed(fit.condition_number, 1) + " / " + Fixed(100.0 * fit.num_inliers / fit_pairs.size(), 0);
    return test.Error(fit.A);
  } catch (const ecv::InputError& error) {
    std::cerr << error.what() << '\n';
    return "refused";
  }
}

TestPixels Test(const std::vector<FramePairs>& frames, const std::string& object, const std::string& video) {
  return {Gather(frames, object, video, InTestFrames, Which::kAll),
          Gather(frames, object, video, InTestFrames, Which::kUsable)};
}

std::string RealTable(const std::vector<FramePairs>& frames) {
  std::map<std::pair<std::string, std::string>, int> seen;  // (object, video) -> frames
  for (const FramePairs& frame : frames) ++seen[{frame.object, frame.video}];
  std::ostringstream table;
  table << "Mean colour error |rendered - real| (RGB in [0, 1], Euclidean) over the test pixels where the render's "
           "depth agrees with the real depth within 1 cm (test frames 3, 7, 11, 15, 19 of each video), as \"all "
           "pixels / usable pixels\" (usable: neither image saturated (> 0.98) nor dark, as for fitting), before and "
           "after A (default fit: RANSAC + IRLS 0.10, on automatic pairs, 2000 per frame). A fitted on: the same "
           "object in "
           "frames 1, 5, 9, 13, 17 of the same video; the same object in another video; the other objects of the "
           "other videos (one matrix for the camera). cond / inl = condition number and inlier % of the same-video "
           "fit.\n\n"
           "| object | video | test pixels (usable) | before | same video | other video | other objects, other videos "
           "| cond / inl % |\n|---|---|---:|---:|---:|---:|---:|---:|\n";
  const ecv::ColorFitOptions options;
  for (const auto& [key, count] : seen) {
    const auto& [object, video] = key;
    const TestPixels test = Test(frames, object, video);
    std::string note;
    const std::string same = After(Gather(frames, object, video, SameVideoOtherFrames), test, options, &note);
    table << "| " << object << " | " << video << " | " << test.all.size() << " (" << test.usable.size() << ") | "
          << test.Error(Eigen::Matrix3d::Identity()) << " | " << same << " | "
          << After(Gather(frames, object, video, OtherVideoSameObject), test, options) << " | "
          << After(Gather(frames, object, video, OtherVideosOtherObjects), test, options) << " | " << note << " |\n";
  }
  return table.str();
}

// The methods on the transfers that matter: the same object from another video, and the camera matrix.
std::string MethodTable(const std::vector<FramePairs>& frames) {
  std::ostringstream table;
  table << "\nFit methods on the real transfers (mean colour error on all / usable test pixels after A; before: A = I; "
           "time of the fit):\n\n"
        << "| A for | from | before |";
  for (const auto& [label, options] : Methods()) table << ' ' << label << " |";
  table << "\n|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  const struct {
    std::string object, video, from;
    Selector select;
  } cases[] = {{"006_mustard_bottle", "0002", "006 in 0001", OtherVideoSameObject},
               {"006_mustard_bottle", "0001", "006 in 0002", OtherVideoSameObject},
               {"006_mustard_bottle", "0002", "003, 004, 009 in 0000, 0001", OtherVideosOtherObjects},
               {"010_potted_meat_can", "0002", "all of 0000, 0001", OtherVideosOtherObjects},
               {"009_gelatin_box", "0000", "all but 009 of 0001, 0002", OtherVideosOtherObjects},
               {"003_cracker_box", "0001", "009, 010 of 0000, 0002", OtherVideosOtherObjects}};
  for (const auto& c : cases) {
    const TestPixels test = Test(frames, c.object, c.video);
    const std::vector<ecv::ColorPair> fit = Gather(frames, c.object, c.video, c.select);
    table << "| " << c.object << " in " << c.video << " | " << c.from << " | "
          << test.Error(Eigen::Matrix3d::Identity()) << " |";
    for (const auto& [label, options] : Methods()) {
      const auto start = Clock::now();
      const std::string after = After(fit, test, options);
      table << ' ' << after << " (" << Fixed(MillisecondsSince(start), 0) << " ms) |";
    }
    table << '\n';
  }
  return table.str();
}

// ---- (3) the effect of calibration: hand pairs against the ground truth; colour error and correspondence score ----

const char* const kCalibrated[] = {"003_cracker_box", "004_sugar_box",       "006_mustard_bottle",
                                   "009_gelatin_box", "010_potted_meat_can", "011_banana"};
const int kAutoFrames[] = {1, 3, 5};  // of the labelled video; the hand pairs are of frame 1
bool HeldOut(int frame) {
  return frame >= 7;  // colour errors: frames 7-19 of every video; scores: set (a)'s frames 7, 13, 19
}

// One model's hand-labelled pairs, the frame they were labelled on, and how far each picked scene pixel lies from the
// ground-truth projection of the model pixel's surface point (the model view re-rendered at the pose in the CSV).
struct HandPairs {
  std::string object, video;
  int frame = 0;
  std::vector<ecv::ColorPair> pairs;
  std::vector<double> offsets_px;  // infinity: no surface under the model pixel
};

// "# key: value" comment lines of a pairs CSV.
std::map<std::string, std::vector<double>> CsvNotes(const std::string& path, std::string* scene_frame) {
  std::ifstream file(path);
  std::map<std::string, std::vector<double>> notes;
  for (std::string line; std::getline(file, line);) {
    const size_t colon = line.find(':');
    if (line.rfind("# ", 0) != 0 || colon == std::string::npos) continue;
    const std::string key = line.substr(2, colon - 2);
    if (key == "scene_frame") *scene_frame = line.substr(colon + 2);
    std::istringstream values(line.substr(colon + 1));
    for (double value; values >> value;) notes[key].push_back(value);
  }
  for (const char* key : {"camera", "model_view_camera_from_object", "model_crop_origin", "scene_crop_origin"}) {
    if (notes[key].empty()) throw ecv::InputError(path + ": no comment line \"# " + key + ": ...\"");
  }
  return notes;
}

HandPairs ReadHandPairs(const std::string& data, const std::string& object, ecv::Renderer& renderer, ecv::MeshId mesh) {
  const std::string path = std::string(ECV_SOURCE_DIR) + "/bench/colorcal_pairs/" + object + ".csv";
  std::string scene_frame;
  auto notes = CsvNotes(path, &scene_frame);
  HandPairs hand{object, scene_frame.substr(0, 4), std::stoi(scene_frame.substr(5)), ecv::ReadColorPairsCsv(path), {}};
  const std::vector<double>& k = notes["camera"];
  const ecv::PinholeCamera camera{k[0], k[1], k[2], k[3], 640, 480};
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 12; ++i) camera_from_object.matrix()(i / 4, i % 4) = notes["model_view_camera_from_object"][i];
  const cv::Mat depth = renderer.Render(mesh, camera, camera_from_object).depth;
  const ecv::LoadedFrame frame = ecv::LoadYcbvFrame(FramePrefix(data, hand.video, hand.frame));
  Eigen::Isometry3d scene_from_object = Eigen::Isometry3d::Identity();
  for (const ecv::GroundTruth& truth : frame.ground_truth) {
    if (truth.object_name == object) scene_from_object = truth.camera_from_object;
  }
  for (const ecv::PixelPair& pair : ecv::ReadPixelPairsCsv(path)) {
    const Eigen::Vector2d model(pair.model_pixel.x + notes["model_crop_origin"][0],
                                pair.model_pixel.y + notes["model_crop_origin"][1]);
    const Eigen::Vector2d scene(pair.scene_pixel.x + notes["scene_crop_origin"][0],
                                pair.scene_pixel.y + notes["scene_crop_origin"][1]);
    const float z = depth.at<float>(static_cast<int>(model.y()), static_cast<int>(model.x()));
    const Eigen::Vector3d point = scene_from_object * camera_from_object.inverse() * camera.BackProject(model, z);
    hand.offsets_px.push_back(z > 0.0F ? (frame.rgbd.camera.Project(point) - scene).norm()
                                       : std::numeric_limits<double>::infinity());
  }
  return hand;
}

// Automatic pairs of `object` in one frame, as `ecvpose colorcal auto` samples them (ground-truth pose, unlit render,
// depth agreement within 1 cm, default PosePairOptions).
std::vector<ecv::ColorPair> AutoPairs(const std::string& data, const std::string& object, const std::string& video,
                                      int frame_id, ecv::Renderer& renderer, ecv::MeshId mesh) {
  const ecv::LoadedFrame frame = ecv::LoadYcbvFrame(FramePrefix(data, video, frame_id));
  for (const ecv::GroundTruth& truth : frame.ground_truth) {
    if (truth.object_name != object) continue;
    const ecv::RenderResult render = renderer.Render(mesh, frame.rgbd.camera, truth.camera_from_object);
    const cv::Mat mask = ecv::DepthAgreementMask(render.depth, frame.rgbd.depth, 0.01);
    return ecv::ColorPairsFromPose(render.color, frame.rgbd.color, mask).pairs;
  }
  return {};
}

// The fits compared: label and options (RANSAC + IRLS unless said).
std::vector<std::pair<std::string, ecv::ColorFitOptions>> FitVariants() {
  std::vector<std::pair<std::string, ecv::ColorFitOptions>> variants;
  auto add = [&](const std::string& label, ecv::ColorFitMethod method, ecv::ColorMatrixForm form, bool keep) {
    ecv::ColorFitOptions options;
    options.method = method, options.form = form, options.keep_brightness = keep;
    variants.emplace_back(label, options);
  };
  using M = ecv::ColorFitMethod;
  using F = ecv::ColorMatrixForm;
  add("full lsq", M::kLeastSquares, F::kFull, false);
  add("full", M::kRansac, F::kFull, false);
  add("diag", M::kRansac, F::kDiagonal, false);
  add("auto form", M::kRansac, F::kAuto, false);
  add("full keep-bright", M::kRansac, F::kFull, true);
  add("diag keep-bright", M::kRansac, F::kDiagonal, true);
  add("auto form keep-bright", M::kRansac, F::kAuto, true);
  for (F form : {F::kFull, F::kDiagonal, F::kAuto}) {
    add(std::string(form == F::kFull       ? "full"
                    : form == F::kDiagonal ? "diag"
                                           : "auto form") +
            " offset",
        M::kRansac, form, false);
    variants.back().second.fit_offset = true;
  }
  return variants;
}

// The matrices of one model: "none", then "<source> <variant>" for the sources hand, auto 1 fr, auto 3 fr.
struct ModelMatrices {
  std::vector<std::string> labels;
  std::vector<std::optional<Eigen::Matrix3d>> matrices;  // nullopt: the fit was refused
  std::vector<Eigen::Vector3d> offsets;                  // fit_offset: b (for the colour errors only; 0 otherwise)
  std::vector<std::string> notes;                        // diagonal of A, form, inliers
};

ModelMatrices FitMatrices(const HandPairs& hand, const std::vector<ecv::ColorPair>& auto_one,
                          const std::vector<ecv::ColorPair>& auto_three) {
  // Diagnostic rows: a plain scalar gain below and above 1 (the colour differences shrink or grow, nothing else).
  ModelMatrices result{
      {"none", "scalar 0.8 (diagnostic)", "scalar 1.2 (diagnostic)"},
      {Eigen::Matrix3d::Identity(), 0.8 * Eigen::Matrix3d::Identity(), 1.2 * Eigen::Matrix3d::Identity()},
      {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()},
      {"", "", ""}};
  for (const auto& [source, pairs] : {std::pair<std::string, const std::vector<ecv::ColorPair>*>("hand", &hand.pairs),
                                      {"auto 1 fr", &auto_one},
                                      {"auto 3 fr", &auto_three}}) {
    for (const auto& [label, options] : FitVariants()) {
      result.labels.push_back(source + " " + label);
      try {
        const ecv::ColorFit fit = ecv::FitColorMatrix(*pairs, options);
        result.matrices.push_back(fit.A);
        result.offsets.push_back(fit.offset);
        result.notes.push_back(Fixed(fit.A(0, 0), 2) + " " + Fixed(fit.A(1, 1), 2) + " " + Fixed(fit.A(2, 2), 2) +
                               ", " + ecv::ToString(fit.form) + ", " + std::to_string(fit.num_inliers) + "/" +
                               std::to_string(pairs->size()) + ", cond " + Fixed(fit.condition_number, 0));
      } catch (const ecv::InputError& error) {
        result.matrices.push_back(std::nullopt);
        result.offsets.push_back(Eigen::Vector3d::Zero());
        result.notes.push_back(std::string("refused: ") + error.what());
      }
    }
  }
  return result;
}

// ECV correspondence score of one set-(a) pair with the query (library view) colours mapped by A (the primitives of
// both views extracted once; the query's descriptors recomputed from the mapped primitives, as the recognizer does).
double MappedScore(const ecv::bench::ViewPair& pair, const std::vector<ecv::Primitive>& query,
                   const std::vector<ecv::Primitive>& train, const ecv::Descriptors& train_descriptors,
                   const Eigen::Matrix3d& A) {
  std::vector<ecv::Primitive> mapped = query;
  ecv::ApplyColorMatrix(A, &mapped);
  const ecv::Descriptors descriptors = ecv::ComputeDescriptors(mapped);
  if (descriptors.primitive.empty() || train_descriptors.primitive.empty()) return 0.0;
  const ecv::DescriptorMatcher matcher(train, train_descriptors);
  return ecv::ScoreCorrespondences(mapped, train, matcher.Match(mapped, descriptors), pair.TrainFromQuery(), 0.01)
      .Score();
}

// Mean |c_b - c_a| (RGB mean, [0, 1]) over the primitive pairs within the descriptor's radius (0.025 m): the colour
// differences the context descriptor histograms.
double MeanColourDifference(const std::vector<ecv::Primitive>& primitives, const Eigen::Matrix3d& A) {
  std::vector<ecv::Primitive> mapped = primitives;
  ecv::ApplyColorMatrix(A, &mapped);
  double sum = 0.0;
  long count = 0;
  for (size_t a = 0; a < mapped.size(); ++a) {
    for (size_t b = a + 1; b < mapped.size(); ++b) {
      if ((mapped[a].position - mapped[b].position).squaredNorm() > 0.025F * 0.025F) continue;
      sum += (mapped[b].color - mapped[a].color).cwiseAbs().mean();
      ++count;
    }
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

// Table of per-model values (rows: matrices; columns: models; last column: the mean over the models with a value).
std::string EffectTable(const std::string& what, const std::vector<std::string>& objects,
                        const std::vector<std::string>& labels, const std::vector<std::vector<double>>& values,
                        int decimals) {
  std::ostringstream table;
  table << "| " << what << " |";
  for (const std::string& object : objects) table << ' ' << object.substr(0, 3) << " |";
  table << " mean |\n|---|";
  for (size_t i = 0; i <= objects.size(); ++i) table << "---:|";
  table << '\n';
  for (size_t row = 0; row < labels.size(); ++row) {
    table << "| " << labels[row] << " |";
    double sum = 0.0;
    int count = 0;
    for (size_t col = 0; col < objects.size(); ++col) {
      const double value = values[col][row];
      table << ' ' << (std::isnan(value) ? std::string("—") : Fixed(value, decimals)) << " |";
      if (!std::isnan(value)) sum += value, ++count;
    }
    table << ' ' << (count > 0 ? Fixed(sum / count, decimals) : "—") << " |\n";
  }
  return table.str();
}

std::string HandPairsTable(const std::vector<HandPairs>& hands) {
  std::ostringstream table;
  table << "| model | labelled on | offset of each picked scene pixel from the true projection, px | median | max |\n"
           "|---|---|---|---:|---:|\n";
  for (const HandPairs& hand : hands) {
    std::vector<double> offsets = hand.offsets_px;
    table << "| " << hand.object << " | " << hand.video << "/" << hand.frame << " |";
    for (const double offset : offsets) table << ' ' << Fixed(offset, 1);
    table << " | " << Fixed(ecv::bench::Median(offsets), 1) << " | "
          << Fixed(*std::max_element(offsets.begin(), offsets.end()), 1) << " |\n";
  }
  return table.str();
}

// Mean colour error on every pixel where the render at the ground truth lies on the object (depth within 1 cm) in the
// held-out frames of every video, per matrix (refused fits: identity, as the model then stays uncalibrated).
std::vector<double> HeldOutColourErrors(const std::string& data, const std::string& object,
                                        const ModelMatrices& matrices, ecv::Renderer& renderer, ecv::MeshId mesh) {
  ecv::PosePairOptions every_pixel;
  every_pixel.max_pairs = 0, every_pixel.window_radius_px = 0, every_pixel.min_value = 0.0, every_pixel.max_value = 1.0;
  std::vector<ecv::ColorPair> pixels;
  for (const char* video : kVideos) {
    for (const int frame_id : kFrames) {
      if (!HeldOut(frame_id)) continue;
      const ecv::LoadedFrame frame = ecv::LoadYcbvFrame(FramePrefix(data, video, frame_id));
      for (const ecv::GroundTruth& truth : frame.ground_truth) {
        if (truth.object_name != object) continue;
        const ecv::RenderResult render = renderer.Render(mesh, frame.rgbd.camera, truth.camera_from_object);
        const cv::Mat mask = ecv::DepthAgreementMask(render.depth, frame.rgbd.depth, 0.01);
        const auto add = ecv::ColorPairsFromPose(render.color, frame.rgbd.color, mask, every_pixel).pairs;
        pixels.insert(pixels.end(), add.begin(), add.end());
      }
    }
  }
  std::vector<double> errors;
  for (size_t m = 0; m < matrices.matrices.size(); ++m) {
    const Eigen::Matrix3d A = matrices.matrices[m].value_or(Eigen::Matrix3d::Identity());
    double sum = 0.0;
    for (const ecv::ColorPair& pixel : pixels) {
      sum += ((A * pixel.model + matrices.offsets[m]).cwiseMax(0.0).cwiseMin(1.0) - pixel.scene).norm();
    }
    errors.push_back(pixels.empty() ? 0.0 : sum / static_cast<double>(pixels.size()));
  }
  return errors;
}

// Mean ECV correspondence score (%) per matrix over the held-out pairs of set (a) of `object`; NaN when it has none.
std::vector<double> HeldOutScores(const std::vector<ecv::bench::ViewPair>& view_pairs, const std::string& object,
                                  const ModelMatrices& matrices, std::vector<double>* differences,
                                  std::vector<double>* grey_scores) {
  std::vector<double> sums(matrices.matrices.size(), 0.0);
  *grey_scores = std::vector<double>(matrices.matrices.size(), 0.0);      // per matrix: BrightnessPreserving(A) applied
  *differences = std::vector<double>(matrices.matrices.size() + 1, 0.0);  // per matrix (query mapped), then the real
  int count = 0;
  for (const ecv::bench::ViewPair& pair : view_pairs) {
    const size_t slash = pair.train.name.find('/');
    if (pair.set != "recognition" || pair.object != object || !HeldOut(std::stoi(pair.train.name.substr(slash + 1)))) {
      continue;
    }
    const auto query = ecv::ExtractPrimitives(pair.query.rgbd, {}, pair.query.mask).primitives;
    const auto train = ecv::ExtractPrimitives(pair.train.rgbd, {}, pair.train.mask).primitives;
    const ecv::Descriptors train_descriptors = ecv::ComputeDescriptors(train);
    for (size_t m = 0; m < sums.size(); ++m) {
      const Eigen::Matrix3d A = matrices.matrices[m].value_or(Eigen::Matrix3d::Identity());
      sums[m] += MappedScore(pair, query, train, train_descriptors, A);
      (*differences)[m] += MeanColourDifference(query, A);
      (*grey_scores)[m] += MappedScore(pair, query, train, train_descriptors, ecv::BrightnessPreserving(A));
    }
    differences->back() += MeanColourDifference(train, Eigen::Matrix3d::Identity());
    ++count;
    std::cerr << '.' << std::flush;
  }
  for (double& sum : sums) sum = count > 0 ? 100.0 * sum / count : std::numeric_limits<double>::quiet_NaN();
  for (double& sum : *differences) sum = count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
  for (double& sum : *grey_scores) {
    sum = count > 0 ? 100.0 * sum / count : std::numeric_limits<double>::quiet_NaN();
  }
  return sums;
}

std::string EffectReport(const Settings& settings) {
  ecv::Renderer renderer;
  const std::map<std::string, ecv::MeshId> meshes = AddMeshes(settings.data, renderer);
  const std::vector<std::string> objects(std::begin(kCalibrated), std::end(kCalibrated));
  std::vector<HandPairs> hands;
  std::vector<ModelMatrices> matrices;
  for (const std::string& object : objects) {
    const ecv::MeshId mesh = meshes.at(object);
    hands.push_back(ReadHandPairs(settings.data, object, renderer, mesh));
    std::vector<ecv::ColorPair> auto_one, auto_three;
    for (const int frame : kAutoFrames) {
      const auto pairs = AutoPairs(settings.data, object, hands.back().video, frame, renderer, mesh);
      if (frame == kAutoFrames[0]) auto_one = pairs;
      auto_three.insert(auto_three.end(), pairs.begin(), pairs.end());
    }
    matrices.push_back(FitMatrices(hands.back(), auto_one, auto_three));
  }
  std::vector<std::vector<double>> errors, scores, differences, grey_scores;
  for (size_t i = 0; i < objects.size(); ++i) {
    errors.push_back(HeldOutColourErrors(settings.data, objects[i], matrices[i], renderer, meshes.at(objects[i])));
  }
  std::cerr << "rendering and extracting the view pairs of set (a)";
  const auto view_pairs = ecv::bench::LoadViewPairs(settings.data, settings.library_distance_m);
  for (size_t i = 0; i < objects.size(); ++i) {
    differences.emplace_back();
    grey_scores.emplace_back();
    scores.push_back(HeldOutScores(view_pairs, objects[i], matrices[i], &differences.back(), &grey_scores.back()));
  }
  std::vector<std::string> difference_labels = matrices[0].labels;
  difference_labels.push_back("**real frame**");
  std::cerr << '\n';

  std::ostringstream out;
  out << "#### Hand-labelled pairs (bench/colorcal_pairs/*.csv) against the ground truth\n\n"
      << HandPairsTable(hands)
      << "\nFits: the hand pairs (10, frame 1 of the labelled video), automatic pairs of that frame (\"auto 1 fr\", "
         "2000) and of frames 1, 3, 5 (\"auto 3 fr\", pooled); variants: least squares or RANSAC + IRLS (default "
         "0.10), full 3x3 or diagonal (per-channel gains) or auto form (diagonal above condition number 30), "
         "optionally scaled to keep the brightness, or fitted with an offset (c_scene = A c_model + b: A is the slope, "
         "stored and applied alone; the colour errors use b). A refused fit (fewer than 3 inliers, ill-conditioned) "
         "leaves the "
         "model uncalibrated: identity in the tables.\n\n"
      << "#### (a) Mean colour error |A rendered - real| on held-out frames (7-19 of every video), all pixels where "
         "the render at the ground truth lies on the object\n\n"
      << EffectTable("matrix", objects, matrices[0].labels, errors, 3)
      << "\n#### (b) Correspondence score (%) of set (a), held-out frames 7, 13, 19: library view nearest the ground "
         "truth (views at "
      << Fixed(settings.library_distance_m, 2)
      << " m) vs the real frame, the view's primitive colours mapped by A, descriptors recomputed (banana: not in "
         "set (a))\n\n"
      << EffectTable("matrix", objects, matrices[0].labels, scores, 1)
      << "\n#### (b') The same with each A scaled to keep grey's brightness before mapping (BrightnessPreserving: "
         "channel sum of A (1, 1, 1) = 3), as the recognizer could apply a stored matrix for matching\n\n"
      << EffectTable("matrix", objects, matrices[0].labels, grey_scores, 1)
      << "\n#### Why: mean colour difference |c_b - c_a| (RGB mean) between primitives within 2.5 cm, the quantity the "
         "descriptor's colour histograms bin: the library view mapped by each A, and the real frame (same pairs as "
         "(b))\n\n"
      << EffectTable("matrix", objects, difference_labels, differences, 3)
      << "\n#### The matrices: diagonal of A, form, inliers, condition number\n\n| matrix |";
  for (const std::string& object : objects) out << ' ' << object << " |";
  out << "\n|---|";
  for (size_t i = 0; i < objects.size(); ++i) out << "---|";
  out << '\n';
  for (size_t row = 3; row < matrices[0].labels.size(); ++row) {
    out << "| " << matrices[0].labels[row] << " |";
    for (const ModelMatrices& m : matrices) out << ' ' << m.notes[row].substr(0, 90) << " |";
    out << '\n';
  }
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  Settings settings;
  CLI::App app{
      "colorcal_bench: the colour-matrix fit, on synthetic pairs and real YCB-Video frames; with --effect, "
      "the hand-labelled pairs and the fitted matrices' effect on colour errors and matching.",
      "colorcal_bench"};
  app.add_option("--trials", settings.trials, "Seeded synthetic fits per cell (pair count, mislabelled share, method)")
      ->capture_default_str();
  app.add_option("--data", settings.data, "Data directory (with ycbv_subset)")->capture_default_str();
  app.add_option("--results", settings.results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.add_flag_callback(
      "--no-report", [&settings] { settings.report = false; }, "Print the tables only: write nothing to --results");
  app.add_flag("--effect", settings.effect,
               "Instead of the synthetic and real fits: the hand-labelled pairs and the fitted matrices' effect on "
               "held-out frames");
  app.add_option("--library-distance", settings.library_distance_m,
                 "With --effect: distance in metres of the library views matched against the frames")
      ->capture_default_str();
  if (const auto exit_code = ecv::bench::ParseCommandLine(app, argc, argv)) return *exit_code;
  try {
    if (settings.effect) {
      const std::string markdown = EffectReport(settings);
      std::cout << markdown;
      if (settings.report) {
        ecv::bench::ReportSection(settings.results,
                                  "Colour calibration: hand pairs and the effect on matching (colorcal_bench)",
                                  ecv::bench::CommandLine(argc, argv), markdown);
      }
      return 0;
    }
    std::string markdown =
        "Defaults taken from these tables: RANSAC + IRLS (the Tukey polish), inlier threshold 0.10, condition-number "
        "limit 1000 (automatic pairs of one object reach 770).\n\n### Synthetic pairs\n\n" +
        SyntheticTable(settings);
    std::cout << markdown << std::flush;
    const std::vector<FramePairs> frames = CollectRealPairs(settings);
    const std::string real = "\n### Real YCB-Video frames\n\n" + RealTable(frames) + MethodTable(frames);
    std::cout << real;
    markdown += real;
    if (settings.report) {
      ecv::bench::ReportSection(settings.results, "Colour calibration (colorcal_bench)",
                                ecv::bench::CommandLine(argc, argv), markdown);
    }
  } catch (const ecv::InputError& error) {
    std::cerr << "colorcal_bench: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
