// setup_bench: what a one-frame `ecvpose recognize` pays before and beside the recognition itself, with the
// models' meshes stored in the library (schema 2) against the same library reading its mesh files (as before):
// reading the library, decoding the meshes, making the Recognizer (meshes uploaded for verification), the first
// frame, and `eval`'s model set-up; the library's size either way. The two variants alternate over the rounds and
// must give the same detections. Peer in the same run: Open3D reading the same mesh files
// (bench/mesh_load_open3d.py, skipped when Open3D is not installed).
// Replaces its section of bench/RESULTS.md (bench_util ReportSection).
//
//   scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9
//   setup_bench --db /tmp/ycbv.sqlite [--frame YCBV_PREFIX] [--rounds 3] [--threads 2] [--preselect N] [--work DIR]
//               [--results FILE]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "core/timing.h"
#include "modeldb/model_library.h"
#include "modeldb/sql.h"
#include "recognize/evaluation.h"
#include "recognize/recognizer.h"

namespace {

using ecv::Clock;
using ecv::MillisecondsSince;
using ecv::bench::Fixed;
using ecv::bench::Median;
namespace fs = std::filesystem;

struct Settings {
  std::string db;
  std::string frame = std::string(ECV_DATA_DIR) + "/ycbv_subset/Example-Scenes/0001/000001";
  int rounds = 3;
  int threads = 2;
  int preselect = ecv::RecognizerOptions().preselect.models;  // searched models per frame (lazy meshes beyond)
  std::string work = "/tmp/setup_bench";
  std::string results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  std::string command = "setup_bench";
};

// Per variant, one value per round.
struct Times {
  std::vector<double> read, meshes, setup, frame, eval, open3d;
  std::string detections;  // of the last round
};

double MegaBytes(const std::string& path) {
  return static_cast<double>(fs::file_size(path)) / 1e6;
}

// The models, scores and poses (0.1 mm) found: equal strings mean the same detections.
std::string Signature(const std::vector<ecv::Detection>& detections) {
  std::ostringstream text;
  for (const ecv::Detection& d : detections) {
    const Eigen::Vector3d t = d.camera_from_object.translation() * 1e4;
    text << d.model << ' ' << Fixed(d.score, 6) << ' ' << Fixed(t.x(), 0) << ' ' << Fixed(t.y(), 0) << ' '
         << Fixed(t.z(), 0) << '\n';
  }
  return text.str();
}

// Open3D's wall time for reading every mesh file of `library`, ms; negative when it could not run.
double Open3dMeshLoadMs(const ecv::ModelLibrary& library) {
  std::string command = "/usr/bin/python3 " + std::string(ECV_SOURCE_DIR) + "/bench/mesh_load_open3d.py";
  for (const ecv::LibraryModel& model : library.models()) command += " '" + model.record.mesh_path + "'";
  FILE* pipe = popen((command + " 2>/dev/null").c_str(), "r");
  if (pipe == nullptr) return -1.0;
  double ms = -1.0;
  if (std::fscanf(pipe, "%lf", &ms) != 1) ms = -1.0;
  return pclose(pipe) == 0 ? ms : -1.0;
}

void RunVariant(const Settings& settings, const std::string& path, const ecv::LoadedFrame& frame, bool with_peer,
                Times* times) {
  ecv::LibraryLoadOptions load;
  load.build_matchers = false;  // as `recognize` loads it
  auto start = Clock::now();
  const ecv::ModelLibrary library = ecv::ModelLibrary::Load(path, load);
  times->read.push_back(MillisecondsSince(start));
  start = Clock::now();
  size_t triangles = 0;
  for (const ecv::LibraryModel& model : library.models()) triangles += ecv::ModelMesh(model.record).NumTriangles();
  times->meshes.push_back(MillisecondsSince(start));
  ecv::RecognizerOptions options;
  options.threads = settings.threads;
  options.preselect.models = settings.preselect;
  start = Clock::now();
  ecv::Recognizer recognizer(library, options);
  times->setup.push_back(MillisecondsSince(start));
  start = Clock::now();
  const ecv::RecognitionResult result = recognizer.Recognize(frame.rgbd);
  times->frame.push_back(MillisecondsSince(start));
  times->detections = Signature(result.detections);
  start = Clock::now();
  const std::vector<ecv::EvalModel> models = ecv::EvalModels(library);
  times->eval.push_back(MillisecondsSince(start));
  if (with_peer) times->open3d.push_back(Open3dMeshLoadMs(library));
  std::cerr << path << ": " << library.models().size() << " models, " << triangles << " triangles, "
            << result.detections.size() << " detections, read + set-up " << Fixed(times->read.back(), 0) << " + "
            << Fixed(times->setup.back(), 0) << " ms\n";
}

std::string Row(const std::string& what, double megabytes, const Times& t) {
  const double total = Median(t.read) + Median(t.setup) + Median(t.frame);
  return "| " + what + " | " + Fixed(megabytes, 1) + " | " + Fixed(Median(t.read), 0) + " | " +
         Fixed(Median(t.meshes), 0) + " | " + Fixed(Median(t.setup), 0) + " | " + Fixed(Median(t.frame), 0) + " | " +
         Fixed(total, 0) + " | " + Fixed(Median(t.eval), 0) + " |\n";
}

}  // namespace

