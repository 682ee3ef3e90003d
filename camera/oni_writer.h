#pragma once

// Writes RGB-D frames as an ONI recording that OpenNI2's own file driver plays (openni::Device::open(path)), for
// frames that never came from an OpenNI2 device: OpenNI2's recorder only records the streams of an opened device.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/frame.h"

namespace ecv {

class AtomicFile;

/// Units of a recording's 16-bit depth values (OpenNI2's pixel formats DEPTH_1_MM and DEPTH_100_UM).
enum class OniDepthUnit { kMillimetre, kHundredMicrometres };

/// Depth values per metre of `unit`: 1000 or 10 000.
double DepthValuesPerMetre(OniDepthUnit unit);

/// The unit that holds `depth_m` (CV_32FC1 metres) exactly: the first of 100 um and 1 mm whose 16-bit values read back
/// (value / values per metre, as the frame readers convert) to the same floats; 100 um when neither does. Sets
/// `exact` to whether it does.
OniDepthUnit ExactDepthUnit(const cv::Mat& depth_m, bool* exact);

/// `depth_m` (CV_32FC1 metres, 0 = missing) as CV_16UC1 values of `unit`, rounded to the nearest. Throws InputError
/// naming `source` for depths beyond 65535 units (6.5 m at 100 um, 65 m at 1 mm).
cv::Mat DepthValues(const cv::Mat& depth_m, OniDepthUnit unit, const std::string& source);

/// What a recording holds: one depth and one colour stream of one size.
struct OniWriterOptions {
  int width = 0;   ///< pixels, both images
  int height = 0;  ///< pixels, both images
  OniDepthUnit depth_unit = OniDepthUnit::kHundredMicrometres;
  double fps = 30.0;  ///< frames per second: sets the timestamps (microseconds) and the players' speed
  /// Fields of view (radians) that OpenNI2 reports for the streams; intrinsics go beside the file (FILE.oni.json).
  double horizontal_fov_rad = 1.0;
  double vertical_fov_rad = 0.8;

  /// Throws InputError for sizes outside 1..the file driver's frame buffer (1600 x 1200), a non-positive fps or
  /// fields of view outside (0, pi).
  void Check() const;
};

/// An ONI recording being written: frames are appended uncompressed (depth 16-bit, colour RGB888) under a temporary
/// name, and Finish writes the seek tables and the end, fills in the counts and renames the file into place. A writer
/// destroyed before Finish leaves nothing at `path`.
class OniWriter {
 public:
  /// Throws InputError naming `path` when it cannot be written.
  OniWriter(const std::string& path, const OniWriterOptions& options);
  ~OniWriter();
  OniWriter(const OniWriter&) = delete;
  OniWriter& operator=(const OniWriter&) = delete;

  /// Appends one frame: `color` CV_8UC3 RGB and `depth_values` CV_16UC1 in the options' unit, both of the options'
  /// size (InputError otherwise).
  void Write(const cv::Mat& color, const cv::Mat& depth_values);

  /// Completes the file and renames it to `path`. InputError when no frame was written.
  void Finish();

  int frames() const { return static_cast<int>(depth_positions_.size()); }

 private:
  struct Node;
  void WriteHeader();
  void WriteNode(const Node& node);
  void WriteNodeData(const Node& node, const cv::Mat& pixels, uint64_t timestamp_us, int frame_number);
  void WriteSeekTable(const Node& node, uint64_t* position);
  void PatchCounts(uint64_t depth_seek_table, uint64_t color_seek_table);
  uint64_t Timestamp(int frame_number) const;

  std::string path_;
  OniWriterOptions options_;
  std::unique_ptr<AtomicFile> file_;
  std::unique_ptr<Node> depth_node_, color_node_;
  std::vector<uint64_t> depth_positions_, color_positions_;  // file positions of each frame's data records
  uint64_t depth_node_added_ = 0, color_node_added_ = 0;     // file positions of the node-added records
};

}  // namespace ecv
