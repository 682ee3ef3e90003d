// ransac_bench: the paper's Table I (prerejective against standard RANSAC at a fixed number of iterations)
// and the peers (PCL's SampleConsensusPrerejective, Open3D's correspondence RANSAC with its edge-length
// checker), all fed the same ECV correspondences of two view pairs: a rendered wide-baseline pair and the real
// YCB-Video pair moved by 30 degrees (issue 6, "Benchmarks"). Prints markdown tables and puts them in
// bench/RESULTS.md with the date, the machine and the command, in place of the previous run's section.
//
//   ransac_bench [--runs N] [--standard-runs N] [--paper-runs N] [--iterations K] [--results FILE] [--no-peers]
//                [--data DIR] [--python EXE] [--scratch DIR] [--note TEXT]
//
// Open3D runs through bench/ransac_open3d.py under EXE (default /usr/bin/python3); without Open3D the bench
// says so and goes on. Install it with `apt-get install -y python3-open3d` (Debian 12, Open3D 0.16).

#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <numeric>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "bench_util.h"
#include "core/error.h"
#include "core/point_index.h"
#include "core/pose.h"
#include "core/timing.h"
#include "ransac_pairs.h"
#include "ransac_peer_open3d.h"
#include "ransac_peer_pcl.h"
#include "registration/ransac.h"

