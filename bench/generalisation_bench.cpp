// The generalisation set (issue 54): scenes no setting was chosen on. Rendered scenes of the 16 YCB-Video meshes in
// resting poses on tables cut from real frames, with unmodelled LM-O clutter, light of random colour and direction,
// shadows and sensor noise; composites of real frames (an object cut from one video and pasted into another, also
// beside its look-alikes); the real frames under strong casts. Everything is drawn from seeds, and split once: odd
// seeds and video 0002 choose settings, even seeds and videos 0000 and 0001 report (generalisation_set.h). Reports
// recall at ADD < 0.1 d and false positives per frame, per set, condition and object, and how the mistakes happen.
//
//   scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9               # 7 textured models
//   scripts/build_ycbv_library --with-untextured /tmp/ycbv16.sqlite --views 40 --distance 0.9
//   generalisation_bench --db /tmp/ycbv.sqlite [--hypotheses context both] [--seeds 1 2 3] [--track]
//                        [--rendered 200] [--composites 100] [--cast-step 1] [--split reporting|choosing] [--threads 2]
//                        [--figures bench/figures] [--results bench/RESULTS.md] [the settings flags of `recognize`]
// Every setting of the recognizer's table (recognize/recognizer_settings.h) is a flag, as in `ecvpose recognize`, and
// applies to every run; --hypotheses and --seeds take several values, one run each, and --track adds tracking runs.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_util.h"
#include "core/error.h"
#include "generalisation_set.h"
#include "modeldb/model_library.h"
#include "recognize/evaluation.h"
#include "recognize/recognition_json.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"
#include "recognize/settings_flags.h"

