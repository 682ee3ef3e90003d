// `ecvpose modeldb`: build a model library from meshes into SQLite, and list, inspect, remove, verify, export
// and migrate it. Compiled only into the ecvpose executable; reads flags into options and calls ecv_modeldb.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/error.h"
#include "io/frame_io.h"
#include "io/ply_io.h"
#include "io/pose_io.h"
#include "modeldb/library_build.h"
#include "modeldb/mesh_sources.h"
#include "modeldb/model_builder.h"
#include "modeldb/model_database.h"
#include "modeldb/schema.h"

namespace ecv::app {
namespace {

struct ModeldbArgs {
  std::string db;
  // build
  std::vector<std::string> inputs;
  int views = ModelBuildOptions::DefaultSampling().num_views;
  MeshArgs mesh;
  std::string name;
  std::string camera;
  std::string size = "640x480";
  double distance_m = ModelBuildOptions().distance_m;
  std::string shading = "auto";
  bool symmetric = false;
  std::string feature_settings;  // JSON file of FeatureSettings; empty: the defaults
  int threads = app::AllCores();
  bool no_stored_mesh = false;
  bool no_point_pairs = false;
  int mesh_texture_size = MeshBlobOptions().max_texture_size;
  std::string shard;  // "I/N": build only the I-th of N parts (0 <= I < N)
  // merge
  std::vector<std::string> shards;
  // list, info, remove, export, verify
  std::string model;
  bool json = false;
  std::string ply;
  int view = -1;
  std::string color_by = "type";
  bool quick = false;
};

std::string Fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

// --camera fx,fy,cx,cy and --size WxH; the YCB-Video camera by default.
PinholeCamera CameraArgument(const ModeldbArgs& args) {
  PinholeCamera camera = YcbVideoCamera();
  if (!args.camera.empty()) {
    const auto k = ParseIntrinsics(args.camera, "--camera");
    camera.fx = k[0], camera.fy = k[1], camera.cx = k[2], camera.cy = k[3];
  }
  char x = 0;
  std::istringstream size(args.size);
  if (!(size >> camera.width >> x >> camera.height) || x != 'x' || !(size >> std::ws).eof()) {
    ThrowInputError("--size", "image size", "WIDTHxHEIGHT in pixels, e.g. 640x480", args.size);
  }
  camera.Check("--camera/--size");
  return camera;
}

ModelBuildOptions BuildArguments(const ModeldbArgs& args) {
  ModelBuildOptions options;
  options.sampling.num_views = args.views;
  options.distance_m = args.distance_m;
  options.threads = args.threads;
  options.camera = CameraArgument(args);
  options.render.shading = args.shading == "headlight" ? Shading::kHeadlight : Shading::kUnlit;
  options.shade_untextured = args.shading == "auto";
  options.store_mesh = !args.no_stored_mesh;
  options.point_pairs = !args.no_point_pairs;
  options.mesh_blob.max_texture_size = args.mesh_texture_size;
  if (!args.feature_settings.empty()) {  // --feature-settings: e.g. {"descriptor": {"pairs": 1}}
    std::ifstream file(args.feature_settings);
    std::stringstream text;
    text << file.rdbuf();
    if (!file) ThrowInputError(args.feature_settings, "--feature-settings", "a readable JSON file");
    options.features = FeatureSettingsFromJson(text.str(), args.feature_settings);
    try {
      options.features.ecv.Check();
      options.features.descriptor.Check();
    } catch (const InputError& error) {
      ThrowInputError(args.feature_settings, "--feature-settings", "settings in their ranges", error.what());
    }
  }
  options.Check();
  return options;
}

ModelSource SourceDefaults(const ModeldbArgs& args) {
  ModelSource defaults;
  defaults.name = args.name;
  defaults.unit = args.mesh.unit;
  defaults.allow_missing_textures = args.mesh.allow_missing_textures;
  defaults.symmetric = args.symmetric;
  if (!args.mesh.object_from_mesh_path.empty()) {
    defaults.object_from_mesh = ReadPoseFile(args.mesh.object_from_mesh_path, "object_from_mesh");
  }
  return defaults;
}

// --shard I/N as (I, N); (0, 1) when not given.
std::pair<int, int> ShardArgument(const std::string& text) {
  if (text.empty()) return {0, 1};
  int index = -1, parts = 0;
  char slash = 0;
  std::istringstream in(text);
  if (!(in >> index >> slash >> parts) || slash != '/' || !(in >> std::ws).eof() || parts < 1 || index < 0 ||
      index >= parts) {
    ThrowInputError("--shard", "part of the build", "I/N with 0 <= I < N, e.g. 0/4", text);
  }
  return {index, parts};
}

// Progress on stderr: a line per view and per model stored, a FAILED line per model that could not be built.
LibraryBuildReporter BuildReporter(const ModelBuildOptions& options) {
  const auto prefix = std::make_shared<std::string>();
  LibraryBuildReporter reporter;
  reporter.started = [prefix, views = options.sampling.num_views](const ModelSource& source, int number, int count) {
    *prefix = "modeldb: [" + std::to_string(number) + "/" + std::to_string(count) + "] " + source.name;
    std::cerr << *prefix << ": building " << views << " views of " << source.mesh_path << '\n';
  };
  reporter.progress = [prefix](const ModelSource&, const BuildProgress& p) {
    std::cerr << *prefix << ": view " << p.view << "/" << p.num_views << ": " << p.primitives << " primitives, "
              << p.descriptors << " descriptors\n";
  };
  reporter.stored = [prefix](const ModelSource&, const BuildResult& built, const AddModelResult& added) {
    for (const std::string& warning : built.warnings) std::cerr << *prefix << ": warning: " << warning << '\n';
    const BuildTimings& t = built.timings;
    std::cerr << *prefix << ": stored " << built.record.views.size() << " views, " << built.record.NumPrimitives()
              << " primitives, " << built.record.NumDescriptors() << " descriptors (render "
              << Fixed(t.render_ms / 1000, 1) << " s, extract " << Fixed(t.extract_ms / 1000, 1) << " s, describe "
              << Fixed(t.describe_ms / 1000, 1) << " s, point pairs " << Fixed(t.point_pairs_ms / 1000, 1)
              << " s, insert " << Fixed(added.insert_ms / 1000, 1) << " s)"
              << (built.record.mesh_blob.empty()
                      ? std::string(", mesh not stored")
                      : ", mesh stored (" + Fixed(built.record.mesh_blob.size() / 1e6, 1) + " MB)")
              << (added.replaced ? "; replaced the earlier model" : "")
              << (added.color_matrix_kept ? ", kept its colour matrix" : "")
              << (added.color_matrix_dropped ? ", dropped its colour matrix (the mesh changed)" : "") << '\n';
  };
  reporter.failed = [prefix](const ModelSource&, const std::string& message) {
    std::cerr << *prefix << ": FAILED: " << message << '\n';
  };
  return reporter;
}

int RunBuild(const ModeldbArgs& args) {
  if (!args.name.empty() && args.inputs.size() != 1) {
    std::cerr << "ecvpose modeldb build: --name needs exactly one MESH\n";
    return kExitBadUsage;
  }
  const ModelBuildOptions options = BuildArguments(args);
  const auto [shard, parts] = ShardArgument(args.shard);
  MeshSourceScan scan = FindMeshSources(args.inputs, SourceDefaults(args), args.mesh.object_from_mesh_path.empty());
  KeepShard(shard, parts, &scan);
  if (!args.name.empty() && scan.sources.size() > 1) {
    std::cerr << "ecvpose modeldb build: --name needs a single mesh, " << args.inputs[0] << " holds "
              << scan.sources.size() << '\n';
    return kExitBadUsage;
  }
  for (const std::string& problem : scan.problems) std::cerr << "modeldb: FAILED: " << problem << '\n';
  const LibraryBuildSummary summary = BuildLibrary(args.db, scan.sources, options, BuildReporter(options));
  std::cout << "built " << summary.built.size() << " of " << scan.sources.size() + scan.problems.size()
            << " models into " << args.db;
  if (parts > 1) std::cout << " (shard " << shard << "/" << parts << ")";
  if (!summary.failed.empty() || !scan.problems.empty()) {
    std::cout << "; failed (see above):";
    for (const std::string& name : summary.failed) std::cout << ' ' << name;
    for (const std::string& problem : scan.problems) std::cout << ' ' << problem.substr(0, problem.find(':'));
  }
  std::cout << '\n';
  // A part may hold no model (fewer models than parts); a whole build must hold one.
  const bool some = !summary.built.empty() || (parts > 1 && scan.sources.empty());
  return summary.failed.empty() && scan.problems.empty() && some ? kExitOk : kExitBadInput;
}

int RunMerge(const ModeldbArgs& args) {
  LibraryMergeReporter reporter;
  reporter.copied = [](const std::string& model, const std::string& shard, int number, int count) {
    std::cerr << "modeldb: [" << number << "/" << count << "] " << model << " from " << shard << '\n';
  };
  const int models = MergeLibraries(args.db, args.shards, reporter);
  std::cout << "merged " << models << " models of " << args.shards.size() << " libraries into " << args.db << '\n';
  return kExitOk;
}

// null when none were made; else the points and pairs, and the refusal of a mesh that has none.
nlohmann::ordered_json PointPairsJson(const ModelSummary& m) {
  if (m.point_pair_points < 0) return nullptr;
  nlohmann::ordered_json json = {{"points", m.point_pair_points}, {"pairs", m.point_pairs}};
  if (!m.point_pair_refusal.empty()) json["refusal"] = m.point_pair_refusal;
  return json;
}

// The point pair column of `modeldb list`: the points stored, "refused" for a mesh without, "-" when none were made.
std::string PointPairsColumn(const ModelSummary& m) {
  if (m.point_pair_points < 0) return "-";
  return m.point_pair_points == 0 ? "refused" : std::to_string(m.point_pair_points);
}

// The BOP obj_id of each model of the library (as recognize --out-bop writes them).
std::map<std::string, int> LibraryObjectIds(const std::vector<ModelSummary>& models) {
  std::vector<std::pair<std::string, int64_t>> named;
  for (const ModelSummary& m : models) named.emplace_back(m.name, m.id);
  return BopObjectIds(std::move(named));
}

nlohmann::ordered_json SummaryJson(const ModelSummary& m, int bop_object_id) {
  return {{"name", m.name},
          {"id", m.id},
          {"bop_obj_id", bop_object_id},
          {"mesh_path", m.mesh_path},
          {"mesh_sha256", m.mesh_sha256},
          {"unit", m.unit},
          {"object_from_mesh", PoseToJson(m.object_from_mesh)},
          {"diameter_m", m.diameter_m},
          {"symmetric", m.symmetric},
          {"views", m.num_views},
          {"primitives", m.num_primitives},
          {"descriptors", m.num_descriptors},
          {"descriptor_sha256", m.descriptor_sha256},
          {"color_matrix", m.has_color_matrix},
          {"stored_mesh_bytes", m.mesh_blob_bytes},
          {"stored_bytes", StoredBytes(m)},
          {"point_pairs", PointPairsJson(m)},
          {"build_options", nlohmann::json::parse(m.build_options_json, nullptr, false)},
          {"created", m.created}};
}

int RunList(const ModeldbArgs& args) {
  const ModelDatabase database(args.db, OpenMode::kReadOnly);
  const std::vector<ModelSummary> models = database.ListModels();
  const std::map<std::string, int> object_ids = LibraryObjectIds(models);
  if (args.json) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const ModelSummary& model : models) list.push_back(SummaryJson(model, object_ids.at(model.name)));
    std::cout << list.dump(2) << '\n';
    return kExitOk;
  }
  std::printf("%s: %zu models (schema version %d)\n", args.db.c_str(), models.size(), kModelDbSchemaVersion);
  if (models.empty()) return kExitOk;
  std::printf("%-28s %6s %6s %11s %12s %12s %9s %7s %8s %10s %9s  %s\n", "name", "obj_id", "views", "primitives",
              "descriptors", "diameter_mm", "symmetric", "colour", "mesh_MB", "ppf_points", "stored_MB", "created");
  long long stored = 0;
  for (const ModelSummary& m : models) {
    const std::string mesh = m.mesh_blob_bytes > 0 ? Fixed(m.mesh_blob_bytes / 1e6, 1) : "file";  // not stored
    const long long bytes = StoredBytes(m);
    std::printf("%-28s %6d %6d %11d %12d %12.1f %9s %7s %8s %10s %9.1f  %s\n", m.name.c_str(), object_ids.at(m.name),
                m.num_views, m.num_primitives, m.num_descriptors, 1000.0 * m.diameter_m, m.symmetric ? "yes" : "no",
                m.has_color_matrix ? "yes" : "no", mesh.c_str(), PointPairsColumn(m).c_str(), bytes / 1e6,
                m.created.c_str());
    stored += bytes;
  }
  std::error_code error;
  const auto file_bytes = static_cast<long long>(std::filesystem::file_size(args.db, error));
  std::printf("stored values %.1f MB in a file of %s MB\n", stored / 1e6,
              error ? "?" : Fixed(static_cast<double>(file_bytes) / 1e6, 1).c_str());
  return kExitOk;
}

