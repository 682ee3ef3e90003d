// YCB-Video frames: <prefix>-color.png, <prefix>-depth.png and <prefix>-meta.mat (MATLAB v5, read with
// matio): intrinsic_matrix (3x3), factor_depth, cls_indexes (N), poses (3x4xN, model to camera, metres).

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include <matio.h>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/image_bytes.h"
#include "io/mat_check.h"

namespace ecv {
namespace {

struct MatFileCloser {
  void operator()(mat_t* file) const { Mat_Close(file); }
};
struct MatVarFreer {
  void operator()(matvar_t* variable) const { Mat_VarFree(variable); }
};

// A numeric MATLAB array as doubles in MATLAB's column-major order, with its dimensions.
struct MatArray {
  std::vector<double> values;
  std::vector<size_t> dims;
};

template <typename T>
void AppendAs(const void* data, size_t count, std::vector<double>* out) {
  const T* typed = static_cast<const T*>(data);
  out->assign(typed, typed + count);
}

// The variable `name`, of at most `max_values` values: its header is read first, so that dimensions the meta file
// cannot have are refused before matio allocates for them.
MatArray ReadNumeric(mat_t* file, const std::string& path, const char* name, size_t max_values) {
  {
    std::unique_ptr<matvar_t, MatVarFreer> info(Mat_VarReadInfo(file, name));
    if (!info) ThrowInputError(path, name, "a numeric variable", "none");
    double values = 1.0;
    for (int i = 0; i < info->rank; ++i) values *= static_cast<double>(info->dims[i]);
    if (info->rank < 0 || info->rank > 8 || !(values <= static_cast<double>(max_values))) {
      ThrowInputError(path, name, "an array of at most " + std::to_string(max_values) + " values",
                      std::to_string(values));
    }
  }
  std::unique_ptr<matvar_t, MatVarFreer> variable(Mat_VarRead(file, name));
  if (!variable) ThrowInputError(path, name, "a numeric variable", "none");
  MatArray array;
  size_t count = 1;
  for (int i = 0; i < variable->rank; ++i) {
    array.dims.push_back(variable->dims[i]);
    count *= variable->dims[i];
  }
  if (variable->isComplex || variable->data == nullptr) ThrowInputError(path, name, "a real numeric array");
  switch (variable->class_type) {
    case MAT_C_DOUBLE: AppendAs<double>(variable->data, count, &array.values); break;
    case MAT_C_SINGLE: AppendAs<float>(variable->data, count, &array.values); break;
    case MAT_C_UINT8: AppendAs<uint8_t>(variable->data, count, &array.values); break;
    case MAT_C_INT32: AppendAs<int32_t>(variable->data, count, &array.values); break;
    case MAT_C_UINT16: AppendAs<uint16_t>(variable->data, count, &array.values); break;
    case MAT_C_INT64: AppendAs<int64_t>(variable->data, count, &array.values); break;
    default: ThrowInputError(path, name, "a double, single or integer array");
  }
  return array;
}

}  // namespace

std::string YcbvClassName(int cls_index) {
  static const std::array<const char*, 21> kNames = {"002_master_chef_can",
                                                     "003_cracker_box",
                                                     "004_sugar_box",
                                                     "005_tomato_soup_can",
                                                     "006_mustard_bottle",
                                                     "007_tuna_fish_can",
                                                     "008_pudding_box",
                                                     "009_gelatin_box",
                                                     "010_potted_meat_can",
                                                     "011_banana",
                                                     "019_pitcher_base",
                                                     "021_bleach_cleanser",
                                                     "024_bowl",
                                                     "025_mug",
                                                     "035_power_drill",
                                                     "036_wood_block",
                                                     "037_scissors",
                                                     "040_large_marker",
                                                     "051_large_clamp",
                                                     "052_extra_large_clamp",
                                                     "061_foam_brick"};
  if (cls_index < 1 || cls_index > static_cast<int>(kNames.size())) {
    ThrowInputError("YCB-Video", "cls_index", "a class index in 1..21", std::to_string(cls_index));
  }
  return kNames[static_cast<size_t>(cls_index - 1)];
}

LoadedFrame LoadYcbvFrame(const std::string& prefix) {
  const std::string meta_path = prefix + "-meta.mat";
  // matio sizes its reads from the file's counts alone: the structure is checked first (io/mat_check.h).
  CheckMatFile(meta_path);
  std::unique_ptr<mat_t, MatFileCloser> file(Mat_Open(meta_path.c_str(), MAT_ACC_RDONLY));
  if (!file) ThrowInputError(meta_path, "meta", "a readable MATLAB file (YCB-Video -meta.mat)");

  // A frame holds each of the 21 classes at most a few times: 1000 objects is far beyond any real frame, and keeps a
  // broken file from costing more than a few hundred kilobytes.
  constexpr size_t kMaxObjects = 1000;
  const MatArray intrinsics = ReadNumeric(file.get(), meta_path, "intrinsic_matrix", 9);
  if (intrinsics.values.size() != 9) ThrowInputError(meta_path, "intrinsic_matrix", "a 3x3 matrix");
  const MatArray factor = ReadNumeric(file.get(), meta_path, "factor_depth", 1);
  if (factor.values.size() != 1) ThrowInputError(meta_path, "factor_depth", "a scalar");
  const MatArray classes = ReadNumeric(file.get(), meta_path, "cls_indexes", kMaxObjects);
  const MatArray poses = ReadNumeric(file.get(), meta_path, "poses", 12 * kMaxObjects);
  const size_t num_objects = classes.values.size();
  if (poses.values.size() != 12 * num_objects || poses.dims.size() < 2 || poses.dims[0] != 3 || poses.dims[1] != 4) {
    ThrowInputError(meta_path, "poses", "3x4xN with N = " + std::to_string(num_objects) + " (cls_indexes)");
  }

  // Column-major: element (r, c) of a 3x3 is values[r + 3 c]; of pose n, values[r + 3 c + 12 n].
  const std::vector<double>& k = intrinsics.values;
  const std::array<double, 4> camera = {k[0], k[4], k[6], k[7]};
  // The meta file's values are its errors, before an image is read.
  CheckDepthScale(factor.values[0], meta_path, "factor_depth");
  CheckIntrinsics(camera, meta_path, "intrinsic_matrix");
  LoadedFrame loaded;
  loaded.rgbd = MakeFrame(prefix + "-color.png", prefix + "-depth.png", factor.values[0], camera, prefix);
  const std::filesystem::path name(prefix);
  loaded.scene_id = NumberOfName(name.parent_path().filename().string());
  loaded.image_id = loaded.scene_id >= 0 ? NumberOfName(name.filename().string()) : -1;
  if (loaded.image_id < 0) loaded.scene_id = -1;
  for (size_t n = 0; n < num_objects; ++n) {
    Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) matrix(r, c) = poses.values[static_cast<size_t>(r + 3 * c) + 12 * n];
    }
    GroundTruth truth;
    const double index = classes.values[n];
    if (!(index >= 1.0 && index <= 21.0 && index == std::floor(index))) {
      ThrowInputError(meta_path, "cls_indexes[" + std::to_string(n) + "]", "a class index in 1..21",
                      std::to_string(index));
    }
    truth.object_id = static_cast<int>(index);
    truth.object_name = YcbvClassName(truth.object_id);
    truth.camera_from_object = RigidFromMatrix(matrix, meta_path, "poses[" + std::to_string(n) + "]");
    loaded.ground_truth.push_back(truth);
  }
  return loaded;
}

