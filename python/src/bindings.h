#pragma once

#include <pybind11/pybind11.h>

namespace ecv::python {

namespace py = pybind11;

/// ModelLibrary, Model, build_models and render.
void BindLibrary(py::module_& m);

/// Frame, load_frame, Detection and Recognizer.
void BindRecognizer(py::module_& m);

/// Camera and open_camera (OpenNI2 devices and .oni recordings); after BindRecognizer, which binds Frame.
void BindCamera(py::module_& m);

inline constexpr const char* kBuildModelsDoc = R"(Builds a model library from meshes, as `ecvpose modeldb build` does.

db: the library's path (created if missing; a model of the same name is replaced).
meshes: a mesh file or a directory of <name>/<name>.obj folders, or a list of them.
name: the model's name (one mesh only; default: the file stem or folder name).
unit: "m", "cm" or "mm", the unit of the mesh's coordinates.
object_from_mesh: a 4x4 pose or the path of a JSON file with one ("object_from_mesh"); default: the
    object_from_mesh.json beside each mesh, if there is one.
symmetric: mark the models symmetric (evaluated with ADD-S).
allow_missing_textures: build with default colours where a texture or material file is missing.
views, distance: rendered views per model, and their distance from the object centre in metres.
camera, size: the views' 3x3 intrinsics (default: YCB-Video's) and (width, height).
shading: "auto", "unlit" or "headlight".
threads: worker threads, 0 (every core) or 1 to 256; the library is the same for any count.
stored_mesh, mesh_texture_size: store each mesh in the library (textures at most this many pixels a side).
point_pairs: store each model's point pair points (shape-driven hypotheses; False: as `--no-ppf`).
feature_settings: a dict of extraction and descriptor settings as `ecvpose modeldb info` shows them.
shard: (part, parts): only the models of that part, 0 <= part < parts, split by name alike on every machine (as
    `modeldb build --shard part/parts`); merge_libraries joins the parts' libraries.
progress: called as progress(model, view, views) after each view.

Returns the names of the models built. Raises InputError naming each model that failed, after building the others.)";

inline constexpr const char* kRecognizerDoc = R"(Recognizer(library, **options): a recognizer over `library`.

The options are the settings of `ecvpose recognize`, its flags with underscores (views_per_model for
--views-per-model; icp and contour, True by default, for --no-icp and --no-contour), with the same defaults but
threads=2 (the CLI takes every core). An unknown keyword or a value out of range raises InputError naming it.
Recognizer.settings shows the values a recognizer runs with.

Loads the models' meshes for verification (about a second for seven models).)";

}  // namespace ecv::python
