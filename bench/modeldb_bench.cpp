// modeldb_bench: the model library (issue 7) on the textured YCB meshes (google_16k, 4096^2 textures).
//  1. Build: time per model split into render / extract / describe / insert, size per model and per view,
//     load time (rows, and the matchers).
//  2. How many views: correspondence score of held-out random views of each object against the nearest
//     library view, for libraries of 20..100 views (why the default is what it is).
//  3. Scaling: load and query time for libraries of 10, 100 and 1000 models, synthesised by re-adding the
//     built models' views under new names (fewer views per model there; said in the table).
//  Peer: the same records read from a flat binary file (no SQL, no index) in the same run.
//  With --parts instead: every object of ycb_objects built by `ecvpose modeldb build` in one process on every core,
//  against parts built side by side on one core each (--shard) and then merged (`modeldb merge`).
// Replaces its section of bench/RESULTS.md (bench_util ReportSection); --parts has a section of its own.
//
//   modeldb_bench [--views N] [--fit-views N] [--scale-views N] [--study-views N] [--scales N,N,...] [--data DIR]
//                 [--work DIR] [--results FILE]
//   modeldb_bench --parts [--views N] [--data DIR] [--work DIR] [--results FILE]

#include <sys/stat.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_util.h"
#include "core/timing.h"
#include "ecv/matching.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "modeldb/model_builder.h"
#include "modeldb/model_database.h"
#include "modeldb/model_library.h"

namespace {

using ecv::Clock;
using ecv::MillisecondsSince;
using ecv::bench::Fixed;
namespace fs = std::filesystem;

const char* const kObjects[] = {"003_cracker_box",    "004_sugar_box",   "005_tomato_soup_can",
                                "006_mustard_bottle", "009_gelatin_box", "010_potted_meat_can"};

struct Settings {
  int views = ecv::ModelBuildOptions::DefaultSampling().num_views;
  int scale_views = 2;                        // views per synthesised model in the scaling part
  int study_views = 5;                        // held-out views per object in the views study
  int fit_views = 4;                          // views per object of the comparison build at the fitting distance
  std::vector<int> scales = {10, 100, 1000};  // library sizes of the scaling part
  std::string data = ECV_DATA_DIR;
  std::string work = "/tmp/modeldb_bench";
  std::string results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  std::string command = "modeldb_bench";
  bool parts = false;  // the parts comparison instead of the rest
};

double MegaBytes(double bytes) {
  return bytes / (1024.0 * 1024.0);
}

double FileBytes(const std::string& path) {
  struct stat info {};
  return stat(path.c_str(), &info) == 0 ? static_cast<double>(info.st_size) : 0.0;
}

ecv::ModelSource YcbSource(const Settings& settings, const std::string& object) {
  ecv::ModelSource source;
  source.name = object;
  source.mesh_path = settings.data + "/ycbv_subset/ycb_google16k_textured/" + object + "_textured.obj";
  source.object_from_mesh =
      ecv::ReadTransformTable(settings.data + "/ycbv_subset/derived/google16k_to_ycbv.txt").at(object);
  return source;
}

// ---- 1. build ----------------------------------------------------------------------------------------------

struct BuildRow {
  std::string object;
  std::string distance;
  ecv::BuildTimings timings;
  double insert_ms = 0.0, bytes = 0.0;
  int views = 0, primitives = 0;
};

std::string BuildTable(const std::vector<BuildRow>& rows) {
  std::string table =
      "| model | distance m | views | primitives | load+hash+pack s | render s | extract s | describe s | insert s | "
      "total "
      "s | "
      "MB | describe s/view | kB/view | B/primitive "
      "|\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const BuildRow& r : rows) {
    const ecv::BuildTimings& t = r.timings;
    const double total = t.load_ms + t.upload_ms + t.render_ms + t.extract_ms + t.describe_ms + r.insert_ms;
    table += "| " + r.object + " | " + r.distance + " | " + std::to_string(r.views) + " | " +
             std::to_string(r.primitives) + " | " + Fixed(t.load_ms / 1000, 1) + " | " +
             Fixed((t.upload_ms + t.render_ms) / 1000, 1) + " | " + Fixed(t.extract_ms / 1000, 1) + " | " +
             Fixed(t.describe_ms / 1000, 1) + " | " + Fixed(r.insert_ms / 1000, 2) + " | " + Fixed(total / 1000, 1) +
             " | " + Fixed(MegaBytes(r.bytes), 1) + " | " + Fixed(t.describe_ms / 1000 / r.views, 2) + " | " +
             Fixed(r.bytes / 1024 / r.views, 0) + " | " + Fixed(r.bytes / r.primitives, 0) + " |\n";
  }
  return table;
}

