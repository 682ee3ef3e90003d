#pragma once

// BOP's localisation task (Hodaň et al., BOP Challenge 2019/2020): per test image, the objects to find and how many
// instances of each (test_targets_bop19.json), and the results as BOP's CSV (scene_id,im_id,obj_id,score,R,t,time).

#include <map>
#include <ostream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/pose.h"
#include "modeldb/model_library.h"
#include "recognize/detection.h"

namespace ecv {

/// One entry of a BOP targets file: in image `image_id` of scene `scene_id`, `instances` instances of `object_id`.
struct BopTarget {
  int scene_id = 0;
  int image_id = 0;
  int object_id = 0;
  int instances = 0;
};

/// The entries of a BOP targets file (a JSON array of {"scene_id", "im_id", "obj_id", "inst_count"}), in file order.
/// Throws InputError naming the file, the entry and the field.
std::vector<BopTarget> ReadBopTargets(const std::string& path);

/// A test image and its targets.
struct BopImage {
  int scene_id = 0;
  int image_id = 0;
  std::map<int, int> objects;  ///< obj_id -> instances

  std::pair<int, int> key() const { return {scene_id, image_id}; }
};

/// The images of `targets` in order of scene, then image, each with its objects; an object listed twice for one
/// image is an InputError naming `source`.
std::vector<BopImage> GroupBopTargets(const std::vector<BopTarget>& targets, const std::string& source);

/// `image`'s targets as library model names -> instances, by the BOP object id of each model (`model_of_object`);
/// the ids without a model go to `missing` when given.
std::map<std::string, int> TargetModels(const BopImage& image, const std::map<int, std::string>& model_of_object,
                                        std::set<int>* missing = nullptr);

/// The BOP object id of each model of `library` (BopObjectIds: "obj_000005" is 5, a YCB-Video name its class
/// index, other names an id of their own), by model name.
std::map<std::string, int> LibraryObjectIds(const ModelLibrary& library);

/// The inverse: each object id's model.
std::map<int, std::string> ModelOfObject(const std::map<std::string, int>& object_ids);

/// Each ground-truth instance whose name is no model of the library but whose dataset id is the BOP object id of one
/// (`model_of_object`) renamed after that model: a BOP frame's obj_000001 is the library's 002_master_chef_can.
void NameTruthAfterModels(const std::map<int, std::string>& model_of_object, std::vector<GroundTruth>* truth);

/// BOP's CSV header line, with its newline.
inline constexpr const char* kBopCsvHeader = "scene_id,im_id,obj_id,score,R,t,time\n";

/// One BOP CSV row per detection: R row-major, t in millimetres, `seconds` the image's time (BOP: the same for every
/// estimate of an image). `object_ids` gives each model's obj_id.
void WriteBopRows(std::ostream& out, std::pair<int, int> scene_image, const std::vector<Detection>& detections,
                  const std::map<std::string, int>& object_ids, double seconds);

/// The estimates of a BOP CSV by (scene_id, im_id), each named by its library model (`model_of_object`), in file
/// order. Throws InputError naming the file, the line and the field (a bad header, a malformed row, an obj_id
/// without a model).
std::map<std::pair<int, int>, std::vector<Detection>> ReadBopResults(const std::string& path,
                                                                     const std::map<int, std::string>& model_of_object);

}  // namespace ecv
