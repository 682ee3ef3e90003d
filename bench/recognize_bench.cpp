// Recognition on real data: every YCB-Video frame under ../shared/data through the recognizer with a library
// of the textured YCB meshes, scored against the ground truth (recall at ADD < 0.1 d, false positives), with
// and without ICP, and the time per frame split by stage. With --peers, the same frames through PCL (FPFH +
// SampleConsensusPrerejective + ICP), OpenCV's PPF detector (+ ICP) and Open3D's FPFH + RANSAC + ICP recipe
// (bench/recognition_open3d.py under --python EXE, default /usr/bin/python3; skipped, saying so, without Open3D)
// in the same run; with --lmo-db, the Linemod-Occluded frame (8 vertex-coloured models) as its own table.
//
//   scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9
//   scripts/build_lmo_library /tmp/lmo.sqlite --views 40 --distance 1.0
//   recognize_bench --db /tmp/ycbv.sqlite [--db MORE.sqlite...] [--lmo-db /tmp/lmo.sqlite] [--peers] [--track]
//                   [--search-every N...] [--confirm-every N...] [--confirm-first N...] [--track-score S] [--seeds
//                   S...]
//                   [--threads N...] [--bytes] [--preselect N...] [--turned] [--casts] [--python EXE] [--figure F.jpg]
//                   [--results bench/RESULTS.md] [--frames N] [the settings flags of `ecvpose recognize`]
// Every setting of the recognizer's table (recognize/recognizer_settings.h) is a flag, as in `ecvpose recognize`,
// and applies to every run of ours, but those that add runs: --threads, --preselect, --hypotheses, --track,
// --search-every, --confirm-every and --confirm-first.
// --threads N (N > 1) adds a run of ours with N worker threads: the same detections (checked), its own times.
// --bytes adds a run of ours matching with ByteNeighbours (recognize --matcher bytes; needs AVX-512 VNNI).
// --preselect N adds a run of ours searching only the N models whose best views rank highest (recognize --preselect N).
// --turned adds a run of ours on the same frames turned 180 degrees (a camera held upside down; ground truth moved).
// --casts adds runs of ours on the same frames under changed light (white balance, gamma; ColorCasts below).
// --track adds a run with the previous frame's detections as priors; --search-every N (N > 1) one more where
// only every N-th frame of a video searches the models that are not tracked (recognize --search-every);
// --confirm-every N... adds tracking runs with each TrackingOptions::confirm_every for each of --seeds (and each
// --confirm-first, and with --casts under each light), and
// --track-score S sets the follow score of every tracking run (recognize --track-score).
// --db repeated runs every run of ours with each library in turn (the peers and --figure with the first): a block of
// rows per library in the recall table, a row per library in each time table with its ratio to the first library's.
// --figure F.jpg draws the detections of ours and each peer in frame 0001/000001 (the demo frame) side by side.
// --object-pixels also runs the peers on depth cut to the ground-truth objects' own pixels; --peers-only,
// --frame-step, --ppf-sampling, --ppf-scene-distance and --min-inlier-fraction are for tuning the peers.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "bench_util.h"
#include "core/byte_neighbours.h"
#include "core/timing.h"
#include "io/frame_io.h"
#include "recognition_peers.h"
#include "recognize/evaluation.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"
#include "recognize/settings_flags.h"