// Builds every object into `path` with `views` views at `distance_m` (0: as close as fits), closing the file after
// each so that its size is settled.
std::vector<BuildRow> BuildLibrary(const Settings& settings, const std::string& path, int views, double distance_m,
                                   ecv::Renderer& renderer) {
  ecv::ModelBuildOptions options;
  options.sampling.num_views = views;
  options.distance_m = distance_m;
  std::vector<BuildRow> rows;
  for (const char* object : kObjects) {
    const double before = FileBytes(path);
    const ecv::ModelSource source = YcbSource(settings, object);
    const ecv::BuildResult built = ecv::BuildModel(source, options, renderer);
    const ecv::TriangleMesh mesh = ecv::LoadMesh(source.mesh_path, {1.0, source.object_from_mesh, false});
    const double distance = ecv::ViewDistance(ecv::ComputeBoundingSphere(mesh), options);
    BuildRow row{object, Fixed(distance, 2), built.timings, 0.0, 0.0, views, built.record.NumPrimitives()};
    row.insert_ms = ecv::ModelDatabase(path, ecv::OpenMode::kCreate).AddModel(built.record).insert_ms;
    row.bytes = FileBytes(path) - before;
    std::cerr << object << " at " << row.distance << " m: " << row.primitives << " primitives, "
              << Fixed(MegaBytes(row.bytes), 1) << " MB\n";
    rows.push_back(row);
  }
  return rows;
}

// ---- peer: a flat binary file ----------------------------------------------------------------------------

template <typename T>
void Put(std::ofstream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}
template <typename T>
void PutVector(std::ofstream& out, const std::vector<T>& values) {
  Put(out, values.size());
  out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(T)));
}
template <typename T>
T Get(std::ifstream& in) {
  T value{};
  in.read(reinterpret_cast<char*>(&value), sizeof(T));
  return value;
}
template <typename T>
void GetVector(std::ifstream& in, std::vector<T>* values) {
  values->resize(Get<size_t>(in));
  in.read(reinterpret_cast<char*>(values->data()), static_cast<std::streamsize>(values->size() * sizeof(T)));
}

// Views as raw arrays, and the stored mesh's bytes (the records' names and metadata are left out: the peer is the
// cheapest reader possible).
void WriteFlat(const std::string& path, const std::vector<ecv::StoredModel>& models) {
  std::ofstream out(path, std::ios::binary);
  Put(out, models.size());
  for (const ecv::StoredModel& model : models) {
    PutVector(out, model.record.mesh_blob);
    Put(out, model.record.views.size());
    for (const ecv::ModelView& view : model.record.views) {
      Put(out, view.camera);
      Put(out, view.camera_from_object);
      PutVector(out, view.primitives);
      PutVector(out, view.descriptors.primitive);
      out.write(reinterpret_cast<const char*>(view.descriptors.values.ptr<float>()),
                static_cast<std::streamsize>(view.descriptors.values.total() * sizeof(float)));
    }
  }
}

std::vector<ecv::ModelRecord> ReadFlat(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<ecv::ModelRecord> models(Get<size_t>(in));
  for (ecv::ModelRecord& model : models) {
    GetVector(in, &model.mesh_blob);
    model.views.resize(Get<size_t>(in));
    for (ecv::ModelView& view : model.views) {
      view.camera = Get<ecv::PinholeCamera>(in);
      view.camera_from_object = Get<Eigen::Isometry3d>(in);
      GetVector(in, &view.primitives);
      GetVector(in, &view.descriptors.primitive);
      view.descriptors.values.create(static_cast<int>(view.descriptors.primitive.size()), ecv::kDescriptorSize, CV_32F);
      in.read(reinterpret_cast<char*>(view.descriptors.values.ptr<float>()),
              static_cast<std::streamsize>(view.descriptors.values.total() * sizeof(float)));
    }
  }
  return models;
}

