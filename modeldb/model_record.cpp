#include "modeldb/model_record.h"

#include <algorithm>
#include <set>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/mesh_blob.h"
#include "io/mesh_io.h"
#include "modeldb/content_hash.h"

namespace ecv {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "descriptors are stored as little-endian float32");

// Every field of the options, once, for writing and reading alike: visit(group, key, field). A field added
// to EcvOptions or DescriptorOptions must be added here too, or a library would not record it.
template <typename Settings, typename Visit>
void VisitFields(Settings& settings, Visit visit) {
  auto& e = settings.ecv;
  visit("ecv", "wavelength_px", e.monogenic.wavelength_px);
  visit("ecv", "sigma_on_f", e.monogenic.sigma_on_f);
  visit("ecv", "grid_spacing_px", e.grid_spacing_px);
  visit("ecv", "min_magnitude", e.min_magnitude);
  visit("ecv", "max_edge_variance", e.max_edge_variance);
  visit("ecv", "edge_nms", e.edge_nms);
  visit("ecv", "surface_radius_m", e.surface_radius_m);
  visit("ecv", "depth_gap_m", e.depth_gap_m);
  visit("ecv", "color_radius_px", e.color_radius_px);
  auto& d = settings.descriptor;
  visit("descriptor", "radius_m", d.radius_m);
  visit("descriptor", "max_neighbours", d.max_neighbours);
  visit("descriptor", "unsigned_segments", d.unsigned_segments);
  visit("descriptor", "soft_binning", d.soft_binning);
  visit("descriptor", "use_color", d.use_color);
  visit("descriptor", "balance_colors", d.balance_colors);
  visit("descriptor", "hellinger", d.hellinger);
  visit("descriptor", "pairs", d.pairs);            // DescriptorPairs as its integer value
  visit("descriptor", "appearance", d.appearance);  // DescriptorAppearance as its integer value
  visit("descriptor", "closeness_weight", d.closeness_weight);
  visit("descriptor", "shells", d.shells);
  visit("descriptor", "shape", d.shape);  // DescriptorShape as its integer value
  visit("descriptor", "surface_weight", d.surface_weight);
}

nlohmann::ordered_json ToJson(const FeatureSettings& settings) {
  nlohmann::ordered_json json;
  VisitFields(settings, [&](const char* group, const char* key, const auto& field) { json[group][key] = field; });
  return json;
}

// Reads `key` of `object` into `value` when present; InputError naming the source and key on a wrong type.
template <typename T>
void Read(const nlohmann::json& object, const char* key, T* value, const std::string& source) {
  if (!object.contains(key)) return;
  try {
    *value = object.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    ThrowInputError(source, key, "a value of the option's type", object.at(key).dump());
  }
}

// Unknown keys mean settings this version cannot apply: recognition would extract different features.
void RejectUnknown(const nlohmann::json& object, const nlohmann::ordered_json& known, const std::string& source) {
  for (const auto& item : object.items()) {
    if (!known.contains(item.key())) {
      ThrowInputError(source, item.key(), "a setting this ecvpose knows (written by a newer version?)");
    }
  }
}

// The object number a BOP or YCB-Video name stands for ("obj_000005": 5, "003_cracker_box": 2); none for another name.
std::optional<int> DatasetObjectId(const std::string& name) {
  if (name.size() > 4 && name.size() <= 13 && name.rfind("obj_", 0) == 0 &&
      name.find_first_not_of("0123456789", 4) == std::string::npos) {
    return std::stoi(name.substr(4));
  }
  for (int id = 1; id <= 21; ++id) {
    if (YcbvClassName(id) == name) return id;
  }
  return std::nullopt;
}

}  // namespace

std::string FeatureSettingsToJson(const FeatureSettings& settings) {
  return ToJson(settings).dump();
}

FeatureSettings StoredFeatureDefaults() {
  return {EcvOptions{}, DescriptorOptions{}};
}

FeatureSettings FeatureSettingsFromJson(const std::string& text, const std::string& source,
                                        const FeatureSettings& missing) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (!json.is_object()) ThrowInputError(source, "feature settings", "a JSON object", text.substr(0, 80));
  FeatureSettings settings = missing;
  const nlohmann::ordered_json known = ToJson(settings);
  RejectUnknown(json, known, source);
  const nlohmann::json ecv = json.value("ecv", nlohmann::json::object());
  const nlohmann::json descriptor = json.value("descriptor", nlohmann::json::object());
  RejectUnknown(ecv, known["ecv"], source + ": ecv");
  RejectUnknown(descriptor, known["descriptor"], source + ": descriptor");
  VisitFields(settings, [&](const std::string& group, const char* key, auto& field) {
    Read(group == "ecv" ? ecv : descriptor, key, &field, source);
  });
  return settings;
}

int BopObjectId(const std::string& name, int64_t library_id) {
  return DatasetObjectId(name).value_or(static_cast<int>(library_id));
}

std::map<std::string, int> BopObjectIds(std::vector<std::pair<std::string, int64_t>> models) {
  std::sort(models.begin(), models.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  std::map<std::string, int> ids;
  std::set<int> taken;
  auto claim = [&](const std::string& name, int id) {
    if (ids.count(name) > 0 || taken.count(id) > 0) return;
    ids[name] = id;
    taken.insert(id);
  };
  // Dataset names claim their ids first, then the other models their library numbers; a model whose id is held
  // gets the next number above all given, in library order.
  for (const auto& [name, library_id] : models) {
    if (const std::optional<int> id = DatasetObjectId(name)) claim(name, *id);
  }
  for (const auto& [name, library_id] : models) claim(name, static_cast<int>(library_id));
  for (const auto& [name, library_id] : models) {
    if (ids.count(name) == 0) claim(name, taken.empty() ? 1 : *taken.rbegin() + 1);
  }
  return ids;
}

int ModelRecord::NumPrimitives() const {
  size_t count = 0;
  for (const ModelView& view : views) count += view.primitives.size();
  return static_cast<int>(count);
}

int ModelRecord::NumDescriptors() const {
  int count = 0;
  for (const ModelView& view : views) count += view.descriptors.values.rows;
  return count;
}

std::string ModelRecord::DescriptorSha256() const {
  Sha256 hash;
  for (const ModelView& view : views) {
    const cv::Mat& values = view.descriptors.values;
    for (int row = 0; row < values.rows; ++row) hash.Update(values.ptr<float>(row), kDescriptorSize * sizeof(float));
  }
  return hash.HexDigest();
}

long long StoredBytes(const ModelSummary& model) {
  constexpr long long kDescriptorBytes = kDescriptorSize * sizeof(float);
  constexpr long long kPrimitiveBytes = 13 * 8;  // position, orientation, colour, image position, magnitude, angle
  constexpr long long kPointBytes = 6 * sizeof(float);  // position and normal
  return model.num_descriptors * kDescriptorBytes + model.num_primitives * kPrimitiveBytes + model.mesh_blob_bytes +
         std::max(0, model.point_pair_points) * kPointBytes;
}

TriangleMesh ModelMesh(const ModelRecord& record, bool with_textures, std::vector<std::string>* warnings) {
  if (!record.mesh_blob.empty()) {
    return DecodeMeshBlob(record.mesh_blob.data(), record.mesh_blob.size(), "model " + record.name + ": stored mesh",
                          with_textures);
  }
  MeshLoadOptions load;
  load.metres_per_unit = MetresPerUnit(record.unit);
  load.object_from_mesh = record.object_from_mesh;
  load.allow_missing_textures = true;
  return LoadMesh(record.mesh_path, load, warnings);
}

}  // namespace ecv
