#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "core/camera.h"
#include "core/mesh.h"
#include "ecv/descriptor.h"
#include "ecv/primitives.h"
#include "modeldb/point_pair_record.h"

namespace ecv {

/// The feature settings of a library: every model in one library is built with the same ones, and
/// recognition extracts the scene's features with them too.
struct FeatureSettings {
  EcvOptions ecv;
  DescriptorOptions descriptor = DescriptorOptions::SourceShells();
};

/// What a stored field that is missing meant when it was written: libraries from before the descriptor's
/// `pairs` and `shells` fields existed were built with all pairs in one shell (DescriptorOptions' field defaults).
FeatureSettings StoredFeatureDefaults();

/// The settings as canonical JSON text (every field, fixed order), as stored in the library.
std::string FeatureSettingsToJson(const FeatureSettings& settings);

/// Settings from JSON text; fields that are missing take their values from `missing` (a user's partial
/// settings: today's defaults; a library's stored ones: StoredFeatureDefaults()). Throws InputError naming
/// `source`.
FeatureSettings FeatureSettingsFromJson(const std::string& text, const std::string& source,
                                        const FeatureSettings& missing = {});

/// One rendered view of a library model.
struct ModelView {
  int index = 0;                                                         ///< 0.. within the model
  PinholeCamera camera;                                                  ///< intrinsics it was rendered with
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();  ///< metres
  std::vector<Primitive> primitives;  ///< object frame (positions in metres, orientations unit vectors)
  Descriptors descriptors;            ///< rows refer to `primitives` (only primitives with a context have one)
};

/// A whole library model: where it came from, how it was built, and its views.
struct ModelRecord {
  int64_t id = 0;           ///< the model's number in its library (0: not stored yet), kept when it is built again
  std::string name;         ///< unique in a library
  std::string mesh_path;    ///< the mesh file it was built from
  std::string mesh_sha256;  ///< SHA-256 of the mesh file followed by its texture files
  std::string unit = "m";   ///< unit of the mesh file's coordinates: "m", "cm" or "mm"
  /// Applied to the mesh after the unit change: x_object = R x_mesh + t (metres).
  Eigen::Isometry3d object_from_mesh = Eigen::Isometry3d::Identity();
  double diameter_m = 0.0;         ///< largest distance between two vertices, metres
  bool symmetric = false;          ///< evaluated with ADD-S instead of ADD
  std::string build_options_json;  ///< how the views were made (views, camera, distance, shading), JSON
  FeatureSettings features;        ///< extraction and descriptor settings used
  std::vector<ModelView> views;
  /// The mesh as rendered (object frame, metres, textures capped), packed by io/mesh_blob.h, so that verification
  /// needs no mesh file; empty when not stored (a model of a schema-1 library, or built with store_mesh off):
  /// ModelMesh then reads mesh_path.
  std::vector<unsigned char> mesh_blob;
  /// Its point pair points; nullopt when none were made (built without them, or migrated without a stored mesh).
  std::optional<PointPairRecord> point_pairs;

  int NumPrimitives() const;
  int NumDescriptors() const;
  /// SHA-256 of all descriptor values (float32, little-endian) in view and row order: equal digests mean
  /// the descriptors are equal bit for bit.
  std::string DescriptorSha256() const;
};

/// The BOP obj_id a model asks for: the number of a BOP name ("obj_000005": 5), the class index of a YCB-Video
/// name ("003_cracker_box": 2), else its number in the library (`library_id`).
/// Two models may ask for the same id: a library's ids come from BopObjectIds.
int BopObjectId(const std::string& name, int64_t library_id);

/// The BOP obj_id of every model of a library (name and library id, any order), one id per model: BopObjectId's,
/// unless another model holds it. Dataset names claim their ids first, then the others their library numbers; a
/// model whose id is held gets the next number above all given, in library id order.
std::map<std::string, int> BopObjectIds(std::vector<std::pair<std::string, int64_t>> models);

/// The mesh of a library model in the object frame (metres): the stored one (mesh_blob) when there is one, else
/// its mesh file (mesh_path with the record's unit and object_from_mesh; missing textures tolerated, as in the
/// build). Without `with_textures`, geometry alone (a stored mesh's textures are not decoded). Throws InputError
/// naming the model for stored bytes that do not decode, or the file for one that cannot be read; `warnings` (may
/// be null) receives what the file's loader tolerated.
TriangleMesh ModelMesh(const ModelRecord& record, bool with_textures = true,
                       std::vector<std::string>* warnings = nullptr);

/// A 3x3 colour matrix of a model (paper Sect. IV-C): c_scene = model_to_scene * c_model (RGB in [0, 1]).
struct ColorMatrixRecord {
  Eigen::Matrix3d model_to_scene = Eigen::Matrix3d::Identity();
  double rms = 0.0;     ///< RMS residual of the fit, colour units in [0, 1]
  std::string source;   ///< how it was fitted, e.g. "pairs:bench/pairs.csv" or "auto:0001/000001"
  std::string created;  ///< UTC time of storing, ISO 8601 (set by the database)
};

/// A model as loaded from a library: its record and its colour matrix, read in one transaction.
struct StoredModel {
  ModelRecord record;
  std::optional<ColorMatrixRecord> color_matrix;  ///< nullopt when not calibrated
};

/// What the database says about one model, without its views.
struct ModelSummary {
  int64_t id = 0;  ///< the model's number in its library, kept when the model is built again
  std::string name;
  std::string mesh_path;
  std::string mesh_sha256;
  std::string unit;
  Eigen::Isometry3d object_from_mesh = Eigen::Isometry3d::Identity();
  double diameter_m = 0.0;
  bool symmetric = false;
  std::string build_options_json;
  int num_views = 0;
  int num_primitives = 0;
  int num_descriptors = 0;
  std::string descriptor_sha256;
  bool has_color_matrix = false;
  long long mesh_blob_bytes = 0;  ///< size of the stored mesh; 0 when the model reads its mesh file
  /// Stored point pair points: -1 when none were made (built without them, or migrated without a stored mesh), 0
  /// when the mesh was refused (point_pair_refusal says why).
  int point_pair_points = -1;
  long long point_pairs = 0;       ///< pairs in their table
  std::string point_pair_refusal;  ///< why the mesh has no point pairs
  std::string created;             ///< UTC time of storing, ISO 8601
};

/// The bytes of a model's stored values: its descriptors (kDescriptorSize float32 each), its primitives' 13 numbers
/// (8 bytes each), its mesh and its point pair points (6 float32 each). The library file holds these and, about 10 %
/// more, the rows' keys and SQLite's pages.
long long StoredBytes(const ModelSummary& model);

}  // namespace ecv