// ---- 2. how many views ----------------------------------------------------------------------------------------

constexpr int kStudyViewCounts[] = {20, 40, 60, 100};

struct StudyCell {
  double angle_deg = 0.0, score = 0.0, ceiling = 0.0;
  int samples = 0;
};

Eigen::Vector3d ViewDirection(const Eigen::Isometry3d& camera_from_object, const Eigen::Vector3d& centre) {
  return (camera_from_object.inverse().translation() - centre).normalized();
}

// Held-out views at seeded random directions, each scored against the nearest view of every library size.
void StudyObject(const Settings& settings, const std::string& object, ecv::Renderer& renderer,
                 std::vector<StudyCell>* cells) {
  ecv::MeshLoadOptions load;
  load.object_from_mesh = YcbSource(settings, object).object_from_mesh;
  const ecv::TriangleMesh mesh = ecv::LoadMesh(YcbSource(settings, object).mesh_path, load);
  const ecv::MeshId id = renderer.AddMesh(mesh);
  const ecv::BoundingSphere sphere = ecv::ComputeBoundingSphere(mesh);
  const ecv::ModelBuildOptions options;
  const double distance = ecv::ViewDistance(sphere, options);
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  for (int t = 0; t < settings.study_views; ++t) {
    const Eigen::Vector3d direction = Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
    const Eigen::Isometry3d pose = ecv::LookAt(sphere.center_object + distance * direction, sphere.center_object,
                                               Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX());
    const ecv::ModelView held_out = ecv::BuildModelView(renderer, id, pose, options);
    for (size_t n = 0; n < std::size(kStudyViewCounts); ++n) {
      ecv::ViewSamplingOptions sampling = options.sampling;
      sampling.num_views = kStudyViewCounts[n];
      sampling.distance_m = distance;
      const std::vector<Eigen::Isometry3d> library = ecv::SampleViews(sphere, options.camera, sampling);
      size_t nearest = 0;
      for (size_t i = 1; i < library.size(); ++i) {
        if (ViewDirection(library[i], sphere.center_object).dot(direction) >
            ViewDirection(library[nearest], sphere.center_object).dot(direction)) {
          nearest = i;
        }
      }
      const ecv::ModelView view = ecv::BuildModelView(renderer, id, library[nearest], options);
      const ecv::DescriptorMatcher matcher(view.primitives, view.descriptors);
      const auto matches = matcher.Match(held_out.primitives, held_out.descriptors);
      // Both views are in the object frame: the true alignment is the identity.
      const ecv::CorrespondenceScore score =
          ecv::ScoreCorrespondences(held_out.primitives, view.primitives, matches, Eigen::Isometry3d::Identity());
      StudyCell& cell = (*cells)[n];
      cell.angle_deg +=
          std::acos(std::min(1.0, ViewDirection(library[nearest], sphere.center_object).dot(direction))) * 180.0 / M_PI;
      cell.score += 100.0 * score.Score();
      cell.ceiling += 100.0 * ecv::TruePartnerFraction(held_out.primitives, held_out.descriptors.primitive,
                                                       view.primitives, Eigen::Isometry3d::Identity());
      ++cell.samples;
    }
  }
  renderer.RemoveMesh(id);
}

std::string ViewsStudy(const Settings& settings, ecv::Renderer& renderer, double bytes_per_view) {
  std::vector<StudyCell> cells(std::size(kStudyViewCounts));
  for (const char* object : kObjects) {
    std::cerr << "views study: " << object << '\n';
    StudyObject(settings, object, renderer, &cells);
  }
  std::string table =
      "| library views | mean angle to the nearest view, deg | correspondence score % | ceiling % | MB per model |\n"
      "|---:|---:|---:|---:|---:|\n";
  for (size_t n = 0; n < cells.size(); ++n) {
    const StudyCell& c = cells[n];
    table += "| " + std::to_string(kStudyViewCounts[n]) + " | " + Fixed(c.angle_deg / c.samples, 1) + " | " +
             Fixed(c.score / c.samples, 1) + " | " + Fixed(c.ceiling / c.samples, 1) + " | " +
             Fixed(MegaBytes(bytes_per_view * kStudyViewCounts[n]), 0) + " |\n";
  }
  return table;
}