namespace ecv::bench {
namespace {

struct NamedFrame {
  std::string name;  // "0001/000001"
  LoadedFrame frame;
};

std::vector<NamedFrame> YcbvFrames(const std::string& data, int limit, int step) {
  std::vector<std::string> prefixes = YcbvFramePrefixes(data);
  std::vector<std::string> kept;
  for (size_t i = 0; i < prefixes.size(); i += static_cast<size_t>(std::max(step, 1))) kept.push_back(prefixes[i]);
  prefixes = kept;
  if (limit > 0 && static_cast<int>(prefixes.size()) > limit) prefixes.resize(static_cast<size_t>(limit));
  std::vector<NamedFrame> frames;
  for (const std::string& prefix : prefixes) {
    frames.push_back({std::filesystem::path(prefix).parent_path().filename().string() + "/" +
                          std::filesystem::path(prefix).filename().string(),
                      LoadYcbvFrame(prefix)});
  }
  return frames;
}

// The `frames` as the same camera held upside down sees them (TurnUpsideDown), with their ground truth moved
// along: recognition should not depend on the camera's roll about its optical axis.
std::vector<NamedFrame> TurnedFrames(const std::vector<NamedFrame>& frames) {
  std::vector<NamedFrame> turned;
  for (const NamedFrame& named : frames) {
    NamedFrame copy{named.name, {TurnUpsideDown(named.frame.rgbd), named.frame.ground_truth}};
    const cv::Size size = named.frame.rgbd.color.size();
    const auto turn_box = [&](const cv::Rect& box) {
      return box.empty()
                 ? box
                 : cv::Rect(size.width - box.x - box.width, size.height - box.y - box.height, box.width, box.height);
    };
    for (GroundTruth& truth : copy.frame.ground_truth) {
      truth.camera_from_object = TurnedFromCamera() * truth.camera_from_object;
      truth.object_box = turn_box(truth.object_box);
      truth.visible_box = turn_box(truth.visible_box);
    }
    turned.push_back(std::move(copy));
  }
  return turned;
}

// The light changes of --casts: white balance 15 % warmer and 15 % cooler, and gamma 0.8 and 1.25.
std::vector<std::pair<std::string, ColorCast>> ColorCasts() {
  ColorCast warm, cool, bright, dark;
  warm.rgb_gain = Eigen::Vector3d(1.15, 1.0, 0.85);
  cool.rgb_gain = Eigen::Vector3d(0.85, 1.0, 1.15);
  bright.gamma = 0.8;
  dark.gamma = 1.25;
  return {{"warm (R x1.15, B x0.85)", warm},
          {"cool (R x0.85, B x1.15)", cool},
          {"gamma 0.8", bright},
          {"gamma 1.25", dark}};
}

// The `frames` with their colours changed by `cast`.
std::vector<NamedFrame> CastFrames(const std::vector<NamedFrame>& frames, const ColorCast& cast) {
  std::vector<NamedFrame> changed;
  for (const NamedFrame& named : frames) {
    changed.push_back({named.name, {WithColorCast(named.frame.rgbd, cast), named.frame.ground_truth}});
  }
  return changed;
}

std::vector<NamedFrame> LmoFrames(const std::string& data) {
  return {{"lmo/000002/000003", LmoFrame(data)}};
}

struct Run {
  std::vector<FrameEvaluation> frames;
  std::vector<std::vector<Detection>> detections;       // per frame
  std::map<std::string, std::vector<double>> stage_ms;  // "total": the whole frame
};
using Runs = std::vector<std::pair<std::string, Run>>;  // in column order

void Log(const std::string& label, size_t i, size_t n, const FrameEvaluation& evaluation, double ms) {
  int correct = 0;
  for (const ObjectEvaluation& object : evaluation.objects) correct += object.correct ? 1 : 0;
  std::cerr << label << " [" << i + 1 << "/" << n << "] " << evaluation.frame << ": " << correct << " of "
            << evaluation.objects.size() << " correct, " << evaluation.false_positives << " false positives, "
            << Fixed(ms, 0) << " ms\n";
}

// Whether two runs judged the same detections: per frame, the same objects found with the same pose errors and
// the same false positives.
bool SameDetections(const Run& a, const Run& b) {
  if (a.frames.size() != b.frames.size()) return false;
  for (size_t f = 0; f < a.frames.size(); ++f) {
    const FrameEvaluation &x = a.frames[f], &y = b.frames[f];
    if (x.objects.size() != y.objects.size() || x.false_positive_models != y.false_positive_models) return false;
    for (size_t o = 0; o < x.objects.size(); ++o) {
      if (x.objects[o].detected != y.objects[o].detected || x.objects[o].error.add_m != y.objects[o].error.add_m) {
        return false;
      }
    }
  }
  return true;
}

// With `track`, each frame gets the previous frame's detections of the same video as priors, and only every
// `search_every`-th frame of a video (the first, 1 + n, ...) searches the models that are not tracked.
Run RunRecognizer(const ModelLibrary& library, const RecognizerOptions& options, const std::vector<NamedFrame>& frames,
                  const std::vector<EvalModel>& models, const std::string& label, bool track = false,
                  int search_every = 1) {
  Recognizer recognizer(library, options);
  RecognitionStream stream(recognizer, {track, search_every});
  Run run;
  for (size_t i = 0; i < frames.size(); ++i) {
    // Each video is a stream of its own.
    const auto video = [&](size_t k) { return frames[k].name.substr(0, frames[k].name.find('/')); };
    if (i > 0 && video(i) != video(i - 1)) stream.Reset();
    const RecognitionResult result = stream.Next(frames[i].frame.rgbd);
    run.frames.push_back(EvaluateFrame(frames[i].name, result.detections, frames[i].frame.ground_truth, models));
    run.detections.push_back(result.detections);
    for (const auto& [stage, ms] : result.timings_ms) run.stage_ms[stage].push_back(ms);
    Log(label, i, frames.size(), run.frames.back(), result.timings_ms.at("total"));
  }
  return run;
}

Run RunPeer(RecognitionPeer& peer, const std::vector<NamedFrame>& frames, const std::vector<EvalModel>& models,
            const std::string& label) {
  Run run;
  for (size_t i = 0; i < frames.size(); ++i) {
    const PeerResult result = peer.Recognize(frames[i].frame.rgbd);
    run.frames.push_back(EvaluateFrame(frames[i].name, result.detections, frames[i].frame.ground_truth, models));
    run.detections.push_back(result.detections);
    run.stage_ms["total"].push_back(result.time_ms);
    run.stage_ms["scene"].push_back(result.scene_ms);
    run.stage_ms["scene points"].push_back(result.scene_points);
    Log(label, i, frames.size(), run.frames.back(), result.time_ms);
    for (const Detection& detection : result.detections) {
      const auto& objects = run.frames.back().objects;
      const auto object = std::find_if(objects.begin(), objects.end(),
                                       [&](const ObjectEvaluation& o) { return o.model == detection.model; });
      std::cerr << "  " << detection.model << " share " << Fixed(detection.inlier_fraction, 2) << ' '
                << (object == objects.end() ? "absent"
                    : object->correct       ? "correct"
                                            : "wrong");
      if (object != objects.end()) {
        std::cerr << " (" << Fixed(object->error.rotation_deg, 0) << " deg, " << Fixed(object->error.translation_mm, 0)
                  << " mm)";
      }
      std::cerr << '\n';
    }
  }
  return run;
}

// The false positives that were tracked detections: a mistake carried on from an earlier frame (one instance per
// model, so a false positive's model names its detection).
int FollowedFalsePositives(const Run& run) {
  int followed = 0;
  for (size_t i = 0; i < run.frames.size() && i < run.detections.size(); ++i) {
    for (const std::string& model : run.frames[i].false_positive_models) {
      followed += static_cast<int>(std::count_if(run.detections[i].begin(), run.detections[i].end(),
                                                 [&](const Detection& d) { return d.model == model && d.tracked; }));
    }
  }
  return followed;
}

// The run labelled `label` in `runs`, or null.
const Run* FindRun(const Runs& runs, const std::string& label) {
  const auto found = std::find_if(runs.begin(), runs.end(), [&](const auto& run) { return run.first == label; });
  return found == runs.end() ? nullptr : &found->second;
}

// The run labelled `label` (it must be there).
const Run& RunNamed(const Runs& runs, const std::string& label) {
  const Run* run = FindRun(runs, label);
  if (run == nullptr) throw std::logic_error("recognize_bench: no run labelled '" + label + "'");
  return *run;
}

// The runs on the frames with one library.
struct LibraryRuns {
  std::string name;  // "ycbv.sqlite (7 models)"
  Runs runs;         // in column order
};

using ObjectFilter = std::function<bool(const FrameEvaluation&, const ObjectEvaluation&)>;

// "correct / present" over the objects of `run` that `counted` keeps; with the recall in per cent if `recall`.
std::string CountObjects(const Run& run, const ObjectFilter& counted, bool recall = false) {
  int correct = 0, present = 0;
  for (const FrameEvaluation& frame : run.frames) {
    for (const ObjectEvaluation& object : frame.objects) {
      if (!counted(frame, object)) continue;
      correct += object.correct ? 1 : 0;
      ++present;
    }
  }
  const std::string count = std::to_string(correct) + " / " + std::to_string(present);
  return recall ? count + " (" + Fixed(100.0 * correct / std::max(present, 1), 1) + " %)" : count;
}

// The video of a frame: the part of its name before '/'.
std::string VideoOf(const std::string& frame) {
  return frame.substr(0, frame.find('/'));
}

// The median or mean of the run's whole-frame times, in ms; "-" without them.
std::string FrameMs(const Run& run, bool median) {
  const auto total = run.stage_ms.find("total");
  if (total == run.stage_ms.end()) return "-";
  return Fixed(median ? Median(total->second) : Mean(total->second), 0);
}

// A table row: `name`, then `cell` of the run of each of `columns` in `runs` ("-" where `runs` has none).
std::string TableRow(const std::string& name, const Runs& runs, const std::vector<std::string>& columns,
                     const std::function<std::string(const Run&)>& cell) {
  std::string row = "| " + name + " |";
  for (const std::string& label : columns) {
    const Run* run = FindRun(runs, label);
    row += ' ' + (run != nullptr ? cell(*run) : std::string("-")) + " |";
  }
  return row + '\n';
}

// The recall table's rows of one library's `runs`: per object correct / present; then recall (overall and per video,
// when there are several), false positives and the time per frame.
std::string RecallRows(const Runs& runs, const std::vector<std::string>& columns) {
  std::set<std::string> objects, videos;
  for (const auto& [label, run] : runs) {
    for (const FrameEvaluation& frame : run.frames) {
      videos.insert(VideoOf(frame.frame));
      for (const ObjectEvaluation& object : frame.objects) objects.insert(object.model);
    }
  }
  std::string rows;
  for (const std::string& name : objects) {
    rows += TableRow(name, runs, columns, [&](const Run& run) {
      return CountObjects(run, [&](const FrameEvaluation&, const ObjectEvaluation& o) { return o.model == name; });
    });
  }
  rows += TableRow("**all (recall)**", runs, columns, [](const Run& run) {
    return "**" +
           CountObjects(
               run, [](const FrameEvaluation&, const ObjectEvaluation&) { return true; }, true) +
           "**";
  });
  for (const std::string& video : videos.size() > 1 ? videos : std::set<std::string>{}) {
    rows += TableRow("video " + video, runs, columns, [&](const Run& run) {
      return CountObjects(run,
                          [&](const FrameEvaluation& f, const ObjectEvaluation&) { return VideoOf(f.frame) == video; });
    });
  }
  rows += TableRow("false positives per frame", runs, columns, [](const Run& run) {
    int false_positives = 0;
    for (const FrameEvaluation& frame : run.frames) false_positives += frame.false_positives;
    return Fixed(static_cast<double>(false_positives) / std::max<size_t>(run.frames.size(), 1), 2);
  });
  rows += TableRow("false positives followed from an earlier frame", runs, columns,
                   [](const Run& run) { return std::to_string(FollowedFalsePositives(run)); });
  rows += TableRow("median ms per frame", runs, columns, [](const Run& run) { return FrameMs(run, true); });
  rows += TableRow("mean ms per frame", runs, columns, [](const Run& run) { return FrameMs(run, false); });
  return rows;
}

// A column per run (each label once, in the order they ran); the rows of RecallRows per library, under a row naming
// the library when there are several.
std::string RecallTable(const std::vector<LibraryRuns>& libraries) {
  std::vector<std::string> columns;
  for (const LibraryRuns& library : libraries) {
    for (const auto& [label, run] : library.runs) {
      if (std::find(columns.begin(), columns.end(), label) == columns.end()) columns.push_back(label);
    }
  }
  std::ostringstream out;
  out << "| object |";
  for (const std::string& label : columns) out << ' ' << label << " |";
  out << "\n|---|";
  for (size_t i = 0; i < columns.size(); ++i) out << "---:|";
  out << '\n';
  for (const LibraryRuns& library : libraries) {
    if (libraries.size() > 1) {
      out << "| **" << library.name << "** |";
      for (size_t i = 0; i < columns.size(); ++i) out << " |";
      out << '\n';
    }
    out << RecallRows(library.runs, columns);
  }
  return out.str();
}

// The time per stage of the run labelled `label` (ms per frame). With several libraries: the stages of the first
// library's run, then one row per library with its time per frame and its median over the first library's.
std::string TimingTable(const std::vector<LibraryRuns>& libraries, const std::string& label) {
  const bool several = libraries.size() > 1;
  std::ostringstream out;
  out << "| stage | median ms per frame | mean ms per frame |" << (several ? " median / first library's |" : "")
      << "\n|---|---:|---:|" << (several ? "---:|" : "") << '\n';
  const Run& first = RunNamed(libraries.front().runs, label);
  for (const char* stage : {"extract", "describe", "track", "preselect", "rank", "match", "ransac", "point_pairs",
                            "verify", "refine", "total"}) {
    const auto found = first.stage_ms.find(stage);
    if (found == first.stage_ms.end() || (several && found->first == "total")) continue;
    out << "| " << stage << " | " << Fixed(Median(found->second), 1) << " | " << Fixed(Mean(found->second), 1)
        << (several ? " | |\n" : " |\n");
  }
  const double first_median = Median(first.stage_ms.at("total"));
  for (const LibraryRuns& library : several ? libraries : std::vector<LibraryRuns>{}) {
    const std::vector<double>& total = RunNamed(library.runs, label).stage_ms.at("total");
    out << "| total, " << library.name << " | " << Fixed(Median(total), 1) << " | " << Fixed(Mean(total), 1) << " | "
        << Fixed(Median(total) / std::max(first_median, 1e-9), 2) << " |\n";
  }
  return out.str();
}

// The peers' inlier share (recognition_peers.h) of every ground-truth pose: what the acceptance threshold must pass.
std::string GroundTruthInlierShares(const std::vector<PeerModel>& models, const std::vector<NamedFrame>& frames,
                                    const PeerOptions& options) {
  std::vector<double> shares;
  for (const NamedFrame& frame : frames) {
    const std::vector<Eigen::Vector3f> scene = SceneCloud(frame.frame.rgbd, options.voxel_m);
    const RadiusGrid grid(scene, static_cast<float>(options.inlier_distance_m));
    for (const GroundTruth& truth : frame.frame.ground_truth) {
      for (const PeerModel& model : models) {
        if (model.name != truth.object_name) continue;
        std::vector<Eigen::Vector3f> points;
        VoxelDownsample(model.points, {}, options.voxel_m, &points, nullptr);
        shares.push_back(InlierFraction(points, truth.camera_from_object, grid));
      }
    }
  }
  if (shares.empty()) return "";
  std::sort(shares.begin(), shares.end());
  const auto below =
      std::count_if(shares.begin(), shares.end(), [&](double s) { return s < options.min_inlier_fraction; });
  return "At the ground-truth poses that share is " + Fixed(100 * shares.front(), 0) + " % to " +
         Fixed(100 * shares.back(), 0) + " % (median " + Fixed(100 * Median(shares), 0) + " %; " +
         std::to_string(below) + " of " + std::to_string(shares.size()) + " objects below the threshold). ";
}

// `frame` with depth only where the scene lies within 1 cm of a ground-truth object of `models` (posed by the
// ground truth): the peers handed the objects' own pixels, to tell their matching from the clutter.
NamedFrame ObjectPixelsOnly(const NamedFrame& frame, const std::vector<PeerModel>& models) {
  std::vector<Eigen::Vector3f> posed;
  for (const GroundTruth& truth : frame.frame.ground_truth) {
    for (const PeerModel& model : models) {
      if (model.name != truth.object_name) continue;
      for (const Eigen::Vector3f& point : model.points) posed.push_back(truth.camera_from_object.cast<float>() * point);
    }
  }
  NamedFrame masked = frame;
  masked.frame.rgbd.depth = frame.frame.rgbd.depth.clone();
  const RadiusGrid grid(posed, 0.01F);
  cv::Mat& depth = masked.frame.rgbd.depth;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      float& z = depth.at<float>(v, u);
      if (z <= 0.0F) continue;
      const Eigen::Vector3f point = frame.frame.rgbd.camera.BackProject(Eigen::Vector2d(u, v), z).cast<float>();
      if (posed.empty() || grid.NearestWithin(point).first < 0) z = 0.0F;
    }
  }
  return masked;
}

