#include "modeldb/library_build.h"

#include <exception>

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

}  // namespace ecv