// ---- 3. scaling ---------------------------------------------------------------------------------------------

// Descriptors of a real YCB-Video frame, extracted with the library's settings: the query of the scaling part.
struct SceneFeatures {
  std::vector<ecv::Primitive> primitives;
  ecv::Descriptors descriptors;
};

SceneFeatures LoadScene(const Settings& settings, const ecv::FeatureSettings& features) {
  const ecv::LoadedFrame frame = ecv::LoadYcbvFrame(settings.data + "/ycbv_subset/Example-Scenes/0001/000001");
  SceneFeatures scene;
  scene.primitives = ecv::ExtractPrimitives(frame.rgbd, features.ecv).primitives;
  scene.descriptors = ecv::ComputeDescriptors(scene.primitives, features.descriptor);
  return scene;
}

// The meshes, uploaded once, that the scaling part re-adds under new names.
struct ScalingMeshes {
  std::vector<ecv::StoredModel> built;  // metadata of each object (views unused)
  std::vector<ecv::MeshId> ids;
  std::vector<ecv::BoundingSphere> spheres;
};

ScalingMeshes UploadMeshes(const Settings& settings, const std::vector<ecv::StoredModel>& built,
                           ecv::Renderer& renderer) {
  ScalingMeshes meshes{built, {}, {}};
  for (const ecv::StoredModel& model : built) {
    const ecv::ModelSource source = YcbSource(settings, model.record.name);
    const ecv::TriangleMesh mesh = ecv::LoadMesh(source.mesh_path, {1.0, source.object_from_mesh, false});
    meshes.ids.push_back(renderer.AddMesh(mesh));
    meshes.spheres.push_back(ecv::ComputeBoundingSphere(mesh));
  }
  return meshes;
}

// A library of `count` models: the meshes in turn, re-added under new names, each with `views` views from
// seeded random directions (so that no two views, and no two descriptors, are copies of each other).
void SynthesiseLibrary(const ScalingMeshes& meshes, int count, int views, const std::string& path,
                       ecv::Renderer& renderer) {
  fs::remove(path);
  ecv::ModelDatabase database(path, ecv::OpenMode::kCreate);
  const ecv::ModelBuildOptions options;
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  for (int i = 0; i < count; ++i) {
    const size_t object = static_cast<size_t>(i) % meshes.ids.size();
    const ecv::BoundingSphere& sphere = meshes.spheres[object];
    ecv::ModelRecord record = meshes.built[object].record;
    record.name += "_copy" + std::to_string(i);
    record.views.clear();
    record.mesh_blob.clear();  // the study is of the descriptors: 1000 copies of the meshes would add about 2 GB
    for (int v = 0; v < views; ++v) {
      const Eigen::Vector3d direction = Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
      const Eigen::Isometry3d pose =
          ecv::LookAt(sphere.center_object + ecv::ViewDistance(sphere, options) * direction, sphere.center_object,
                      Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX());
      record.views.push_back(ecv::BuildModelView(renderer, meshes.ids[object], pose, options));
      record.views.back().index = v;
    }
    database.AddModel(record);
  }
}

