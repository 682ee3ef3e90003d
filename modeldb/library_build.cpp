#include "modeldb/library_build.h"

#include <exception>
#include <filesystem>
#include <map>
#include <optional>
#include <utility>

#include "core/error.h"
#include "modeldb/sql.h"
#include "render/renderer.h"

namespace ecv {

LibraryBuildSummary BuildLibrary(const std::string& db_path, const std::vector<ModelSource>& sources,
                                 const ModelBuildOptions& options, const LibraryBuildReporter& reporter) {
  ModelDatabase database(db_path, OpenMode::kCreate);
  Renderer renderer;
  LibraryBuildSummary summary;
  for (size_t i = 0; i < sources.size(); ++i) {
    const ModelSource& source = sources[i];
    if (reporter.started) reporter.started(source, static_cast<int>(i) + 1, static_cast<int>(sources.size()));
    try {
      const BuildResult built = BuildModel(source, options, renderer, [&](const BuildProgress& progress) {
        if (reporter.progress) reporter.progress(source, progress);
      });
      const AddModelResult added = database.AddModel(built.record);
      summary.built.push_back(built.record.name);
      if (reporter.stored) reporter.stored(source, built, added);
    } catch (const InputError& error) {
      summary.failed.push_back(source.name);
      if (reporter.failed) reporter.failed(source, error.what());
    } catch (const SqlError& error) {
      summary.failed.push_back(source.name);
      if (reporter.failed) reporter.failed(source, error.what());
    } catch (const std::exception& error) {  // out of memory, a library's own error: this model's, not the build's
      summary.failed.push_back(source.name);
      if (reporter.failed) reporter.failed(source, source.mesh_path + ": " + error.what());
    }
  }
  return summary;
}

namespace {

// The library's feature settings as JSON; empty while it holds no model.
std::string SettingsText(const ModelDatabase& library) {
  const std::optional<FeatureSettings> settings = library.feature_settings();
  return settings ? FeatureSettingsToJson(*settings) : std::string();
}

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code error;
  return std::filesystem::equivalent(a, b, error) && !error;
}

}  // namespace

int MergeLibraries(const std::string& out_path, const std::vector<std::string>& shard_paths,
                   const LibraryMergeReporter& reporter) {
  std::vector<ModelDatabase> shards;
  std::map<std::string, size_t> shard_of_model;  // name -> index into shards, in name order
  std::string settings, settings_from;
  for (const std::string& path : shard_paths) {
    if (SameFile(path, out_path)) ThrowInputError(path, "shard", "a library other than the merged one", out_path);
    shards.emplace_back(path, OpenMode::kReadOnly);
    const std::string shard_settings = SettingsText(shards.back());
    if (!shard_settings.empty() && !settings.empty() && shard_settings != settings) {
      ThrowInputError(path, "feature settings",
                      "those of " + settings_from + ": the parts of one library are built with the same settings",
                      shard_settings);
    }
    if (settings.empty()) {
      settings = shard_settings;
      settings_from = path;
    }
    for (const ModelSummary& model : shards.back().ListModels()) {
      const auto [place, added] = shard_of_model.emplace(model.name, shards.size() - 1);
      if (!added) {
        ThrowInputError(path, "model \"" + model.name + "\"", "each model in one shard only",
                        "also in " + shard_paths[place->second]);
      }
    }
  }
  ModelDatabase out(out_path, OpenMode::kCreate);
  const std::string out_settings = SettingsText(out);
  if (!out_settings.empty() && !settings.empty() && out_settings != settings) {
    ThrowInputError(settings_from, "feature settings", "those of the library merged into, " + out_path, settings);
  }
  int number = 0;
  for (const auto& [name, shard] : shard_of_model) {
    out.AddModel(shards[shard].LoadModels({name}).front());
    if (reporter.copied) reporter.copied(name, shard_paths[shard], ++number, static_cast<int>(shard_of_model.size()));
  }
  return static_cast<int>(shard_of_model.size());
}

}  // namespace ecv