namespace ecv::bench {
namespace {

constexpr double kDegree = M_PI / 180.0;
constexpr double kInlierDistance = 0.01;      // eps, metres
constexpr double kRequiredInliers = 0.1;      // of view A's points (scene registration, paper Sect. IV-B)
constexpr double kPolygonThreshold = 0.25;    // t_poly; peers get the similarity 1 - t_poly
constexpr double kSuccessTranslation = 0.01;  // metres, at the centre of view A's points
constexpr double kSuccessRotationDeg = 2.0;

struct Settings {
  int runs = 100;
  int standard_runs = 100;  // standard RANSAC is slow: fewer runs allowed for it alone
  int paper_runs = 10;      // runs of both variants without preverification (the paper's algorithm); 0: none
  int iterations = 5000;
  bool peers = true;
  std::string results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  std::string data = ECV_DATA_DIR;
  std::string python = "/usr/bin/python3";
  std::string scratch;  // where the Open3D input goes; a temporary directory (removed) when empty
  std::string note;     // free text for the report (e.g. the state of the tree)
  std::string command;
};

// One run of any method.
struct Run {
  bool returned = false;  // the method reports a pose
  Eigen::Isometry3d b_from_a = Eigen::Isometry3d::Identity();
  double time_ms = 0.0, cpu_ms = 0.0;  // wall and process CPU time
  int scored = -1;                     // hypotheses whose inliers were counted (ours only)
};

// Runs of one method on one pair, summarised.
struct Summary {
  std::string method, threads, runs_text;
  int runs = 0, returned = 0, successes = 0;
  double mean_ms = 0.0, median_ms = 0.0, mean_cpu_ms = 0.0, mean_fit_mm = 0.0, mean_scored = -1.0;
  double median_rotation_deg = 0.0, median_translation_mm = 0.0;  // over the successes
};

// RansacOptions::threads and ::preverify where the RANSAC has them (the lead adds them in parallel with this
// bench): detected at compile time, so the bench builds either way.
template <typename Options, typename = void>
struct HasThreads : std::false_type {};
template <typename Options>
struct HasThreads<Options, std::void_t<decltype(std::declval<Options&>().threads)>> : std::true_type {};
template <typename Options, typename = void>
struct HasPreverify : std::false_type {};
template <typename Options>
struct HasPreverify<Options, std::void_t<decltype(std::declval<Options&>().preverify)>> : std::true_type {};
constexpr bool kOursThreaded = HasThreads<RansacOptions>::value;
constexpr bool kOursPreverifies = HasPreverify<RansacOptions>::value;

// One configuration of our RANSAC.
struct Variant {
  bool prerejective = true;  // polygon test on (t_poly) or off (standard RANSAC)
  int threads = 1;
  bool preverify = true;  // false: every object point is checked for each pose, as in the paper
  int runs = 100;         // seeds 1..runs
};

template <typename Options>
void Configure(const Variant& variant, Options* options) {
  if constexpr (HasThreads<Options>::value) options->threads = variant.threads;
  if constexpr (HasPreverify<Options>::value) options->preverify = variant.preverify;
}

// Mean distance (metres) of A's points within eps of their nearest B point under `b_from_a`; 0 if none.
double FitError(const RegistrationPair& pair, const PointIndex& b_index, const Eigen::Isometry3d& b_from_a) {
  const Eigen::Isometry3f transform = b_from_a.cast<float>();
  double sum = 0.0;
  int inliers = 0;
  for (const Eigen::Vector3f& point : pair.a_points) {
    const float squared = b_index.Nearest(transform * point).second;
    if (squared > kInlierDistance * kInlierDistance) continue;
    sum += std::sqrt(static_cast<double>(squared));
    ++inliers;
  }
  return inliers > 0 ? sum / inliers : 0.0;
}

Summary Summarise(const std::string& method, const std::string& threads, const RegistrationPair& pair,
                  const std::vector<Run>& runs) {
  Summary summary{method, threads, std::to_string(runs.size())};
  summary.runs = static_cast<int>(runs.size());
  const PointIndex b_index(pair.b_points);
  std::vector<double> times, rotations, translations;
  double fit_sum = 0.0, scored_sum = 0.0, cpu_sum = 0.0;
  for (const Run& run : runs) {
    times.push_back(run.time_ms);
    cpu_sum += run.cpu_ms;
    scored_sum += run.scored;
    if (!run.returned) continue;
    ++summary.returned;
    fit_sum += FitError(pair, b_index, run.b_from_a);
    const double rotation = RotationAngle(run.b_from_a, pair.b_from_a) / kDegree;
    const double translation = (run.b_from_a * pair.centre_a - pair.b_from_a * pair.centre_a).norm();
    if (rotation < kSuccessRotationDeg && translation < kSuccessTranslation) {
      ++summary.successes;
      rotations.push_back(rotation);
      translations.push_back(1000.0 * translation);
    }
  }
  if (runs.empty()) return summary;
  summary.mean_ms = std::accumulate(times.begin(), times.end(), 0.0) / static_cast<double>(times.size());
  summary.median_ms = Median(times);
  summary.mean_cpu_ms = cpu_sum / static_cast<double>(runs.size());
  if (summary.returned > 0) summary.mean_fit_mm = 1000.0 * fit_sum / summary.returned;
  if (runs.front().scored >= 0) summary.mean_scored = scored_sum / static_cast<double>(runs.size());
  summary.median_rotation_deg = Median(rotations);
  summary.median_translation_mm = Median(translations);
  return summary;
}

std::string Percent(int part, int whole) {
  return whole > 0 ? Fixed(100.0 * part / whole, 0) : "-";
}

// Our RANSAC, seeds 1..variant.runs.
std::vector<Run> RunOurs(const RegistrationPair& pair, const Settings& settings, const Variant& variant) {
  std::vector<Run> result;
  for (int seed = 1; seed <= variant.runs; ++seed) {
    RansacOptions options;
    options.polygon_threshold = variant.prerejective ? kPolygonThreshold : 0.0;
    options.inlier_threshold_m = kInlierDistance;
    options.required_inlier_fraction = kRequiredInliers;
    options.max_iterations = settings.iterations;
    options.seed = static_cast<uint64_t>(seed);
    Configure(variant, &options);
    const auto start = Clock::now();
    const double cpu_start = ProcessCpuMilliseconds();
    const RansacResult ransac = EstimatePoseRansac(pair.a_points, pair.b_points, pair.correspondences, options);
    result.push_back({ransac.success, ransac.scene_from_object, MillisecondsSince(start),
                      ProcessCpuMilliseconds() - cpu_start, ransac.iterations - ransac.rejected_by_polygon});
    std::cerr << "\r  " << (variant.prerejective ? "prerejective" : "standard") << ", " << variant.threads
              << " thread(s)" << (variant.preverify ? "" : ", no preverification") << ": run " << seed << "/"
              << variant.runs << std::flush;
  }
  std::cerr << '\n';
  return result;
}

std::vector<Run> RunPcl(const RegistrationPair& pair, const Settings& settings) {
  PclPrerejectiveOptions options;
  options.max_iterations = settings.iterations;
  options.similarity_threshold = static_cast<float>(1.0 - kPolygonThreshold);
  options.max_correspondence_distance = static_cast<float>(kInlierDistance);
  options.inlier_fraction = static_cast<float>(kRequiredInliers);
  std::vector<Run> result;
  for (int seed = 1; seed <= settings.runs; ++seed) {
    const PeerPose pose =
        RunPclPrerejective(pair.a_points, pair.b_points, pair.correspondences, options, static_cast<unsigned>(seed));
    result.push_back({pose.returned, pose.b_from_a, pose.time_ms, pose.cpu_ms});
    std::cerr << "\r  PCL: run " << seed << "/" << settings.runs << std::flush;
  }
  std::cerr << '\n';
  return result;
}

// Open3D through ransac_open3d.py on the input in `directory`; empty when it did not run (reason in `*problem`).
std::vector<Run> RunOpen3d(const std::filesystem::path& directory, const Settings& settings, int threads,
                           double confidence, std::string* problem) {
  Open3dRansacOptions options;
  options.python = settings.python;
  options.script = std::string(ECV_SOURCE_DIR) + "/bench/ransac_open3d.py";
  options.runs = settings.runs;
  options.max_iterations = settings.iterations;
  options.confidence = confidence;
  options.max_correspondence_distance = kInlierDistance;
  options.similarity_threshold = 1.0 - kPolygonThreshold;
  options.threads = threads;
  std::cerr << "  Open3D, " << threads << " thread(s), confidence " << confidence << "...\n";
  std::vector<Run> runs;
  for (const PeerPose& pose : RunOpen3dRansac(directory, options, problem)) {
    runs.push_back({pose.returned, pose.b_from_a, pose.time_ms, pose.cpu_ms});
  }
  return runs;
}

std::string PairLine(const RegistrationPair& pair) {
  const int n = static_cast<int>(pair.correspondences.size());
  return "- **" + pair.name + "**: " + pair.description + ". " + std::to_string(pair.primitives_a) + " and " +
         std::to_string(pair.primitives_b) + " primitives; " + std::to_string(n) + " correspondences, " +
         std::to_string(pair.true_correspondences) + " true within 1 cm (" + Percent(pair.true_correspondences, n) +
         " %); primitives, descriptors and matching of both frames " + Fixed(pair.extraction_ms, 0) + " ms.\n";
}

std::string TableOneRows(const RegistrationPair& pair, const Summary& prerejective, const Summary& standard,
                         const std::string& scoring) {
  auto ratio = [](double numerator, double denominator) {
    return denominator > 0.0 ? Fixed(numerator / denominator, 1) + "x" : std::string("-");
  };
  auto row = [&](const std::string& variant, const Summary& s, const std::string& speedup) {
    return "| " + pair.name + " | " + variant + scoring + " | " + s.threads + " | " + s.runs_text + " | " +
           Fixed(s.mean_ms / 1000.0, 3) + " | " + Fixed(s.median_ms / 1000.0, 3) + " | " +
           Fixed(s.mean_cpu_ms / 1000.0, 3) + " | " + Fixed(s.mean_scored, 0) + " | " + Percent(s.successes, s.runs) +
           " | " + Fixed(s.mean_fit_mm, 2) + " | " + speedup + " |\n";
  };
  return row("prerejective", prerejective,
             ratio(standard.mean_ms, prerejective.mean_ms) + " / " +
                 ratio(standard.mean_cpu_ms, prerejective.mean_cpu_ms)) +
         row("standard", standard, "1x");
}

// `ours` is our prerejective RANSAC with the same number of threads (or with 1 where ours has no threads).
std::string PeerRow(const RegistrationPair& pair, const Summary& s, const std::string& fed, const Summary& ours) {
  auto ratio = [](double peer, double our) {
    return our > 0.0 && peer > 0.0 ? Fixed(peer / our, 2) : std::string("-");
  };
  return "| " + pair.name + " | " + s.method + " | " + s.threads + " | " + fed + " | " + s.runs_text + " | " +
         Percent(s.successes, s.runs) + " | " + Percent(s.returned, s.runs) + " | " + Fixed(s.mean_ms, 0) + " | " +
         Fixed(s.median_ms, 0) + " | " + Fixed(s.mean_cpu_ms, 0) + " | " + ratio(s.mean_ms, ours.mean_ms) + " / " +
         ratio(s.mean_cpu_ms, ours.mean_cpu_ms) + " | " + Fixed(s.mean_fit_mm, 2) + " | " +
         (s.successes > 0 ? Fixed(s.median_rotation_deg, 2) + " / " + Fixed(s.median_translation_mm, 1) : "-") + " |\n";
}

struct PairTables {
  std::string table_one, peers, notes;
};

PairTables BenchmarkPair(const RegistrationPair& pair, const Settings& settings, const std::filesystem::path& scratch) {
  std::cerr << pair.name << ": " << pair.correspondences.size() << " correspondences, " << pair.true_correspondences
            << " true\n";
  PairTables tables;
  std::vector<int> thread_counts = {1};
  if (kOursThreaded) thread_counts.push_back(2);
  std::vector<Summary> ours;
  for (const int threads : thread_counts) {
    const std::string t = std::to_string(threads);
    const Summary prerejective =
        Summarise("ours, prerejective", t, pair, RunOurs(pair, settings, {true, threads, true, settings.runs}));
    const Summary standard =
        Summarise("ours, standard", t, pair, RunOurs(pair, settings, {false, threads, true, settings.standard_runs}));
    tables.table_one += TableOneRows(pair, prerejective, standard, kOursPreverifies ? ", preverification" : "");
    ours.push_back(prerejective);
  }
  if (kOursPreverifies && settings.paper_runs > 0) {  // the paper's algorithm: every point checked
    const Summary prerejective =
        Summarise("ours, prerejective", "1", pair, RunOurs(pair, settings, {true, 1, false, settings.paper_runs}));
    const Summary standard =
        Summarise("ours, standard", "1", pair, RunOurs(pair, settings, {false, 1, false, settings.paper_runs}));
    tables.table_one += TableOneRows(pair, prerejective, standard, ", every point checked (paper)");
  }
  if (!settings.peers) return tables;
  const std::string fed = std::to_string(pair.correspondences.size()) + " corr.";
  for (const Summary& s : ours) tables.peers += PeerRow(pair, s, fed, s);
  const Summary pcl = Summarise("PCL SampleConsensusPrerejective", "1", pair, RunPcl(pair, settings));
  tables.peers += PeerRow(pair, pcl, fed + " as 1-NN features", ours.front());

  const std::filesystem::path directory = scratch / pair.name.substr(0, 4);
  WriteOpen3dInput(pair.a_points, pair.b_points, pair.correspondences, directory);
  for (const double confidence : {1.0, 0.999}) {
    for (const int threads : {1, 2}) {
      std::string problem;
      const std::vector<Run> runs = RunOpen3d(directory, settings, threads, confidence, &problem);
      if (runs.empty()) {
        tables.notes += "- " + pair.name + ": " + problem + ".\n";
        std::cerr << problem << '\n';
        return tables;
      }
      const std::string method = "Open3D, confidence " + Fixed(confidence, 3);
      const Summary& our = ours[std::min<size_t>(ours.size(), static_cast<size_t>(threads)) - 1];
      tables.peers += PeerRow(pair, Summarise(method, std::to_string(threads), pair, runs), fed, our);
    }
  }
  return tables;
}

std::string Markdown(const std::vector<RegistrationPair>& pairs, const std::vector<PairTables>& tables,
                     const Settings& settings, const std::string& load) {
  std::string text =
      "Issue 6, \"Benchmarks\". Every method gets the same points and correspondences, computed once per pair: "
      "ECV primitives of each whole frame (default EcvOptions), context descriptors (default DescriptorOptions), "
      "nearest neighbour A -> B (DescriptorMatcher, structure-specific, exact search so that the inputs repeat: "
      "FLANN's randomised kd-trees gave 5-15 % different matches from one process to the next). Points: A = the "
      "matched primitives of view A (one correspondence each), B = all primitives of view B.\n\n";
  for (const RegistrationPair& pair : pairs) text += PairLine(pair);
  text += "\nParameters: 3 samples, eps = inlier distance " + Fixed(1000.0 * kInlierDistance, 0) +
          " mm, required inliers " + Fixed(100.0 * kRequiredInliers, 0) +
          " % of A's points, t_poly = " + Fixed(kPolygonThreshold, 2) + " (peers: edge similarity " +
          Fixed(1.0 - kPolygonThreshold, 2) + "), " + std::to_string(settings.iterations) +
          " iterations (samples drawn), seeds 1..runs, other RansacOptions at their defaults. **Success**: the "
          "returned b_from_a is within " +
          Fixed(kSuccessRotationDeg, 0) + " deg (rotation angle) and " + Fixed(1000.0 * kSuccessTranslation, 0) +
          " mm (displacement of the centre of A's points) of the ground truth. Fit error: mean distance of A's points "
          "within eps of their nearest B point under the returned pose, recomputed the same way for every method "
          "(mean over the runs that returned a pose). Times per run: wall time and CPU time (all threads of the "
          "process) of the RANSAC call (ours: including its kd-tree over B; PCL: setters, its trees and align(); "
          "Open3D: the Python call only). " +
          load + "\n\n";
  if (!settings.note.empty()) text += settings.note + "\n\n";
  text +=
      "### Table I: prerejective vs standard RANSAC at " + std::to_string(settings.iterations) +
      " iterations\n\n| pair | variant | threads | runs | mean time s | median s | mean CPU s | poses scored per "
      "run | success % | mean fit error mm | speed-up (wall / CPU) |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const PairTables& t : tables) text += t.table_one;
  text += "| paper (Table I) | prerejective / standard | 1 | 100 | 0.88 / 13.68 | | | | | | 15.5x |\n\n";
  text += "\"Poses scored\": samples that passed the polygon test (all of them for standard RANSAC).";
  if (kOursPreverifies) {
    text +=
        " \"preverification\": RansacOptions::preverify (default, beyond the paper): a pose is dropped once its "
        "inlier count falls well below the required fraction, after >= 50 points checked in a fixed random "
        "order; \"every point checked\" is the paper's algorithm (preverify = false), " +
        std::to_string(settings.paper_runs) + " runs (seeds 1.." + std::to_string(settings.paper_runs) +
        ") to keep the run time down.";
  }
  if (settings.standard_runs != settings.runs) {
    text += " Standard RANSAC ran " + std::to_string(settings.standard_runs) + " runs (seeds 1.." +
            std::to_string(settings.standard_runs) + ") to keep the run time down.";
  }
  text += kOursThreaded ? "\n\n" : " Our RANSAC had no `threads` option when this was built: 1 thread only.\n\n";
  if (!settings.peers) return text;
  text +=
      "### Peers on the same correspondences\n\n"
      "| pair | method | threads | fed | runs | success % | returned a pose % | mean ms | median ms | mean CPU ms | "
      "wall / CPU time over ours | mean fit error mm | median error deg / mm (successes) |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::string notes;
  for (const PairTables& t : tables) {
    text += t.peers;
    notes += t.notes;
  }
  const std::string iterations = std::to_string(settings.iterations);
  text +=
      "\n\"wall / CPU time over ours\": the peer's mean wall time and mean CPU time over those of ours, "
      "prerejective, with the same number of threads (PCL: ours with 1 thread); above 1 = ours faster.\n\n"
      "- PCL 1.13 `pcl::SampleConsensusPrerejective<PointXYZ, PointXYZ, FPFHSignature33>`: source = A's matched "
      "points, target = B's points. PCL matches features itself, so each source feature is the index of its "
      "partner in B and each target feature its own index (first bin of an FPFHSignature33, the rest 0): the "
      "nearest target feature is exactly our correspondence. setCorrespondenceRandomness(1), setNumberOfSamples(3), "
      "setSimilarityThreshold(0.75), setMaxCorrespondenceDistance(0.01), setInlierFraction(0.1), "
      "setMaximumIterations(" +
      iterations +
      "), std::srand(seed). It samples 3 distinct source points, applies the polygon test, scores every "
      "hypothesis by nearest neighbours of all source points, keeps the lowest mean squared error among those "
      "with >= 10 % inliers, does not re-estimate on the inliers; single-threaded.\n"
      "- Open3D 0.16.1 (Debian 12 python3-open3d) `registration_ransac_based_on_correspondence` "
      "(bench/ransac_open3d.py): the same points and correspondences (Vector2iVector), max_correspondence_distance "
      "0.01, TransformationEstimationPointToPoint(False), ransac_n 3, CorrespondenceCheckerBasedOnEdgeLength(0.75), "
      "RANSACConvergenceCriteria(" +
      iterations +
      ", confidence), o3d.utility.random.seed(seed), OMP_NUM_THREADS threads. Per sample it fits first, then "
      "checks edge lengths, then scores by nearest neighbours of all source points (largest inlier count wins, "
      "RMSE breaks ties; no required fraction, so it always returns a pose, and no re-estimate). After each new "
      "best it sets the iteration limit to log(1 - confidence) / log(1 - r^3), r = share of the correspondences "
      "within the distance under that pose. Confidence 1 is meant to run all iterations, but in 0.16 a new best "
      "with r = 0 makes the limit -inf and ends the loop at once (seen in its debug log: \"Est. max k = -inf\", "
      "\"RANSAC exits after 1 validations\"; later Open3D versions guard against it); 0.999 is Open3D's default.\n";
  return text + notes;
}

// "load average 1.2 (1 min)" from /proc/loadavg.
std::string LoadAverage() {
  std::ifstream file("/proc/loadavg");
  std::string one_minute;
  file >> one_minute;
  return one_minute.empty() ? "unknown" : one_minute;
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  using namespace ecv::bench;
  Settings settings;
  settings.command = CommandLine(argc, argv);
  CLI::App app{
      "ransac_bench: prerejective against standard RANSAC at a fixed number of iterations (paper Table I), "
      "and PCL's and Open3D's RANSAC, all on the same ECV correspondences of a rendered and a real view "
      "pair.",
      "ransac_bench"};
  app.add_option("--runs", settings.runs, "Runs (seeds 1..N) per method and pair")
      ->check(AtLeastOne())
      ->capture_default_str();
  CLI::Option* standard_runs = app.add_option("--standard-runs", settings.standard_runs,
                                              "Runs of standard RANSAC, which is slow (default: as --runs)")
                                   ->check(AtLeastOne());
  app.add_option("--paper-runs", settings.paper_runs,
                 "Runs of both variants without preverification, the paper's algorithm (0: none)")
      ->check(CLI::Range(0, std::numeric_limits<int>::max()).description("NONNEGATIVE"))
      ->capture_default_str();
  app.add_option("--iterations", settings.iterations, "RANSAC iterations (samples drawn) per run")
      ->check(AtLeastOne())
      ->capture_default_str();
  app.add_option("--results", settings.results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.add_flag_callback(
      "--no-peers", [&settings] { settings.peers = false; }, "Skip the PCL and Open3D peers");
  app.add_option("--data", settings.data, "Data directory (with ycbv_subset)")->capture_default_str();
  app.add_option("--python", settings.python, "Python interpreter with Open3D for the Open3D peer")
      ->capture_default_str();
  app.add_option("--scratch", settings.scratch,
                 "Directory for the Open3D peer's input, kept (default: a temporary directory, removed)");
  app.add_option("--note", settings.note, "Free text added to the report, e.g. the state of the tree (default: none)");
  if (const auto exit_code = ParseCommandLine(app, argc, argv)) return *exit_code;
  if (standard_runs->count() == 0) settings.standard_runs = settings.runs;
  try {
    const std::string load_before = LoadAverage();
    std::cerr << "rendering the wide-baseline pair and loading the real pair...\n";
    const std::vector<RegistrationPair> pairs = {RenderedPair(settings.data, 40.0), RealPair(settings.data, 30.0)};
    const std::filesystem::path scratch =
        settings.scratch.empty() ? std::filesystem::temp_directory_path() / ("ransac_bench_" + std::to_string(getpid()))
                                 : std::filesystem::path(settings.scratch);
    std::vector<PairTables> tables;
    for (const RegistrationPair& pair : pairs) tables.push_back(BenchmarkPair(pair, settings, scratch));
    if (settings.scratch.empty()) std::filesystem::remove_all(scratch);
    const std::string load = "Load average (1 min) " + load_before + " at the start, " + LoadAverage() +
                             " at the end, on " + std::to_string(std::thread::hardware_concurrency()) +
                             " cores shared with other users: wall times grow with the load, CPU times much less.";
    ReportSection(settings.results, "ransac_bench: prerejective vs standard RANSAC (paper Table I) and peers",
                  settings.command, Markdown(pairs, tables, settings, load));
    return 0;
  } catch (const ecv::InputError& error) {
    std::cerr << "ransac_bench: " << error.what() << '\n';
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "ransac_bench: " << error.what() << '\n';
    return 1;
  }
}