int RunInfo(const ModeldbArgs& args) {
  const ModelDatabase database(args.db, OpenMode::kReadOnly);
  const std::optional<ModelSummary> model = database.FindModel(args.model);
  if (!model) {
    std::cerr << "ecvpose: error: " << args.db << ": no model \"" << args.model << "\" (see `ecvpose modeldb list`)\n";
    return kExitBadInput;
  }
  nlohmann::ordered_json json = SummaryJson(*model, LibraryObjectIds(database.ListModels()).at(model->name));
  if (const std::optional<ColorMatrixRecord> matrix = database.GetColorMatrix(args.model)) {
    const Eigen::Matrix3d& a = matrix->model_to_scene;
    json["color_matrix"] = {
        {"model_to_scene", {{a(0, 0), a(0, 1), a(0, 2)}, {a(1, 0), a(1, 1), a(1, 2)}, {a(2, 0), a(2, 1), a(2, 2)}}},
        {"rms", matrix->rms},
        {"source", matrix->source},
        {"created", matrix->created}};
  }
  if (const std::optional<FeatureSettings> features = database.feature_settings()) {
    json["features"] = nlohmann::json::parse(FeatureSettingsToJson(*features));
  }
  if (args.json) {
    std::cout << json.dump(2) << '\n';
    return kExitOk;
  }
  for (const auto& item : json.items()) {
    std::cout << item.key() << ": "
              << (item.value().is_string() ? item.value().get<std::string>() : item.value().dump());
    if (item.key() == "diameter_m") std::cout << " (" << Fixed(1000.0 * model->diameter_m, 1) << " mm)";
    std::cout << '\n';
  }
  return kExitOk;
}