const char* kOurs = "ECV + RANSAC + ICP";
const char* kTracking = "ECV + RANSAC + ICP, tracking";
const char* kTurned = "ECV + RANSAC + ICP, frames turned 180 degrees";
const char* kFigureFrame = "0001/000001";  // --figure: the demo frame (models/frame)
const char* kBytes = "ECV + RANSAC + ICP, --matcher bytes";
const char* kPcl = "PCL FPFH + prerejective + ICP";
const char* kPpf = "OpenCV PPF + ICP";
const char* kOpen3d = "Open3D FPFH + RANSAC + ICP";

// The label of a search of the `n` pre-selected models.
std::string Preselecting(int n) {
  return std::string(kOurs) + ", --preselect " + std::to_string(n);
}

// The label of tracking with a full search every `n`-th frame.
std::string TrackingEvery(int n) {
  return std::string(kTracking) + ", full search every " + std::to_string(n) + " frames";
}

// Which methods RunAll runs.
struct Methods {
  bool ours = true;                         ///< ECV with and without ICP
  RecognizerOptions options;                ///< every run of ours starts from these (the settings table's flags)
  bool track = false;                       ///< ours also with the previous frame's detections as priors
  std::vector<int> search_every;            ///< each > 1: ours also tracking with a full search only every n-th frame
  bool peers = false;                       ///< PCL, OpenCV PPF and Open3D on the whole frames
  bool object_pixels = false;               ///< the peers also on the objects' pixels only
  std::string python = "/usr/bin/python3";  ///< the interpreter that runs the Open3D peer
  bool bytes = false;          ///< ours also with MatchIndex::kBytes (recognize --matcher bytes; AVX-512 VNNI only)
  std::vector<int> preselect;  ///< each > 0: ours also searching only this many pre-selected models
  std::vector<int> threads;    ///< each > 1: ours also with this many worker threads (the same detections, faster)
  bool turned = false;         ///< ours also on the frames turned 180 degrees (a camera held upside down)
  bool casts = false;          ///< ours also on the frames under each ColorCasts() light (and each seed)
  std::vector<std::string> hypotheses;  ///< ours also with these hypothesis sources (recognize --hypotheses)
  std::vector<uint64_t> seeds;          ///< ours, the hypothesis and the tracking runs repeated with these seeds
  std::vector<int> confirm_every;       ///< tracking also with each of these TrackingOptions::confirm_every
  std::vector<int> confirm_first;       ///< ... and each of these TrackingOptions::confirm_first
};

