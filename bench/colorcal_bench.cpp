// colorcal_bench: the colour-matrix fit (issue 8). (1) Synthetic: how often each method recovers a known A within
// 0.08 (Frobenius) from pairs with Gaussian noise 0.01 and a share of mislabelled pairs, and its time. (2) Real
// YCB-Video: the textured meshes rendered unlit at their ground-truth poses, pairs sampled where the render's depth
// agrees with the real depth within 1 cm; the mean colour error between rendered model and real object before and
// after A, with A fitted on other frames of the same video, on another video, or on other objects.
//
//   colorcal_bench [--trials N] [--data DIR] [--results FILE] [--no-report]

#include <algorithm>
#include <cstring>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "colorcal/color_pairs.h"
#include "core/error.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "render/renderer.h"

namespace {

using ecv::bench::Clock;
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
};

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
          times.push_back(ecv::bench::MillisecondsSince(start));
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
  const auto table = ecv::ReadTransformTable(settings.data + "/ycbv_subset/derived/google16k_to_ycbv.txt");
  ecv::Renderer renderer;
  std::map<std::string, ecv::MeshId> meshes;
  for (const auto& [object, object_from_mesh] : table) {
    ecv::MeshLoadOptions options;
    options.object_from_mesh = object_from_mesh;
    meshes[object] = renderer.AddMesh(
        ecv::LoadMesh(settings.data + "/ycbv_subset/ycb_google16k_textured/" + object + "_textured.obj", options));
  }
  ecv::PosePairOptions usable;
  usable.max_pairs = 0, usable.window_radius_px = 0;
  ecv::PosePairOptions every_pixel = usable;
  every_pixel.min_value = 0.0, every_pixel.max_value = 1.0;
  std::vector<FramePairs> result;
  for (const char* video : kVideos) {
    for (int frame_id : kFrames) {
      const std::string prefix =
          settings.data + "/ycbv_subset/Example-Scenes/" + video + "/" + std::to_string(1000000 + frame_id).substr(1);
      const ecv::LoadedFrame frame = ecv::LoadYcbvFrame(prefix);
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
      table << ' ' << after << " (" << Fixed(ecv::bench::MillisecondsSince(start), 0) << " ms) |";
    }
    table << '\n';
  }
  return table.str();
}

}  // namespace

int main(int argc, char** argv) {
  Settings settings;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--trials" && i + 1 < argc) {
      settings.trials = std::stoi(argv[++i]);
    } else if (flag == "--data" && i + 1 < argc) {
      settings.data = argv[++i];
    } else if (flag == "--results" && i + 1 < argc) {
      settings.results = argv[++i];
    } else if (flag == "--no-report") {
      settings.report = false;
    } else {
      std::cerr << "usage: colorcal_bench [--trials N] [--data DIR] [--results FILE] [--no-report]\n";
      return 2;
    }
  }
  try {
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
      ecv::bench::Report(settings.results, "Colour calibration (colorcal_bench)", ecv::bench::CommandLine(argc, argv),
                         markdown);
    }
  } catch (const ecv::InputError& error) {
    std::cerr << "colorcal_bench: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