int RunRemove(const ModeldbArgs& args) {
  ModelDatabase database(args.db, OpenMode::kReadWrite);
  if (!database.RemoveModel(args.model)) {
    std::cerr << "ecvpose: error: " << args.db << ": no model \"" << args.model << "\" to remove\n";
    return kExitBadInput;
  }
  std::cout << "removed " << args.model << " from " << args.db << '\n';
  return kExitOk;
}

int RunVerify(const ModeldbArgs& args) {
  const ModelDatabase database(args.db, OpenMode::kReadOnly);
  const VerifyReport report = database.Verify(!args.quick);
  std::cout << args.db << ": " << report.models << " models, " << report.views << " views, " << report.primitives
            << " primitives, " << report.descriptors << " descriptors\n";
  for (const std::string& problem : report.problems) std::cout << "problem: " << problem << '\n';
  std::cout << (report.ok() ? "ok" : "NOT consistent") << '\n';
  return report.ok() ? kExitOk : kExitBadInput;
}

int RunExport(const ModeldbArgs& args) {
  const ModelDatabase database(args.db, OpenMode::kReadOnly);
  const std::vector<StoredModel> models = database.LoadModels({args.model});
  const ModelRecord& record = models.at(0).record;
  if (args.view >= static_cast<int>(record.views.size())) {
    ThrowInputError("--view", "view index", "0.." + std::to_string(record.views.size() - 1), std::to_string(args.view));
  }
  std::vector<Primitive> primitives;
  for (const ModelView& view : record.views) {
    if (args.view >= 0 && view.index != args.view) continue;
    primitives.insert(primitives.end(), view.primitives.begin(), view.primitives.end());
  }
  if (args.color_by == "type") {  // segments red, texlets blue (the type is also a PLY property)
    for (Primitive& p : primitives) {
      p.color =
          p.type == PrimitiveType::kSegment ? Eigen::Vector3f(1.0F, 0.1F, 0.1F) : Eigen::Vector3f(0.1F, 0.4F, 1.0F);
    }
  }
  WritePrimitivesPly(args.ply, primitives);
  std::cout << "wrote " << primitives.size() << " primitives of " << args.model << " (object frame, metres, "
            << (args.view >= 0 ? "view " + std::to_string(args.view) : "all views") << ") to " << args.ply << '\n';
  return kExitOk;
}