// The `methods` on `frames` with the library at `db`.
LibraryRuns RunAll(const std::string& db, const std::vector<NamedFrame>& frames, const Methods& methods,
                   const PeerOptions& peer_options, std::ostringstream* notes) {
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(db, load);
  const std::vector<EvalModel> models = EvalModels(library);
  *notes << "Library: " << library.models().size() << " models, " << library.NumViews() << " views (`" << db
         << "`); models with a colour matrix: "
         << std::count_if(library.models().begin(), library.models().end(),
                          [](const LibraryModel& model) { return model.color_matrix.has_value(); })
         << ". ";
  LibraryRuns result{
      std::filesystem::path(db).filename().string() + " (" + std::to_string(library.models().size()) + " models)", {}};
  Runs& runs = result.runs;
  RecognizerOptions options = methods.options;
  // A run of `settings` on `run_frames` labelled `label`, then one more per --seeds seed, labelled ", seed N".
  const auto add_seeded = [&](const std::string& label, RecognizerOptions settings,
                              const std::vector<NamedFrame>& run_frames) {
    runs.emplace_back(label, RunRecognizer(library, settings, run_frames, models, label));
    for (const uint64_t seed : methods.seeds) {
      settings.ransac.seed = seed;
      const std::string seeded = label + ", seed " + std::to_string(seed);
      runs.emplace_back(seeded, RunRecognizer(library, settings, run_frames, models, seeded));
    }
  };
  if (methods.ours) {
    add_seeded(kOurs, options, frames);
    if (methods.turned)
      runs.emplace_back(kTurned, RunRecognizer(library, options, TurnedFrames(frames), models, "turned"));
    if (methods.casts) {
      for (const auto& [name, cast] : ColorCasts()) {
        add_seeded(std::string(kOurs) + ", light " + name, options, CastFrames(frames, cast));
      }
    }
    for (const int threads : methods.threads) {
      if (threads <= 1) continue;
      RecognizerOptions threaded = options;
      threaded.threads = threads;
      const std::string label = "ECV + RANSAC + ICP, " + std::to_string(threads) + " threads";
      runs.emplace_back(label, RunRecognizer(library, threaded, frames, models, "threads"));
      *notes << label << ": detections " << (SameDetections(runs.front().second, runs.back().second) ? "" : "NOT ")
             << "identical to one thread's. ";
    }
    if (methods.bytes) {
      RecognizerOptions bytes = options;
      bytes.match.index = MatchIndex::kBytes;
      runs.emplace_back(kBytes, RunRecognizer(library, bytes, frames, models, "bytes"));
    }
    for (const int preselect : methods.preselect) {
      if (preselect <= 0) continue;
      RecognizerOptions preselecting = options;
      preselecting.preselect.models = preselect;
      runs.emplace_back(Preselecting(preselect), RunRecognizer(library, preselecting, frames, models, "preselect"));
    }
    for (const std::string& source : methods.hypotheses) {
      RecognizerOptions sourced = options;
      sourced.point_pairs.source = ParseHypothesisSource(source, "--hypotheses");
      add_seeded(std::string(kOurs) + ", --hypotheses " + source, sourced, frames);
      if (!methods.casts) continue;
      for (const auto& [name, cast] : ColorCasts()) {
        add_seeded(std::string(kOurs) + ", --hypotheses " + source + ", light " + name, sourced,
                   CastFrames(frames, cast));
      }
    }
    if (methods.track) {
      const RecognizerOptions& tracking = options;
      runs.emplace_back(kTracking, RunRecognizer(library, tracking, frames, models, "track", true));
      for (const int every : methods.search_every) {
        if (every <= 1) continue;
        runs.emplace_back(TrackingEvery(every),
                          RunRecognizer(library, tracking, frames, models, "track every", true, every));
      }
      std::vector<int> confirm_every = methods.confirm_every;
      if (confirm_every.empty()) confirm_every.push_back(tracking.tracking.confirm_every);
      std::vector<uint64_t> seeds = methods.seeds;
      if (seeds.empty()) seeds.push_back(tracking.ransac.seed);
      std::vector<int> confirm_first = methods.confirm_first;
      if (confirm_first.empty()) confirm_first.push_back(tracking.tracking.confirm_first);
      for (const int every : confirm_every) {
        for (const int first : confirm_first) {
          RecognizerOptions confirming = tracking;
          confirming.tracking.confirm_every = every;
          confirming.tracking.confirm_first = first;
          for (const uint64_t seed : seeds) {
            confirming.ransac.seed = seed;
            const std::string label = std::string(kTracking) + ", confirm every " + std::to_string(every) + ", first " +
                                      std::to_string(first) + ", seed " + std::to_string(seed);
            runs.emplace_back(label, RunRecognizer(library, confirming, frames, models, label, true));
            if (!methods.casts) continue;
            for (const auto& [name, cast] : ColorCasts()) {
              const std::string cast_label = label + ", light " + name;
              runs.emplace_back(cast_label,
                                RunRecognizer(library, confirming, CastFrames(frames, cast), models, cast_label, true));
            }
          }
        }
      }
    }
    options.refine = false;
    runs.emplace_back("ECV + RANSAC (no ICP)", RunRecognizer(library, options, frames, models, "no icp"));
  }
  if (!methods.peers) return result;
  std::vector<PeerModel> peer_models;
  for (const LibraryModel& model : library.models()) peer_models.push_back(SamplePeerModel(model.record));
  *notes << GroundTruthInlierShares(peer_models, frames, peer_options);
  auto start = Clock::now();
  const std::unique_ptr<RecognitionPeer> pcl = MakePclPeer(peer_models, peer_options);
  const double pcl_setup_ms = MillisecondsSince(start);
  runs.emplace_back(kPcl, RunPeer(*pcl, frames, models, "pcl"));
  start = Clock::now();
  const std::unique_ptr<RecognitionPeer> ppf = MakePpfPeer(peer_models, peer_options);
  const double ppf_setup_ms = MillisecondsSince(start);
  runs.emplace_back(kPpf, RunPeer(*ppf, frames, models, "ppf"));
  std::string open3d_problem;
  const std::unique_ptr<RecognitionPeer> open3d =
      MakeOpen3dPeer(peer_models, peer_options, methods.python,
                     std::string(ECV_SOURCE_DIR) + "/bench/recognition_open3d.py", &open3d_problem);
  if (open3d) {
    runs.emplace_back(kOpen3d, RunPeer(*open3d, frames, models, "open3d"));
  } else {
    std::cerr << "recognize_bench: " << open3d_problem << '\n';
    *notes << open3d_problem << ". ";
  }
  if (methods.object_pixels) {
    std::vector<NamedFrame> masked;
    for (const NamedFrame& frame : frames) masked.push_back(ObjectPixelsOnly(frame, peer_models));
    runs.emplace_back(std::string(kPcl) + ", objects' pixels only", RunPeer(*pcl, masked, models, "pcl objects"));
    runs.emplace_back(std::string(kPpf) + ", objects' pixels only", RunPeer(*ppf, masked, models, "ppf objects"));
    if (open3d) {
      runs.emplace_back(std::string(kOpen3d) + ", objects' pixels only",
                        RunPeer(*open3d, masked, models, "open3d objects"));
    }
  }
  const Run& pcl_run = RunNamed(runs, kPcl);
  const Run& ppf_run = RunNamed(runs, kPpf);
  *notes << "Peers: model set-up (voxel grid, PCL normals + FPFH) " << Fixed(pcl_setup_ms, 0)
         << " ms for PCL, PPF training " << Fixed(ppf_setup_ms, 0) << " ms for OpenCV, not in the times per frame; "
         << "scene cloud " << Fixed(Median(pcl_run.stage_ms.at("scene points")), 0)
         << " points (median), its normals and features " << Fixed(Median(pcl_run.stage_ms.at("scene")), 0)
         << " ms (PCL), " << Fixed(Median(ppf_run.stage_ms.at("scene")), 0) << " ms (OpenCV)";
  if (open3d) *notes << ", " << Fixed(Median(RunNamed(runs, kOpen3d).stage_ms.at("scene")), 0) << " ms (Open3D)";
  *notes << " per frame. ";
  return result;
}

