#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/frame.h"
#include "core/pose.h"

namespace ecv {

/// How a command names one frame: either one
/// positional FRAME, or the flags --color, --depth, --depth-scale and --camera.
struct FrameSpec {
  /// A frame JSON, a YCB-Video prefix (".../0001/000001"), a BOP image "SCENE_DIR:IMAGE_ID" or an
  /// organized ".pcd"; empty when the frame is given by flags.
  std::string positional;
  std::string color_path;             ///< --color: PNG or JPG
  std::string depth_path;             ///< --depth: 16-bit PNG (also overrides a BOP image's depth)
  std::optional<double> depth_scale;  ///< --depth-scale S: metres = depth value / S
  std::optional<std::string> camera;  ///< --camera "fx,fy,cx,cy" in pixels
};

/// A frame with whatever ground truth its source provides (YCB-Video, BOP; none otherwise).
struct LoadedFrame {
  RgbdFrame rgbd;
  std::vector<GroundTruth> ground_truth;
  /// BOP scene and image ids where the source names them (a YCB-Video prefix .../0001/000007: 1 and 7; a BOP image:
  /// its scene folder's number and its id; a frame JSON: its "scene_id" and "image_id"); -1 otherwise.
  int scene_id = -1;
  int image_id = -1;
};

/// The number a file or folder name spells ("000007": 7); -1 unless it is 1 to 9 decimal digits.
int NumberOfName(const std::string& name);

/// Loads the frame named by `spec`. Throws InputError naming the file and field on any broken input. Adds to
/// `warnings` what is readable but suspect (DepthRangeWarning).
LoadedFrame LoadFrame(const FrameSpec& spec, std::vector<std::string>* warnings = nullptr);

/// A warning naming `source` when the median of the measured depths (metres) lies outside 0.1-10 m, the
/// mark of a wrong depth scale (a millimetre PNG read as YCB-Video's 10 000 per metre, say): every scene
/// primitive would then be isolated and nothing found, without an error. Empty when the depths look right
/// or there are none.
std::optional<std::string> DepthRangeWarning(const cv::Mat& depth_m, const std::string& source);

/// Colour image, PNG or JPG, as CV_8UC3 RGB.
cv::Mat ReadColorImage(const std::string& path);

/// Writes a CV_8UC3 RGB (or CV_8UC1) image as PNG or JPG; throws InputError if it cannot.
void WriteColorImage(const std::string& path, const cv::Mat& image);

/// 16-bit single-channel depth PNG to CV_32FC1 metres (value / `depth_scale`, 0 stays missing).
cv::Mat ReadDepthImage(const std::string& path, double depth_scale);

/// Parses "fx,fy,cx,cy" (pixels); names `source` on errors.
std::array<double, 4> ParseIntrinsics(const std::string& text, const std::string& source);

/// Frame from a colour image, a 16-bit depth PNG, a depth scale and intrinsics {fx, fy, cx, cy} in pixels.
RgbdFrame MakeFrame(const std::string& color_path, const std::string& depth_path, double depth_scale,
                    const std::array<double, 4>& intrinsics, const std::string& source);

/// Frame JSON {"color", "depth", "depth_scale", "camera": [fx, fy, cx, cy]}, paths relative to it.
LoadedFrame LoadFrameJson(const std::string& path);

/// YCB-Video frame prefix ".../0001/000001": -color.png, -depth.png and -meta.mat (intrinsics,
/// factor_depth and the ground-truth poses).
LoadedFrame LoadYcbvFrame(const std::string& prefix);

/// `frame` with an object of another YCB-Video frame pasted in: the pixels that frame's label image
/// (`source_prefix`-label.png) gives the object, colour and depth, and its ground truth. Both frames must come
/// from one camera (InputError otherwise), so the object lies at its ground-truth pose: real pixels for testing
/// several instances of one model. InputError when the source frame lacks the object or its label pixels.
LoadedFrame PasteYcbvObject(LoadedFrame frame, const std::string& source_prefix, const std::string& object_name);

/// Writes `frame` as a frame JSON (`path`, the CLI's FRAME form) with `<stem>-color.png` and a 16-bit
/// `<stem>-depth.png` (depth value = metres x `depth_scale`) beside it; throws InputError if it cannot.
void WriteFrameJson(const std::string& path, const RgbdFrame& frame, double depth_scale = 10000.0);

/// BOP image `image_id` of `scene_dir` (scene_camera.json, scene_gt.json, scene_gt_info.json,
/// rgb/, depth/); `depth_override` replaces the depth image when not empty.
LoadedFrame LoadBopFrame(const std::string& scene_dir, int image_id, const std::string& depth_override = "");

/// Ground truth of BOP image `image_id` from `scene_dir`/scene_gt.json (poses, millimetres -> metres) and
/// scene_gt_info.json when present, without reading any image. Empty when the scene has no scene_gt.json;
/// throws InputError naming the file when it lacks the image or is malformed.
std::vector<GroundTruth> ReadBopGroundTruth(const std::string& scene_dir, int image_id);

/// The frames of a sequence, in order, as FRAME strings that LoadFrame accepts. `dir_or_list` is one of:
/// - a BOP scene folder (has scene_camera.json): "SCENE_DIR:ID" for every image id of scene_camera.json, in
///   increasing order, whose rgb/ (PNG or JPG; or gray/) and depth/ PNG files both exist;
/// - a YCB-Video video folder (prefixes of its *-color.png files) and/or frame JSONs (*.json), in name order;
/// - a text file with one FRAME per line ('#' starts a comment, blank lines are skipped).
/// Throws InputError naming the path when it is none of these or yields no frame (e.g. a BOP scene without
/// a depth/ folder).
std::vector<std::string> ListSequenceFrames(const std::string& dir_or_list);

/// Organized point cloud with colour (x y z rgb/rgba): depth = z, intrinsics fitted to the points.
LoadedFrame LoadPcdFrame(const std::string& path);

/// Organized cloud (CV_32FC3 metres, NaN missing) and colours (CV_8UC3 RGB) of a .pcd file.
void ReadOrganizedPcd(const std::string& path, cv::Mat* points, cv::Mat* color);

/// Name of a YCB-Video class index 1..21 ("003_cracker_box"); throws for other values.
std::string YcbvClassName(int cls_index);

}  // namespace ecv