int RunMigrate(const ModeldbArgs& args) {
  const ModelDbMigration migration = MigrateModelDatabase(args.db);
  if (migration.steps.empty()) {
    std::cout << args.db << ": already at schema version " << migration.to_version << '\n';
    return kExitOk;
  }
  for (const std::string& step : migration.steps) std::cout << "step " << step << '\n';
  std::cout << "migrated " << args.db << " from schema version " << migration.from_version << " to "
            << migration.to_version << '\n';
  for (const std::string& note : migration.notes) std::cerr << "warning: " << args.db << ": " << note << '\n';
  return kExitOk;
}

CLI::App* AddDatabaseCommand(CLI::App& command, const char* name, const char* summary, ModeldbArgs* args) {
  CLI::App* sub = command.add_subcommand(name, summary);
  AddDbOption(*sub, &args->db);
  return sub;
}

void AddBuildFlags(CLI::App& build, ModeldbArgs* args) {
  build.add_option("MESH_OR_DIR", args->inputs, "Mesh files, or directories of <name>/<name>.obj folders")->required();
  build.add_option("--views", args->views, "Rendered views per model")->capture_default_str()->check(AtLeastOne());
  AddMeshFlags(build, &args->mesh);
  build.add_option("--name", args->name, "Model name (one mesh only; default: the file stem or folder name)");
  build.add_option("--camera", args->camera, "Intrinsics fx,fy,cx,cy of the views (default: YCB-Video's)");
  build.add_option("--size", args->size, "Image size of the views, WIDTHxHEIGHT")->capture_default_str();
  build
      .add_option("--distance", args->distance_m,
                  "Camera distance from the object centre, metres; farther if the object would not fit (0: fit)")
      ->capture_default_str()
      ->check(NonNegative());
  build
      .add_option("--shading", args->shading,
                  "auto (headlight for meshes without a texture, unlit for textured ones), unlit (colours as "
                  "stored) or headlight")
      ->check(CLI::IsMember({"auto", "unlit", "headlight"}))
      ->capture_default_str();
  build.add_flag("--symmetric", args->symmetric, "Mark the models symmetric (evaluated with ADD-S)");
  build
      .add_option("--threads", args->threads,
                  "Worker threads describing each view (the same library for any count; default: all cores)")
      ->check(ThreadCount());
  build.add_flag("--no-stored-mesh", args->no_stored_mesh,
                 "Do not store the meshes in the library: recognition then reads each mesh file (mesh_path)");
  build.add_flag("--no-ppf", args->no_point_pairs,
                 "Do not store point pair points: the models then get no shape-driven pose hypotheses "
                 "(recognize --hypotheses ppf|both)");
  build
      .add_option("--mesh-texture-size", args->mesh_texture_size,
                  "Largest side of a stored mesh's textures, pixels (larger ones are downscaled; 0: as they are)")
      ->capture_default_str()
      ->check(NonNegative());
  build.add_option("--shard", args->shard,
                   "I/N: build only part I (0 <= I < N) of N, the models split by name alike on every machine, into "
                   "a library of its own; `modeldb merge` joins the parts");
  build.add_option("--feature-settings", args->feature_settings,
                   "JSON of extraction and descriptor settings, {\"ecv\": {...}, \"descriptor\": {...}} as "
                   "`modeldb info` shows them (missing fields: defaults); for a camera not held level, "
                   "{\"descriptor\": {\"unsigned_segments\": true}} (README: the camera's roll), or the surface "
                   "context, {\"descriptor\": {\"shape\": 1}}");
  build.footer(
      "A directory holds one folder per model, <name>/<name>.obj, with object_from_mesh.json beside the mesh when\n"
      "the mesh's frame differs from the object frame; --object-from-mesh FILE overrides those for every mesh.\n"
      "Each model is stored in one transaction, with its mesh (textures at most --mesh-texture-size), so that\n"
      "recognition needs no mesh file; a model that exists is replaced. Exit code 1 if any failed.");
}

}  // namespace