LoadedFrame PasteYcbvObject(LoadedFrame frame, const std::string& source_prefix, const std::string& object_name) {
  const LoadedFrame source = LoadYcbvFrame(source_prefix);
  const PinholeCamera& into = frame.rgbd.camera;
  const PinholeCamera& from = source.rgbd.camera;
  if (from.fx != into.fx || from.fy != into.fy || from.cx != into.cx || from.cy != into.cy ||
      from.width != into.width || from.height != into.height) {
    ThrowInputError(source_prefix + "-meta.mat", "intrinsic_matrix", "the camera of the frame pasted into");
  }
  const auto truth = std::find_if(source.ground_truth.begin(), source.ground_truth.end(),
                                  [&](const GroundTruth& g) { return g.object_name == object_name; });
  if (truth == source.ground_truth.end()) ThrowInputError(source_prefix + "-meta.mat", "cls_indexes", object_name);
  const std::string label_path = source_prefix + "-label.png";
  const cv::Mat labels = ReadImageFile(label_path, "label");
  if (labels.size() != source.rgbd.depth.size() || labels.depth() != CV_8U || labels.channels() != 1) {
    ThrowInputError(label_path, "label", "an 8-bit one-channel PNG of the frame's size");
  }
  const cv::Mat object = labels == truth->object_id;
  if (cv::countNonZero(object) == 0) {
    ThrowInputError(label_path, "label",
                    "pixels of class " + std::to_string(truth->object_id) + " (" + object_name + ")");
  }
  source.rgbd.color.copyTo(frame.rgbd.color, object);
  source.rgbd.depth.copyTo(frame.rgbd.depth, object);
  frame.ground_truth.push_back(*truth);
  return frame;
}

}  // namespace ecv