std::string ScalingRow(const Settings& settings, const ScalingMeshes& meshes, int count, const SceneFeatures& scene,
                       ecv::Renderer& renderer) {
  const std::string path = settings.work + "/scale_" + std::to_string(count) + ".sqlite";
  auto start = Clock::now();
  SynthesiseLibrary(meshes, count, settings.scale_views, path, renderer);
  const double build_ms = MillisecondsSince(start);
  start = Clock::now();
  const ecv::ModelLibrary library = ecv::ModelLibrary::Load(path);
  const double load_ms = MillisecondsSince(start);
  start = Clock::now();
  size_t matches = 0;
  for (const ecv::LibraryModel& model : library.models()) {
    for (const auto& matcher : model.matchers) matches += matcher->Match(scene.primitives, scene.descriptors).size();
  }
  const double query_ms = MillisecondsSince(start);
  ecv::LibraryLoadOptions one_index;
  one_index.build_matchers = false;
  one_index.build_library_index = true;
  const ecv::ModelLibrary indexed = ecv::ModelLibrary::Load(path, one_index);
  start = Clock::now();
  const size_t library_matches = indexed.MatchLibrary(scene.primitives, scene.descriptors).size();
  const double library_query_ms = MillisecondsSince(start);
  const std::string flat = settings.work + "/scale_" + std::to_string(count) + ".bin";
  WriteFlat(flat, ecv::ModelDatabase(path, ecv::OpenMode::kReadOnly).LoadModels());
  start = Clock::now();
  const size_t flat_models = ReadFlat(flat).size();
  const double flat_ms = MillisecondsSince(start);
  std::cerr << "scaling " << count << ": " << matches << " + " << library_matches << " matches, " << flat_models
            << " flat models\n";
  return "| " + std::to_string(count) + " | " + std::to_string(library.NumViews()) + " | " +
         std::to_string(library.NumDescriptors()) + " | " + Fixed(MegaBytes(FileBytes(path)), 0) + " | " +
         Fixed(build_ms / count, 0) + " | " + Fixed(library.timings().read_ms, 0) + " | " +
         Fixed(library.timings().index_ms, 0) + " | " + Fixed(load_ms, 0) + " | " + Fixed(flat_ms, 0) + " | " +
         Fixed(library.timings().read_ms / flat_ms, 1) + " | " + Fixed(query_ms, 0) + " | " +
         Fixed(query_ms / library.NumViews(), 1) + " | " + Fixed(indexed.timings().library_index_ms, 0) + " | " +
         Fixed(library_query_ms, 0) + " |\n";
}

// ---- main ---------------------------------------------------------------------------------------------------

std::string ScalesText(const std::vector<int>& scales) {
  std::string text;
  for (const int count : scales) text += (text.empty() ? "" : ", ") + std::to_string(count);
  return text;
}

std::string LoadRow(const std::string& what, double sqlite_ms, double flat_ms, double index_ms) {
  return "| " + what + " | " + Fixed(sqlite_ms, 0) + " | " + Fixed(flat_ms, 0) + " | " + Fixed(sqlite_ms / flat_ms, 1) +
         " | " + Fixed(index_ms, 0) + " |\n";
}

}  // namespace

// Runs `command` (shell) and returns its wall time in seconds; throws when it fails.
double TimedShell(const std::string& command) {
  const auto start = Clock::now();
  const int code = ecv::bench::RunShellCommand(command);
  if (code != 0) throw std::runtime_error("exit code " + std::to_string(code) + " of: " + command);
  return MillisecondsSince(start) / 1000.0;
}

// The library's models as (name, mesh digest, descriptor digest, views): what equal libraries share.
std::vector<std::string> ModelDigests(const std::string& path) {
  std::vector<std::string> digests;
  for (const ecv::ModelSummary& m : ecv::ModelDatabase(path, ecv::OpenMode::kReadOnly).ListModels()) {
    digests.push_back(std::to_string(m.id) + " " + m.name + " " + m.mesh_sha256 + " " + m.descriptor_sha256 + " " +
                      std::to_string(m.num_views));
  }
  return digests;
}