// The runs of ours with each library of `dbs`, in turn; the peers with the first only.
std::vector<LibraryRuns> RunLibraries(const std::vector<std::string>& dbs, const std::vector<NamedFrame>& frames,
                                      const Methods& methods, const PeerOptions& peer_options,
                                      std::ostringstream* notes) {
  std::vector<LibraryRuns> libraries;
  Methods per_library = methods;
  for (const std::string& db : dbs) {
    if (!libraries.empty() && !methods.ours) break;
    libraries.push_back(RunAll(db, frames, per_library, peer_options, notes));
    per_library.peers = false;
  }
  if (libraries.size() > 1) {
    *notes << "Every run of ours with each library; the peers with the first. The recall table has the rows of each "
              "library under its name (a library is judged on the objects of the frames that it holds); each time "
              "table the stages with the first library, then a row per library with its median over the first's. ";
  }
  return libraries;
}

// One picture of frame `name` per run of `labels` (those that ran), 2 per row, each with the run's detections
// drawn by the recognizer (models in red, named) and a caption: what the picture in the README compares.
cv::Mat DetectionsFigure(const std::string& db, const std::vector<NamedFrame>& frames, const Runs& runs,
                         const std::string& name, const std::vector<std::string>& labels) {
  const auto frame = std::find_if(frames.begin(), frames.end(), [&](const NamedFrame& f) { return f.name == name; });
  if (frame == frames.end()) throw std::runtime_error("--figure: frame " + name + " is not among the frames run");
  const auto index = static_cast<size_t>(frame - frames.begin());
  const ModelLibrary library = ModelLibrary::Load(db);
  Recognizer recognizer(library);
  std::vector<cv::Mat> panels;
  for (const std::string& label : labels) {
    const auto run = std::find_if(runs.begin(), runs.end(), [&](const auto& r) { return r.first == label; });
    if (run == runs.end()) continue;
    const FrameEvaluation& evaluation = run->second.frames[index];
    const auto found = std::count_if(evaluation.objects.begin(), evaluation.objects.end(),
                                     [](const ObjectEvaluation& o) { return o.correct; });
    cv::Mat panel = recognizer.DrawDetections(frame->frame.rgbd, run->second.detections[index]);
    cv::rectangle(panel, cv::Rect(0, 0, panel.cols, 56), cv::Scalar(0, 0, 0), cv::FILLED);
    const std::string caption = std::to_string(found) + " of " + std::to_string(evaluation.objects.size()) +
                                " found, " + std::to_string(evaluation.false_positives) + " false";
    cv::putText(panel, label, cv::Point(8, 22), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1,
                cv::LINE_AA);
    cv::putText(panel, caption, cv::Point(8, 46), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1,
                cv::LINE_AA);
    panels.push_back(panel);
  }
  if (panels.empty()) throw std::runtime_error("--figure: none of the compared runs ran");
  while (panels.size() % 2 != 0) panels.push_back(cv::Mat::zeros(panels.front().size(), panels.front().type()));
  std::vector<cv::Mat> rows;
  for (size_t i = 0; i < panels.size(); i += 2) {
    cv::Mat row;
    cv::hconcat(panels[i], panels[i + 1], row);
    rows.push_back(row);
  }
  cv::Mat figure;
  cv::vconcat(rows, figure);
  cv::resize(figure, figure, cv::Size(), 0.75, 0.75, cv::INTER_AREA);
  return figure;
}

