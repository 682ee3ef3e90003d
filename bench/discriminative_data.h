#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/frame.h"
#include "ecv/primitives.h"
#include "render/renderer.h"

namespace ecv::bench {

/// One view of an object: an image, the object's pixels and its pose in the view's camera.
struct ObjectView {
  std::string name;  ///< e.g. "0001/000007" or "rendered view 42"
  RgbdFrame rgbd;
  cv::Mat mask;                          ///< CV_8UC1, the object's pixels
  Eigen::Isometry3d camera_from_object;  ///< metres
};

/// The sets of view pairs, in the order the report shows them.
inline const std::vector<std::string> kPairSets = {"recognition", "recognition in clutter", "hard", "easy"};

/// Two views of one object with known relative pose: query (model side) and train (scene side).
struct ViewPair {
  std::string set;     ///< one of kPairSets
  std::string object;  ///< "003_cracker_box"
  bool held_out;       ///< from video 0002: not used to choose parameters
  ObjectView query, train;
  /// The train view is the whole frame, as a recognition scene is: keypoints and descriptor support everywhere,
  /// the clutter included, so that a query can also match the wrong object. Otherwise both views are cut to
  /// the object's pixels.
  bool clutter = false;

  Eigen::Isometry3d TrainFromQuery() const { return train.camera_from_object * query.camera_from_object.inverse(); }
};

/// The pairs of the four sets on the YCB-Video frames under `data_dir` (renders with OSMesa); the set
/// "recognition in clutter" holds the recognition pairs again with `clutter` set. The library
/// views are rendered `library_distance_m` from the object centre (0: as close as fits the image) with
/// `shading`.
std::vector<ViewPair> LoadViewPairs(const std::string& data_dir, double library_distance_m = 0.0,
                                    Shading shading = Shading::kUnlit);

}  // namespace ecv::bench