// The whole YCB set: one build on both cores against two parts side by side on one core each, then their merge.
void PartsComparison(const Settings& settings) {
  using ecv::bench::ShellQuoted;
  const std::string cli = ShellQuoted(ECV_CLI_PATH);
  const std::string meshes = ShellQuoted(settings.data + "/ycb_objects");
  const std::string views = " --views " + std::to_string(settings.views);
  const std::string work = settings.work + "/parts";
  fs::remove_all(work);
  fs::create_directories(work);
  const auto library = [&](const std::string& name) { return ShellQuoted(work + "/" + name + ".sqlite"); };
  const std::string quiet = " > /dev/null 2>> " + ShellQuoted(work + "/build.log");
  std::cerr << "modeldb_bench: one build of " << settings.data << "/ycb_objects on 2 threads\n";
  const double one_s =
      TimedShell(cli + " modeldb build " + meshes + " --db " + library("one") + " --threads 2" + views + quiet);
  std::cerr << "modeldb_bench: 2 parts side by side on 1 thread each\n";
  const double parts_s =
      TimedShell("(" + cli + " modeldb build " + meshes + " --db " + library("part0") + " --shard 0/2 --threads 1" +
                 views + quiet + " & first=$!; " + cli + " modeldb build " + meshes + " --db " + library("part1") +
                 " --shard 1/2 --threads 1" + views + quiet + " & second=$!; wait $first && wait $second)");
  const double merge_s =
      TimedShell(cli + " modeldb merge " + library("merged") + " " + library("part0") + " " + library("part1") + quiet);
  const std::vector<std::string> one = ModelDigests(work + "/one.sqlite");
  const std::vector<std::string> merged = ModelDigests(work + "/merged.sqlite");
  const size_t part0 = ModelDigests(work + "/part0.sqlite").size();
  const size_t part1 = ModelDigests(work + "/part1.sqlite").size();
  std::string markdown =
      "Every object of `ycb_objects` (google_16k meshes, 4096^2 textures), " + std::to_string(settings.views) +
      " views per model, `ecvpose modeldb build` on this 2-core machine: one process with `--threads 2` against two "
      "processes side by side, `--shard 0/2` and `--shard 1/2` with `--threads 1` each, then `modeldb merge` of the "
      "two parts. Equal = the merged library has the one build's models, numbers, mesh and descriptor digests and "
      "views.\n\n| build | models | wall s | s per model | vs one process |\n|---|---:|---:|---:|---:|\n";
  const auto row = [&](const std::string& name, size_t models, double seconds) {
    markdown += "| " + name + " | " + std::to_string(models) + " | " + Fixed(seconds, 1) + " | " +
                Fixed(seconds / std::max<size_t>(models, 1), 2) + " | " + Fixed(seconds / one_s, 2) + " |\n";
  };
  row("one process, 2 threads", one.size(), one_s);
  row("2 parts side by side (" + std::to_string(part0) + " + " + std::to_string(part1) + " models), 1 thread each",
      merged.size(), parts_s);
  row("merge of the 2 parts", merged.size(), merge_s);
  row("2 parts + merge", merged.size(), parts_s + merge_s);
  markdown += "\nMerged library equal to the one build: " + std::string(one == merged ? "yes" : "**no**") + " (" +
              Fixed(MegaBytes(FileBytes(work + "/merged.sqlite")), 0) + " MB).\n";
  ecv::bench::ReportSection(settings.results, "Model library built in parts (modeldb_bench --parts)", settings.command,
                            markdown);
}