CommandAction SetupModeldbCommand(CLI::App& command) {
  auto args = std::make_shared<ModeldbArgs>();
  command.require_subcommand(1);
  CLI::App* build = AddDatabaseCommand(command, "build", "Build models from meshes into the library", args.get());
  AddBuildFlags(*build, args.get());
  CLI::App* list = AddDatabaseCommand(command, "list", "List the library's models", args.get());
  list->add_flag("--json", args->json, "JSON instead of a table");
  CLI::App* info = AddDatabaseCommand(command, "info", "Describe one model", args.get());
  info->add_option("NAME", args->model, "Model name")->required();
  info->add_flag("--json", args->json, "JSON instead of text");
  CLI::App* remove = AddDatabaseCommand(command, "remove", "Remove a model with its views", args.get());
  remove->add_option("NAME", args->model, "Model name")->required();
  CLI::App* verify = AddDatabaseCommand(command, "verify", "Check the library's consistency", args.get());
  verify->add_flag("--quick", args->quick, "Skip re-hashing every model's descriptors");
  CLI::App* exported = AddDatabaseCommand(command, "export", "Write a model's primitives to a PLY", args.get());
  exported->add_option("NAME", args->model, "Model name")->required();
  exported->add_option("--ply", args->ply, "Output PLY (object frame, metres)")->required();
  exported->add_option("--view", args->view, "Only this view (default: all)");
  exported->add_option("--color-by", args->color_by, "type (segments red, texlets blue) or colour")
      ->check(CLI::IsMember({"type", "colour", "color"}))
      ->capture_default_str();
  CLI::App* migrate =
      AddDatabaseCommand(command, "migrate", "Bring a library of an older schema up to date", args.get());
  CLI::App* merge = command.add_subcommand("merge", "Join libraries (the parts of a build --shard) into one");
  merge->add_option("OUT", args->db, "The merged library (created if missing)")->required();
  merge->add_option("LIBRARY", args->shards, "Libraries built with the same feature settings")->required();
  merge->footer(
      "Models are copied in name order, each in one transaction with its colour matrix: the merged parts of a\n"
      "build equal one build of all the models. Refused before anything is written: mixed feature settings or\n"
      "schema versions, a model in two libraries. A model of OUT with the same name is replaced.");
  return [args, build, list, info, remove, verify, exported, migrate, merge]() -> int {
    if (build->parsed()) return RunBuild(*args);
    if (list->parsed()) return RunList(*args);
    if (info->parsed()) return RunInfo(*args);
    if (remove->parsed()) return RunRemove(*args);
    if (verify->parsed()) return RunVerify(*args);
    if (exported->parsed()) return RunExport(*args);
    if (migrate->parsed()) return RunMigrate(*args);
    if (merge->parsed()) return RunMerge(*args);
    return kExitBadUsage;
  };
}

}  // namespace ecv::app