std::string PeerSettings(const PeerOptions& o) {
  std::ostringstream out;
  out << "Peers, whole frame (no masks, no ground truth), geometry only, one thread: model = points sampled on the "
         "mesh surface (2 mm apart, area-weighted, seed 1) with the triangles' normals; scene = every depth pixel; "
         "both on a "
      << Fixed(o.voxel_m * 1000, 0) << " mm voxel grid. PCL: normals by PCL (radius "
      << Fixed(o.normal_radius_m * 1000, 0) << " mm; model normals turned to agree with the mesh's), FPFH radius "
      << Fixed(o.fpfh_radius_m * 1000, 0) << " mm, SampleConsensusPrerejective (" << o.pcl_iterations
      << " iterations, 3 samples, correspondence randomness " << o.pcl_correspondence_randomness << ", similarity "
      << Fixed(o.pcl_similarity, 2) << ", inlier distance " << Fixed(o.inlier_distance_m * 1000, 0)
      << " mm, inlier fraction " << Fixed(o.min_inlier_fraction, 2) << ", std::srand(" << o.seed
      << ") per model), then IterativeClosestPoint (" << o.icp_iterations << " iterations, "
      << Fixed(o.inlier_distance_m * 1000, 0) << " mm). OpenCV: PPF3DDetector(relative sampling "
      << Fixed(o.ppf_relative_sampling, 3) << ", relative distance " << Fixed(o.ppf_relative_distance, 3)
      << ") trained on the voxelised model with its normals; match(scene sample step 1/"
      << Fixed(1.0 / o.ppf_scene_sample_step, 0) << ", relative scene distance " << Fixed(o.ppf_scene_distance, 3)
      << ") on the voxelised scene with computeNormalsPC3d (" << o.ppf_normal_neighbours
      << " neighbours, turned to the camera); the most voted pose, its rotation made rigid (OpenCV 4.6 returns it "
         "scaled: the pose cluster's quaternions are averaged without normalising), refined with ppf_match_3d::ICP ("
      << o.icp_iterations
      << " iterations) on the scene points within one model diameter, kept unless it lowers the inlier share. "
         "Open3D 0.16 (bench/recognition_open3d.py, one OpenMP thread, one process per frame whose start and model "
         "features are not timed): the depth image to a cloud, the same voxel grid, normals (radius "
      << Fixed(o.normal_radius_m * 1000, 0)
      << " mm, at most 30 neighbours; the scene's turned to the camera, the model's to agree with the mesh's), FPFH "
         "(radius "
      << Fixed(o.fpfh_radius_m * 1000, 0)
      << " mm, at most 100 neighbours), registration_ransac_based_on_feature_matching (at most " << o.open3d_iterations
      << " iterations, confidence " << Fixed(o.open3d_confidence, 3) << ", 3 points, edge-length checker "
      << Fixed(o.pcl_similarity, 2) << ", distance checker and inlier distance " << Fixed(o.inlier_distance_m * 1000, 0)
      << " mm, seed " << o.seed << "), then point-to-plane ICP (" << o.icp_iterations << " iterations, "
      << Fixed(o.inlier_distance_m * 1000, 0) << " mm). All peers report a model when, after ICP, at least "
      << Fixed(100 * o.min_inlier_fraction, 0) << " % of its voxelised points lie within "
      << Fixed(o.inlier_distance_m * 1000, 0)
      << " mm of a scene point (score = that share); at most one detection per model.\n";
  return out.str();
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  using namespace ecv;
  using namespace ecv::bench;
  std::vector<std::string> dbs;
  std::string lmo_db, figure, results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  int limit = 0, step = 1;
  Methods methods;
  PeerOptions peer_options;
  CLI::App app{
      "recognize_bench: recognition on the real YCB-Video frames (and the LM-O frame) scored against the "
      "ground truth (recall at ADD < 0.1 d, false positives) with the time per stage; PCL, OpenCV PPF and "
      "Open3D as peers.",
      "recognize_bench"};
  app.add_option("--db", dbs,
                 "Library of the YCB-Video models; repeated, every run of ours with each library in turn (ratios "
                 "between library sizes from one run); the peers and --figure with the first")
      ->required();
  app.add_option("--lmo-db", lmo_db,
                 "Library of the LM-O models: also the LM-O frame, as its own table (default: not run)");
  app.add_flag("--peers", methods.peers, "Also run the peers (PCL, OpenCV PPF, Open3D) on the same frames");
  app.add_flag_callback(
      "--peers-only",
      [&methods] {
        methods.peers = true;
        methods.ours = false;
      },
      "Run the peers only, not ours (for tuning the peers)");
  app.add_flag("--object-pixels", methods.object_pixels,
               "Also run the peers on depth cut to the ground-truth objects' own pixels");
  app.add_flag("--track", methods.track, "Also run ours with the previous frame's detections as priors");
  AddSettingValues(app, "search-every", &methods.search_every,
                   "Implies --track; each N > 1 also runs ours searching untracked models only every N-th frame");
  AddSettingValues(app, "confirm-every", &methods.confirm_every,
                   "With --track: tracking also with each of these confirm_every values (recognize --confirm-every), "
                   "for each of --seeds");
  AddSettingValues(app, "confirm-first", &methods.confirm_first,
                   "With --track: tracking also with each of these confirm_first values (recognize --confirm-first), "
                   "for each --confirm-every and seed");
  AddSettingValues(app, "threads", &methods.threads,
                   "Each N > 1 also runs ours with N worker threads (same detections checked)");
  app.add_flag_callback(
      "--bytes",
      [&methods] {
        if (!ByteNeighbours::CpuHasVnni())
          throw CLI::ValidationError("--bytes", "needs AVX-512 VNNI, which this CPU lacks");
        methods.bytes = true;
      },
      "Also run ours matching with ByteNeighbours (recognize --matcher bytes; needs AVX-512 VNNI)");
  AddSettingValues(app, "preselect", &methods.preselect,
                   "Each N > 0 also runs ours searching only the N models whose best views rank highest");
  AddSettingValues(app, "hypotheses", &methods.hypotheses,
                   "Also run ours with each of these sources of pose hypotheses (ppf, both; recognize --hypotheses)");
  app.add_option("--seeds", methods.seeds,
                 "Also run ours (and each --hypotheses run) with these RANSAC seeds (the default run has --seed)");
  app.add_flag("--turned", methods.turned, "Also run ours on the frames turned 180 degrees (ground truth moved)");
  app.add_flag("--casts", methods.casts,
               "Also run ours on the frames under changed light: white balance 15 % warmer and cooler, gamma 0.8 and "
               "1.25 (with each of --seeds and each --hypotheses source; with --track, tracking too)");
  app.add_option("--python", methods.python, "Python interpreter with Open3D for the Open3D peer")
      ->capture_default_str();
  app.add_option("--figure", figure,
                 "Picture of the detections of ours and each peer in the demo frame 0001/000001 (default: none)");
  app.add_option("--results", results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.add_option("--frames", limit, "Only the first N YCB-Video frames (0: all 30)")->capture_default_str();
  app.add_option("--frame-step", step, "Every S-th YCB-Video frame only (for tuning the peers)")->capture_default_str();
  app.add_option("--ppf-sampling", peer_options.ppf_relative_sampling,
                 "OpenCV PPF peer: model sampling step, relative to the model's box")
      ->capture_default_str();
  app.add_option("--ppf-scene-distance", peer_options.ppf_scene_distance,
                 "OpenCV PPF peer: scene sampling step, relative to the scene's box")
      ->capture_default_str();
  app.add_option("--min-inlier-fraction", peer_options.min_inlier_fraction,
                 "Peers: share of a model's points within 1 cm of the scene after ICP to report it")
      ->capture_default_str();
  RecognizerSettings settings;  // every run of ours: the table's flags but those above, which add runs
  AddSettingFlags(app, &settings,
                  {"threads", "preselect", "hypotheses", "track", "search-every", "search-beside", "confirm-every",
                   "confirm-first"},
                  "Settings of every run of ours (as `ecvpose recognize` takes them)");
  app.footer(
      "Libraries:\n  scripts/build_ycbv_library YCBV_LIB.sqlite --views 40 --distance 0.9\n"
      "  scripts/build_lmo_library LMO_LIB.sqlite --views 40 --distance 1.0");
  if (const auto exit_code = ParseCommandLine(app, argc, argv)) return *exit_code;
  methods.options = settings.options;
  methods.track = methods.track || !methods.search_every.empty();
  try {
    peer_options.Check();
    std::ostringstream markdown, notes;
    const std::vector<NamedFrame> frames = YcbvFrames(ECV_DATA_DIR, limit, step);
    const std::vector<LibraryRuns> libraries = RunLibraries(dbs, frames, methods, peer_options, &notes);
    if (!figure.empty()) {
      WriteColorImage(figure, DetectionsFigure(dbs.front(), frames, libraries.front().runs, kFigureFrame,
                                               {kOurs, kOpen3d, kPcl, kPpf}));
      std::cerr << "recognize_bench: wrote " << figure << '\n';
    }
    markdown << notes.str() << frames.size()
             << " YCB-Video frames (videos 0000-0002). Correct = ADD < 0.1 x diameter (ADD-S for symmetric models); "
                "a false positive is a detection of a model not in the frame or a wrong pose.\n\n"
             << RecallTable(libraries);
    if (methods.ours)
      markdown << "\nTime per frame, whole library (ECV + RANSAC + ICP):\n\n" << TimingTable(libraries, kOurs);
    for (const std::string& source : methods.ours ? methods.hypotheses : std::vector<std::string>{}) {
      markdown << "\nThe same with `--hypotheses " << source << "` (point_pairs: voting; verify and refine include the "
               << "point pair poses'):\n\n"
               << TimingTable(libraries, std::string(kOurs) + ", --hypotheses " + source);
    }
    if (methods.ours && methods.bytes) {
      markdown << "\nThe same matching with ByteNeighbours (`recognize --matcher bytes`: every scene descriptor "
                  "compared over 7-bit values, AVX-512 VNNI):\n\n"
               << TimingTable(libraries, kBytes);
    }
    for (const int preselect : methods.ours ? methods.preselect : std::vector<int>{}) {
      if (preselect <= 0) continue;
      markdown << "\nThe same searching only the " << preselect
               << " models whose best views rank highest (`recognize --preselect " << preselect << "`):\n\n"
               << TimingTable(libraries, Preselecting(preselect));
    }
    if (methods.ours && methods.track) {
      markdown << "\nThe same with tracking (each frame gets the previous frame's detections of its video as priors; "
                  "the first frame of each video has none):\n\n"
               << TimingTable(libraries, kTracking);
      for (const int every : methods.search_every) {
        if (every <= 1) continue;
        markdown << "\nTracking with a full search only on the first frame of each video and then once every " << every
                 << " frames; the frames in between follow the tracked objects and search only the models whose "
                    "track was lost (`recognize --track --search-every "
                 << every << "`):\n\n"
                 << TimingTable(libraries, TrackingEvery(every));
      }
    }
    if (!lmo_db.empty()) {
      std::ostringstream lmo_notes;
      Methods lmo_methods = methods;
      lmo_methods.track = false;  // one frame
      const LibraryRuns lmo_runs = RunAll(lmo_db, LmoFrames(ECV_DATA_DIR), lmo_methods, peer_options, &lmo_notes);
      markdown << "\nLinemod-Occluded, scene 000002 image 3 (Kinect v1, 8 vertex-coloured models, eggbox and glue "
                  "judged by ADD-S). "
               << lmo_notes.str() << "\n\n"
               << RecallTable({lmo_runs});
    }
    if (methods.peers) markdown << '\n' << PeerSettings(peer_options);
    ReportSection(results, "Recognition on YCB-Video and LM-O (recognize_bench)", CommandLine(argc, argv),
                  markdown.str());
  } catch (const std::exception& error) {
    std::cerr << "recognize_bench: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