int main(int argc, char** argv) {
  Settings settings;
  settings.command = ecv::bench::CommandLine(argc, argv);
  CLI::App app{
      "setup_bench: what a one-frame recognize pays before recognising (library read, meshes, Recognizer "
      "set-up, first frame, eval's models), with the meshes stored in the library or read from their files.",
      "setup_bench"};
  app.add_option("--db", settings.db, "Model library with stored meshes")->required();
  app.add_option("--frame", settings.frame, "Frame recognised (a YCB-Video prefix, or any FRAME that recognize takes)")
      ->capture_default_str();
  app.add_option("--rounds", settings.rounds, "Rounds, the two variants alternated")
      ->check(ecv::bench::AtLeastOne())
      ->capture_default_str();
  app.add_option("--threads", settings.threads, "Recognizer threads")
      ->check(ecv::bench::AtLeastOne())
      ->capture_default_str();
  app.add_option("--preselect", settings.preselect,
                 "Models searched per frame (recognize --preselect; a larger library's meshes then load on first use)")
      ->capture_default_str();
  app.add_option("--work", settings.work, "Directory for the library copy without meshes")->capture_default_str();
  app.add_option("--results", settings.results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.footer("Library:\n  scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9");
  if (const auto exit_code = ecv::bench::ParseCommandLine(app, argc, argv)) return *exit_code;
  try {
    fs::create_directories(settings.work);
    const std::string files = settings.work + "/files.sqlite";  // the same library without its stored meshes
    fs::copy_file(settings.db, files, fs::copy_options::overwrite_existing);
    ecv::SqlConnection(files, ecv::SqlOpenMode::kReadWrite, 1000).Execute("DELETE FROM meshes; VACUUM");
    ecv::FrameSpec spec;
    spec.positional = settings.frame;
    const ecv::LoadedFrame frame = ecv::LoadFrame(spec);

    std::map<std::string, Times> times;  // "files", "stored"
    for (int round = 0; round < settings.rounds; ++round) {
      const bool files_first = round % 2 == 0;
      for (int k = 0; k < 2; ++k) {
        const bool use_files = (k == 0) == files_first;
        RunVariant(settings, use_files ? files : settings.db, frame, use_files, &times[use_files ? "files" : "stored"]);
      }
    }
    const Times& before = times["files"];
    const Times& after = times["stored"];
    if (before.detections != after.detections) {
      throw std::runtime_error("the variants found different detections:\n" + before.detections + "--\n" +
                               after.detections);
    }
    const std::vector<double>& peer = before.open3d;
    const bool has_peer = std::all_of(peer.begin(), peer.end(), [](double ms) { return ms >= 0.0; });

    std::string markdown =
        "Library `" + settings.db + "` (" +
        std::to_string(std::count(after.detections.begin(), after.detections.end(), '\n')) + " detections in `" +
        settings.frame + "`, the same with either variant), " + std::to_string(settings.rounds) +
        " rounds, the variants alternated; medians. read = `ModelLibrary::Load` without matchers (as `recognize`); "
        "meshes = every model's mesh decoded on one thread (`ModelMesh`); set-up = `Recognizer` made with " +
        std::to_string(settings.threads) + " threads (meshes decoded and uploaded for verification" +
        (settings.preselect > 0
             ? ", unless `--preselect " + std::to_string(settings.preselect) + "` loads them on first use, in the frame"
             : std::string()) +
        "); frame = the first `Recognize`; eval = "
        "`EvalModels` (geometry for ADD). \"from files\" is the same library with its `meshes` rows deleted (and "
        "vacuumed), so that each model reads its `mesh_path` as before schema 2.\n\n"
        "| meshes | library MB | read ms | meshes ms | set-up ms | frame ms | read + set-up + frame ms | eval ms |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|\n" +
        Row("from files (OBJ + texture files)", MegaBytes(files), before) +
        Row("stored in the library", MegaBytes(settings.db), after);
    const double total_before = Median(before.read) + Median(before.setup) + Median(before.frame);
    const double total_after = Median(after.read) + Median(after.setup) + Median(after.frame);
    markdown += "\nStored / files: set-up " + Fixed(Median(after.setup) / Median(before.setup), 2) + "x, meshes " +
                Fixed(Median(after.meshes) / Median(before.meshes), 2) + "x, read + set-up + frame " +
                Fixed(total_after / total_before, 2) + "x, eval " + Fixed(Median(after.eval) / Median(before.eval), 2) +
                "x.";
    if (has_peer) {
      markdown +=
          " Peer: Open3D's `read_triangle_mesh` of the same mesh files, textures included (its MTLs trimmed, see "
          "bench/mesh_load_open3d.py), took " +
          Fixed(Median(peer), 0) + " ms (one thread; our reading of the files " +
          Fixed(Median(before.meshes) / Median(peer), 2) + "x that, of the stored meshes " +
          Fixed(Median(after.meshes) / Median(peer), 2) + "x).";
    } else {
      markdown += " Peer skipped: Open3D is not installed for /usr/bin/python3 (apt-get install -y python3-open3d).";
    }
    ecv::bench::ReportSection(settings.results,
                              "Recognizer set-up: meshes stored in the library or read from files "
                              "(setup_bench)",
                              settings.command, markdown + "\n");
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "setup_bench: " << error.what() << '\n';
    return 1;
  }
}