int main(int argc, char** argv) {
  Settings settings;
  settings.command = ecv::bench::CommandLine(argc, argv);
  CLI::App app{
      "modeldb_bench: the model library on the textured YCB meshes: build time per step, size, load time "
      "against a flat file, how many views are needed, and scaling to 1000 models.",
      "modeldb_bench"};
  app.add_option("--views", settings.views, "Views per model of the library built and loaded")->capture_default_str();
  app.add_option("--fit-views", settings.fit_views,
                 "Views per model of the comparison build with the views as close as each object fits the image")
      ->capture_default_str();
  app.add_option("--scale-views", settings.scale_views, "Views per synthesised model in the scaling part")
      ->capture_default_str();
  app.add_option("--study-views", settings.study_views, "Held-out views per object in the how-many-views study")
      ->capture_default_str();
  app.add_option("--scales", settings.scales, "Library sizes (models) of the scaling part, comma-separated")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--data", settings.data, "Data directory (with ycbv_subset)")->capture_default_str();
  app.add_option("--work", settings.work, "Directory for the libraries built (their files are replaced)")
      ->capture_default_str();
  app.add_option("--results", settings.results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.add_flag("--parts", settings.parts,
               "Only the whole YCB set (ycb_objects) built in one process against two parts side by side, merged");
  if (const auto exit_code = ecv::bench::ParseCommandLine(app, argc, argv)) return *exit_code;
  try {
    if (settings.parts) {
      PartsComparison(settings);
      return 0;
    }
    fs::create_directories(settings.work);
    const std::string path = settings.work + "/ycb.sqlite";
    fs::remove(path);
    ecv::Renderer renderer;
    const std::vector<BuildRow> rows = BuildLibrary(settings, path, settings.views, 1.0, renderer);
    const std::string fit_path = settings.work + "/ycb_fit.sqlite";
    fs::remove(fit_path);
    std::vector<BuildRow> all_rows = rows;
    for (const BuildRow& row : BuildLibrary(settings, fit_path, settings.fit_views, 0.0, renderer))
      all_rows.push_back(row);

    const ecv::ModelLibrary library = ecv::ModelLibrary::Load(path);  // the whole library, with matchers
    const std::vector<ecv::StoredModel> stored = ecv::ModelDatabase(path, ecv::OpenMode::kReadOnly).LoadModels();
    WriteFlat(settings.work + "/ycb.bin", stored);
    auto start = Clock::now();
    const size_t flat_models = ReadFlat(settings.work + "/ycb.bin").size();
    const double flat_ms = MillisecondsSince(start);
    std::string load_table =
        "| library | SQLite read ms | flat file read ms | ratio | matchers ms |\n|---|---:|---:|---:|---:|\n";
    load_table += LoadRow(std::to_string(flat_models) + " YCB models x " + std::to_string(settings.views) + " views (" +
                              Fixed(MegaBytes(FileBytes(path)), 0) + " MB)",
                          library.timings().read_ms, flat_ms, library.timings().index_ms);

    double bytes = 0.0;
    int views = 0;
    for (const BuildRow& row : rows) bytes += row.bytes, views += row.views;
    const std::string study = ViewsStudy(settings, renderer, bytes / views);

    const SceneFeatures scene = LoadScene(settings, library.feature_settings());
    std::string scaling =
        "| models | views | descriptors | MB | build+add ms/model | read ms | matchers ms | load ms | flat file read "
        "ms | "
        "SQLite / flat | query ms, every view | ms/view | library index ms | query ms, library index |\n"
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    const ScalingMeshes meshes = UploadMeshes(settings, stored, renderer);
    for (const int count : settings.scales) scaling += ScalingRow(settings, meshes, count, scene, renderer);

    const std::string markdown =
        "Textured YCB meshes (google_16k, 4096^2 textures), " + std::to_string(settings.views) +
        " views of 640x480 (YCB-Video camera) per model at the default distance (1 m, farther where the object would "
        "not fit), default ECV and descriptor settings, the mesh stored with each model (textures at 2048^2, LZ4); "
        "one transaction per model. Below them, for comparison, " +
        std::to_string(settings.fit_views) +
        " views per model as close as each object fits the image (the "
        "descriptor benchmark's library). MB = growth of the SQLite file (WAL checkpointed on close).\n\n" +
        BuildTable(all_rows) +
        "\nLoading the whole library for recognition (rows in one read transaction; then one "
        "FLANN matcher per view). Peer: the same views and stored meshes as raw arrays in one flat binary file (no "
        "names, no SQL), "
        "read in the same run; both from a warm page cache.\n\n" +
        load_table + "\nHow many views: " + std::to_string(settings.study_views) +
        " held-out views per object at seeded random "
        "directions (same distance), each matched (1-NN, structure-specific) against the nearest view of a library of "
        "N views; correspondence score (paper Sect. IV-A, 1 cm) and its ceiling, mean over the " +
        std::to_string(std::size(kObjects) * settings.study_views) +
        " views; MB per model from the measured size "
        "per view.\n\n" +
        study + "\nScaling: libraries of " + ScalesText(settings.scales) +
        " models synthesised by re-adding the 6 meshes in "
        "turn under new names with " +
        std::to_string(settings.scale_views) +
        " views each, from seeded random "
        "directions so that no view repeats, without stored meshes (the full " +
        std::to_string(settings.views) + " views would make the 1000-model file about " +
        Fixed(MegaBytes(bytes / views * settings.views * 1000) / 1024, 1) +
        " GB). load = read + matchers; query = matching the " + std::to_string(scene.descriptors.values.rows) +
        " descriptors of the real frame YCB-Video 0001/000001 against every view's matcher (k = 1), or against one "
        "index over all descriptors of the library (LibraryLoadOptions::build_library_index).\n\n" +
        scaling;
    ecv::bench::ReportSection(settings.results, "Model database: build, size, load, views, scaling (modeldb_bench)",
                              settings.command, markdown);
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "modeldb_bench: " << error.what() << '\n';
    return 1;
  }
}