namespace ecv::bench {
namespace {

// What one configuration of the recognizer did on every frame of the set.
struct Run {
  std::string label;
  std::vector<FrameEvaluation> evaluations;        // per frame
  std::vector<std::vector<Detection>> detections;  // per frame
  std::vector<std::vector<JudgedPose>> judged;     // per frame, with RecognizerOptions::keep_judged
  std::vector<std::vector<Detection>> verified;    // per frame, with RecognizerOptions::keep_verified
  std::vector<double> ms;                          // per frame
  std::vector<int> frame_index;                    // into the set's frames
};

struct Counts {
  int correct = 0, present = 0, false_positives = 0, frames = 0;
  void Add(const FrameEvaluation& evaluation) {
    for (const ObjectEvaluation& object : evaluation.objects) {
      correct += object.correct ? 1 : 0;
      ++present;
    }
    false_positives += evaluation.false_positives;
    ++frames;
  }
  std::string Cell() const {
    return std::to_string(correct) + " / " + std::to_string(present) + " (" +
           Fixed(100.0 * correct / std::max(present, 1), 0) + " %), " +
           Fixed(static_cast<double>(false_positives) / std::max(frames, 1), 2);
  }
};

// With `stream_options.track`: along the streams only, each a stream of its own.
Run RunRecognizer(const ModelLibrary& library, const RecognizerOptions& options, const StreamOptions& stream_options,
                  const std::vector<BenchFrame>& frames, const std::vector<EvalModel>& models,
                  const std::string& label) {
  const bool track = stream_options.track;
  Recognizer recognizer(library, options);
  RecognitionStream stream(recognizer, stream_options);
  Run run{label, {}, {}, {}, {}, {}, {}};
  for (size_t i = 0; i < frames.size(); ++i) {
    if (track && frames[i].stream.empty()) continue;  // tracking runs over the streams only
    if (!track || i == 0 || frames[i].stream != frames[i - 1].stream) stream.Reset();
    const RecognitionResult result = stream.Next(frames[i].frame.rgbd);
    run.evaluations.push_back(EvaluateFrame(frames[i].name, result.detections, frames[i].frame.ground_truth, models));
    run.detections.push_back(result.detections);
    run.judged.push_back(result.judged);
    run.verified.push_back(result.verified);
    run.ms.push_back(result.timings_ms.at("total"));
    run.frame_index.push_back(static_cast<int>(i));
    Counts counts;
    counts.Add(run.evaluations.back());
    std::cerr << label << " [" << i + 1 << "/" << frames.size() << "] " << frames[i].name << ": " << counts.correct
              << " of " << counts.present << ", " << counts.false_positives << " false, " << Fixed(run.ms.back(), 0)
              << " ms\n";
  }
  return run;
}

// A markdown table's heading: `first` columns, then one per run.
std::string RunColumnsHeading(const std::vector<std::string>& first, const std::string& first_align,
                              const std::vector<Run>& runs) {
  std::ostringstream out;
  out << '|';
  for (const std::string& column : first) out << ' ' << column << " |";
  for (const Run& run : runs) out << ' ' << run.label << " |";
  out << "\n|" << first_align;
  for (size_t i = 0; i < runs.size(); ++i) out << "---|";
  out << '\n';
  return out.str();
}

// Found / present, recall and false positives per frame, per set and condition (and per video of the casts).
std::string ConditionTable(const std::vector<Run>& runs, const std::vector<BenchFrame>& frames) {
  std::vector<std::string> rows;
  std::map<std::string, std::map<std::string, Counts>> cells;  // row -> run -> counts
  for (const Run& run : runs) {
    for (size_t k = 0; k < run.evaluations.size(); ++k) {
      const BenchFrame& frame = frames[static_cast<size_t>(run.frame_index[k])];
      std::vector<std::string> keys = {frame.set + ": all", frame.set + ": " + frame.condition};
      if (frame.set == "cast") keys.push_back("cast: video " + frame.stream.substr(0, frame.stream.find(',')));
      keys.push_back("all sets");
      for (const std::string& key : keys) {
        if (std::find(rows.begin(), rows.end(), key) == rows.end()) rows.push_back(key);
        cells[key][run.label].Add(run.evaluations[k]);
      }
    }
  }
  std::sort(rows.begin(), rows.end(), [](const std::string& a, const std::string& b) {
    const auto rank = [](const std::string& s) { return s == "all sets" ? 1 : 0; };
    return std::make_pair(rank(a), a) < std::make_pair(rank(b), b);
  });
  std::ostringstream out;
  out << RunColumnsHeading({"set: condition", "frames"}, "---|---:|", runs);
  for (const std::string& row : rows) {
    int frame_count = 0;
    for (const auto& [label, counts] : cells[row]) frame_count = std::max(frame_count, counts.frames);
    out << "| " << row << " | " << frame_count << " |";
    for (const Run& run : runs) {
      const auto cell = cells[row].find(run.label);
      out << ' ' << (cell == cells[row].end() ? std::string("-") : cell->second.Cell()) << " |";
    }
    out << '\n';
  }
  out << "| median ms per frame | |";
  for (const Run& run : runs) out << ' ' << Fixed(Median(run.ms), 0) << " |";
  out << "\n\nCells: found / present (recall), false positives per frame.\n";
  return out.str();
}

// Per object and set: found / present, for each run.
std::string ObjectTable(const std::vector<Run>& runs, const std::vector<BenchFrame>& frames) {
  std::map<std::string, std::map<std::string, std::map<std::string, Counts>>> cells;  // object -> run -> set
  std::set<std::string> sets;
  for (const Run& run : runs) {
    for (size_t k = 0; k < run.evaluations.size(); ++k) {
      const std::string& set = frames[static_cast<size_t>(run.frame_index[k])].set;
      sets.insert(set);
      for (const ObjectEvaluation& object : run.evaluations[k].objects) {
        Counts& counts = cells[object.model][run.label][set];
        counts.correct += object.correct ? 1 : 0;
        ++counts.present;
      }
    }
  }
  std::ostringstream out;
  out << RunColumnsHeading({"object"}, "---|", runs);
  for (const auto& [object, per_run] : cells) {
    out << "| " << object << " |";
    for (const Run& run : runs) {
      std::string cell;
      for (const std::string& set : sets) {
        const auto counts = per_run.find(run.label);
        if (counts == per_run.end() || counts->second.count(set) == 0) continue;
        const Counts& c = counts->second.at(set);
        cell += (cell.empty() ? "" : " · ") + set.substr(0, 4) + " " + std::to_string(c.correct) + "/" +
                std::to_string(c.present);
      }
      out << ' ' << cell << " |";
    }
    out << '\n';
  }
  return out.str();
}

// Where the false positives lie, and how plain sides and grey objects fare: the failures of issue 55.
std::string FailureTable(const std::vector<Run>& runs, const std::vector<BenchFrame>& frames,
                         const std::set<std::string>& library_models, const std::set<std::string>& grey) {
  std::ostringstream out;
  out << "| run | false positives | on another library object | on an object of no library | same object, wrong "
         "pose | elsewhere | followed from an earlier frame | plain sides found | printed sides found | grey objects "
         "found |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Run& run : runs) {
    int total = 0, on_library = 0, on_other = 0, same = 0, elsewhere = 0, followed = 0;
    Counts plain, printed, grey_counts;
    for (size_t k = 0; k < run.evaluations.size(); ++k) {
      const BenchFrame& frame = frames[static_cast<size_t>(run.frame_index[k])];
      const FrameEvaluation& evaluation = run.evaluations[k];
      for (const std::string& model : evaluation.false_positive_models) {
        ++total;
        const auto detection = std::find_if(run.detections[k].begin(), run.detections[k].end(),
                                            [&](const Detection& d) { return d.model == model; });
        if (detection == run.detections[k].end()) continue;
        followed += detection->tracked ? 1 : 0;
        const Eigen::Vector3d at = detection->camera_from_object.translation();
        const SceneObjectInfo* nearest = nullptr;
        for (const SceneObjectInfo& object : frame.objects) {
          if (nearest == nullptr || (object.position - at).norm() < (nearest->position - at).norm()) nearest = &object;
        }
        if (nearest != nullptr && nearest->name == model && (nearest->position - at).norm() < 0.1) {
          ++same;
        } else if (nearest != nullptr && (nearest->position - at).norm() < 0.06) {
          ++(library_models.count(nearest->name) != 0 ? on_library : on_other);
        } else {
          ++elsewhere;
        }
      }
      // Per ground-truth object of the library, in the order EvaluateFrame keeps them.
      size_t o = 0;
      for (size_t g = 0; g < frame.frame.ground_truth.size() && o < evaluation.objects.size(); ++g) {
        if (library_models.count(frame.frame.ground_truth[g].object_name) == 0) continue;
        const ObjectEvaluation& object = evaluation.objects[o++];
        Counts& counts = grey.count(object.model) != 0 ? grey_counts : frame.plain[g] ? plain : printed;
        counts.correct += object.correct ? 1 : 0;
        ++counts.present;
      }
    }
    const auto share = [](const Counts& c) {
      return c.present == 0 ? std::string("-")
                            : std::to_string(c.correct) + " / " + std::to_string(c.present) + " (" +
                                  Fixed(100.0 * c.correct / c.present, 0) + " %)";
    };
    out << "| " << run.label << " | " << total << " | " << on_library << " | " << on_other << " | " << same << " | "
        << elsewhere << " | " << followed << " | " << share(plain) << " | " << share(printed) << " | "
        << share(grey_counts) << " |\n";
  }
  return out.str();
}

// FNV-1a over every detection (frame, model, position to the millimetre): two runs with the same digest found the
// same.
std::string Digest(const Run& run) {
  uint64_t hash = 1469598103934665603ULL;
  const auto add = [&](const std::string& text) {
    for (const char c : text) hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  };
  for (size_t k = 0; k < run.detections.size(); ++k) {
    add(run.evaluations[k].frame);
    for (const Detection& detection : run.detections[k]) {
      const Eigen::Vector3d t = detection.camera_from_object.translation() * 1000.0;
      add(detection.model + Fixed(t.x(), 0) + Fixed(t.y(), 0) + Fixed(t.z(), 0));
    }
  }
  std::ostringstream out;
  out << std::hex << hash;
  return out.str();
}

// One picture per set: the first frame of each condition with the run's detections drawn, captioned.
void WriteFigures(const ModelLibrary& library, const Run& run, const std::vector<BenchFrame>& frames,
                  const std::string& folder, const std::string& tag, const std::string& format) {
  Recognizer recognizer(library);
  std::map<std::string, std::vector<cv::Mat>> panels;  // set -> panels
  std::set<std::string> drawn;
  for (size_t k = 0; k < run.evaluations.size(); ++k) {
    const BenchFrame& frame = frames[static_cast<size_t>(run.frame_index[k])];
    if (!drawn.insert(frame.set + frame.condition).second) continue;
    cv::Mat panel = recognizer.DrawDetections(frame.frame.rgbd, run.detections[k]);
    cv::rectangle(panel, cv::Rect(0, 0, panel.cols, 56), cv::Scalar(0, 0, 0), cv::FILLED);
    Counts counts;
    counts.Add(run.evaluations[k]);
    cv::putText(panel, frame.set + ": " + frame.condition, cv::Point(8, 22), cv::FONT_HERSHEY_SIMPLEX, 0.6,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    cv::putText(panel,
                std::to_string(counts.correct) + " of " + std::to_string(counts.present) + " found, " +
                    std::to_string(counts.false_positives) + " false",
                cv::Point(8, 46), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    panels[frame.set].push_back(panel);
  }
  for (auto& [set, images] : panels) {
    while (images.size() % 3 != 0) images.push_back(cv::Mat::zeros(images.front().size(), images.front().type()));
    std::vector<cv::Mat> rows;
    for (size_t i = 0; i < images.size(); i += 3) {
      cv::Mat row;
      cv::hconcat(std::vector<cv::Mat>{images[i], images[i + 1], images[i + 2]}, row);
      rows.push_back(row);
    }
    cv::Mat figure, bgr;
    cv::vconcat(rows, figure);
    cv::resize(figure, figure, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    cv::cvtColor(figure, bgr, cv::COLOR_RGB2BGR);
    const std::string path = folder + "/generalisation_" + set + "_" + tag + "." + format;
    cv::imwrite(path, bgr, {cv::IMWRITE_JPEG_QUALITY, 80});
    std::cerr << "wrote " << path << '\n';
  }
}

struct Settings {
  std::string db, data = ECV_DATA_DIR, results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md",
                  figures = std::string(ECV_SOURCE_DIR) + "/bench/figures", split = "reporting", figure_format = "jpg";
  std::vector<std::string> hypotheses;  // empty: the table's default
  std::vector<uint64_t> seeds;          // empty: --seed
  int rendered = 200, composites = 100, cast_step = 1;
  bool track = false;
  RecognizerSettings recognizer;  // every run: the settings table's flags
  std::string detections;         // JSON Lines of every run's detections, when given
  std::string judged;             // JSON Lines of every pose the acceptance judged, labelled, when given
  std::string verified;           // JSON Lines of each present object's verified poses, counted, when given
};

// One line per frame of `run`: its set, condition and name, the detections with their verification terms, and
// which objects were found and which detections were false.
void AppendDetections(const std::string& path, const Run& run, const std::vector<BenchFrame>& frames) {
  std::ofstream out(path, std::ios::app);
  if (!out) ThrowInputError(path, "--detections", "a file that can be written");
  for (size_t k = 0; k < run.evaluations.size(); ++k) {
    const BenchFrame& frame = frames[static_cast<size_t>(run.frame_index[k])];
    RecognitionResult result;
    result.detections = run.detections[k];
    nlohmann::json found = nlohmann::json::object();
    nlohmann::json errors = nlohmann::json::array();  // of the detection each object took, or its best wrong one
    for (const ObjectEvaluation& object : run.evaluations[k].objects) {
      found[object.model] = object.correct;
      if (!object.detected) continue;
      errors.push_back({{"model", object.model},
                        {"rotation_deg", object.error.rotation_deg},
                        {"translation_mm", object.error.translation_mm},
                        {"add_mm", 1000.0 * object.error.add_m},
                        {"adds_mm", 1000.0 * object.error.adds_m},
                        {"diameter_mm", 1000.0 * object.diameter_m}});
    }
    out << nlohmann::json{{"run", run.label},
                          {"set", frame.set},
                          {"condition", frame.condition},
                          {"frame", frame.name},
                          {"found", found},
                          {"errors", errors},
                          {"false_positives", run.evaluations[k].false_positive_models},
                          {"detections", RecognitionToJson(result)["detections"]}}
               .dump()
        << '\n';
  }
}

// How far `detection` lies from the nearest ground-truth instance of its model: ADD (ADD-S for a symmetric model)
// over the diameter; infinity when the frame holds none.
double ErrorOverDiameter(const Detection& detection, const LoadedFrame& frame, const std::vector<EvalModel>& models) {
  const auto model =
      std::find_if(models.begin(), models.end(), [&](const EvalModel& m) { return m.name == detection.model; });
  double best = std::numeric_limits<double>::infinity();
  if (model == models.end()) return best;
  for (const GroundTruth& truth : frame.ground_truth) {
    if (truth.object_name != detection.model) continue;
    const PoseError error = ComputePoseError(model->points, detection.camera_from_object, truth.camera_from_object);
    best = std::min(best, (model->symmetric ? error.adds_m : error.add_m) / model->diameter_m);
  }
  return best;
}

// One line per pose the acceptance judged in `run`: the frame, the pose's evidence (the detection's JSON fields),
// the verdict, and the label: right when ADD (ADD-S) < 0.1 x diameter, the error, the model's properties.
void AppendJudged(const std::string& path, const Run& run, const std::vector<BenchFrame>& frames,
                  const std::vector<EvalModel>& models, const std::set<std::string>& grey) {
  std::ofstream out(path, std::ios::app);
  if (!out) ThrowInputError(path, "--judged", "a file that can be written");
  for (size_t k = 0; k < run.judged.size(); ++k) {
    const BenchFrame& frame = frames[static_cast<size_t>(run.frame_index[k])];
    RecognitionResult result;
    result.judged = run.judged[k];
    const nlohmann::json records = RecognitionToJson(result)["judged"];
    for (size_t j = 0; j < run.judged[k].size(); ++j) {
      const Detection& detection = run.judged[k][j].detection;
      const double error = ErrorOverDiameter(detection, frame.frame, models);
      nlohmann::json line = {{"run", run.label},
                             {"set", frame.set},
                             {"condition", frame.condition},
                             {"frame", frame.name},
                             {"right", error < 0.1},
                             {"error_over_diameter", std::isfinite(error) ? error : -1.0},
                             {"grey", grey.count(detection.model) > 0}};
      line.update(records[j]);
      out << line.dump() << '\n';
    }
  }
}

// One line per object of each frame of `run` (a model of the library in the frame's ground truth): how many of its
// poses were verified and how many of them were right, the best score of each kind, and whether it was found. An
// object missed with a right pose verified was lost in the choice among poses; one without, by the hypotheses.
void AppendVerified(const std::string& path, const Run& run, const std::vector<BenchFrame>& frames,
                    const std::vector<EvalModel>& models) {
  std::ofstream out(path, std::ios::app);
  if (!out) ThrowInputError(path, "--verified", "a file that can be written");
  for (size_t k = 0; k < run.verified.size(); ++k) {
    const BenchFrame& frame = frames[static_cast<size_t>(run.frame_index[k])];
    for (const ObjectEvaluation& object : run.evaluations[k].objects) {
      int verified = 0, right = 0;
      double best_right = 0.0, best_wrong = 0.0;
      for (const Detection& pose : run.verified[k]) {
        if (pose.model != object.model) continue;
        ++verified;
        const bool is_right = ErrorOverDiameter(pose, frame.frame, models) < 0.1;
        right += is_right ? 1 : 0;
        double& best = is_right ? best_right : best_wrong;
        best = std::max(best, pose.score);
      }
      out << nlohmann::json{{"run", run.label},
                            {"set", frame.set},
                            {"condition", frame.condition},
                            {"frame", frame.name},
                            {"model", object.model},
                            {"found", object.correct},
                            {"verified", verified},
                            {"right", right},
                            {"best_right_score", best_right},
                            {"best_wrong_score", best_wrong}}
                 .dump()
          << '\n';
    }
  }
}

int Main(int argc, char** argv) {
  CLI::App app("Recognition on the generalisation set: rendered scenes, composites of real frames, cast light");
  Settings s;
  app.add_option("--db", s.db, "Model library (scripts/build_ycbv_library)")->required()->check(CLI::ExistingFile);
  app.add_option("--data", s.data, "The shared data folder (ycbv_subset, lmo_subset)");
  AddSettingValues(app, "hypotheses", &s.hypotheses, "Sources of pose hypotheses, one run each (context, ppf, both)");
  app.add_option("--seeds", s.seeds, "RANSAC seeds, one run each (default: --seed)");
  app.add_option("--rendered", s.rendered, "Rendered scenes")->check(CLI::NonNegativeNumber);
  app.add_option("--composites", s.composites, "Composites of real frames")->check(CLI::NonNegativeNumber);
  app.add_option("--split", s.split, "Which half: reporting (figures to quote) or choosing (to choose settings on)")
      ->check(CLI::IsMember({"reporting", "choosing"}));
  app.add_option("--cast-step", s.cast_step, "Every n-th real frame of each video under each cast")
      ->check(AtLeastOne());
  app.add_flag("--track", s.track,
               "Also track along the cast videos (recognize --track; with --search-every, searching every N-th frame)");
  app.add_option("--figures", s.figures, "Folder of the pictures (one per set)");
  app.add_option("--figure-format", s.figure_format, "Picture format")->check(CLI::IsMember({"jpg", "png"}));
  app.add_option("--results", s.results, "Markdown file the report goes to");
  app.add_option("--detections", s.detections,
                 "JSON Lines file every run's detections are appended to, per frame with their verification terms "
                 "and which were right, with each found or wrongly placed object's pose errors");
  app.add_option("--judged", s.judged,
                 "JSON Lines file every pose the acceptance judged is appended to, one per line, with its evidence, "
                 "the verdict and whether it was right (ADD, ADD-S for symmetric models, < 0.1 x diameter)");
  app.add_option("--verified", s.verified,
                 "JSON Lines file each present object's verified poses are counted into, one object of a frame per "
                 "line: how many, how many right, the best score of each, found or not");
  s.recognizer.options.threads = 2;  // the benchmark machine's cores
  AddSettingFlags(app, &s.recognizer, {"hypotheses", "track", "search-beside"},
                  "Settings of every run (as `ecvpose recognize` takes them)");
  if (const auto exit_code = ParseCommandLine(app, argc, argv)) return *exit_code;
  if (s.hypotheses.empty()) s.hypotheses = {HypothesisSourceName(s.recognizer.options.point_pairs.source)};
  if (s.seeds.empty()) s.seeds = {s.recognizer.options.ransac.seed};
  const SplitHalf half = s.split == "choosing" ? SplitHalf::kChoosing : SplitHalf::kReporting;

  const auto start = std::chrono::steady_clock::now();
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(s.db, load);
  const std::vector<EvalModel> models = EvalModels(library);
  std::set<std::string> library_models;
  for (const EvalModel& model : models) library_models.insert(model.name);

  // The set: every real frame is a source of composites; the choosing videos' frames give the backdrops.
  std::vector<SourceFrame> sources;
  std::vector<std::string> backdrop_frames;
  const std::vector<std::string> choosing = SplitVideos(SplitHalf::kChoosing);
  for (const std::string& prefix : YcbvFramePrefixes(s.data)) {
    sources.push_back(LoadSourceFrame(prefix));
    for (const std::string& video : choosing) {
      if (prefix.find("/" + video + "/") != std::string::npos) backdrop_frames.push_back(prefix);
    }
  }
  const std::vector<SceneAsset> assets = LoadSceneAssets(s.data);
  std::set<std::string> grey;
  for (const SceneAsset& asset : assets) {
    if (asset.repaint) grey.insert(asset.name);
  }
  Renderer renderer;
  std::vector<MeshId> mesh_ids;
  for (const SceneAsset& asset : assets) mesh_ids.push_back(renderer.AddMesh(asset.mesh));
  std::vector<BenchFrame> frames =
      RenderedFrames(renderer, assets, mesh_ids, LoadBackdrops(backdrop_frames), half, s.rendered);
  for (BenchFrame& frame : CompositeFrames(sources, half, s.composites)) frames.push_back(std::move(frame));
  for (BenchFrame& frame : CastFrames(sources, half, s.cast_step)) frames.push_back(std::move(frame));
  const double generate_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // The section is written after every run, so that a long run reports what it has measured so far.
  const std::string tag = std::to_string(library.models().size()) + "models";
  const int planned = static_cast<int>(s.hypotheses.size() * s.seeds.size()) * (s.track ? 2 : 1);
  std::vector<Run> runs;
  const auto report = [&] {
    const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::ostringstream text;
    std::map<std::string, int> per_set;
    for (const BenchFrame& frame : frames) ++per_set[frame.set];
    text << "The " << SplitHalfName(half) << " half: " << per_set["rendered"] << " rendered scenes, "
         << per_set["composite"] << " composites, " << per_set["cast"] << " cast frames; library of "
         << library.models().size() << " models (`" << s.db << "`), " << s.recognizer.options.threads
         << " threads. Generating took " << Fixed(generate_s, 0) << " s, " << runs.size() << " of " << planned
         << " runs " << Fixed(total_s / 60.0, 1) << " min in all.\n\n"
         << ConditionTable(runs, frames) << "\nWhere the false positives lie (nearest object within 6 cm; the "
         << "same object within 10 cm), and the objects by side: plain when the mean grey gradient over the "
         << "visible pixels is under " << kPlainGradient << " (grey objects counted apart).\n\n"
         << FailureTable(runs, frames, library_models, grey) << "\nPer object and set (rend, comp, cast):\n\n"
         << ObjectTable(runs, frames) << "\nDetections digest (equal digests: the same detections):";
    for (const Run& run : runs) text << " " << run.label << " `" << Digest(run) << "`;";
    text << "\n\nPictures: `bench/figures/generalisation_<set>_" << tag << ".jpg`.\n";
    ReportSection(s.results,
                  "Generalisation set (" + std::string(SplitHalfName(half)) + " half, " +
                      std::to_string(library.models().size()) + " models)",
                  CommandLine(argc, argv), text.str());
  };
  const auto add_run = [&](Run run) {
    if (!s.detections.empty()) AppendDetections(s.detections, run, frames);
    if (!s.judged.empty()) AppendJudged(s.judged, run, frames, models, grey);
    if (!s.verified.empty()) AppendVerified(s.verified, run, frames, models);
    runs.push_back(std::move(run));
    if (runs.size() == 1 && !s.figures.empty())
      WriteFigures(library, runs.front(), frames, s.figures, tag, s.figure_format);
    report();
  };
  for (const std::string& source : s.hypotheses) {
    for (const uint64_t seed : s.seeds) {
      RecognizerOptions options = s.recognizer.options;
      options.keep_judged = !s.judged.empty();
      options.keep_verified = !s.verified.empty();
      options.point_pairs.source = ParseHypothesisSource(source, "--hypotheses");
      options.ransac.seed = seed;
      const std::string label = source + ", seed " + std::to_string(seed);
      add_run(RunRecognizer(library, options, {false, 1}, frames, models, label));
      if (s.track) {
        const int every = s.recognizer.stream.search_every;
        const std::string tracking =
            label + ", --track" + (every > 1 ? " --search-every " + std::to_string(every) : "");
        add_run(RunRecognizer(library, options, {true, every}, frames, models, tracking));
      }
    }
  }
  return 0;
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  try {
    return ecv::bench::Main(argc, argv);
  } catch (const std::exception& error) {
    std::cerr << "generalisation_bench: " << error.what() << '\n';
    return 1;
  }
}
