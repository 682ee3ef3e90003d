#include "camera/oni_writer.h"

#include <cmath>
#include <cstring>
#include <vector>

#include "camera/oni_format.h"
#include "core/error.h"
#include "io/atomic_file.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "The ONI writer stores values in the machine's byte order, which must be little-endian as the format is"
#endif

namespace ecv {

/// One stream of the recording: its node in the file.
struct OniWriter::Node {
  uint32_t id;
  const char* name;
  int32_t type;           // oni::kNodeTypeDepth or kNodeTypeImage
  uint64_t pixel_format;  // OniPixelFormat
  int bytes_per_pixel;
};

namespace {

constexpr uint32_t kDepthNode = 1, kColorNode = 2;

// A record's bytes, built field by field in the file's (little-endian) order.
class RecordBytes {
 public:
  // Starts a record of `type` for `node`; the sizes are filled in by Finish.
  RecordBytes(uint32_t type, uint32_t node, uint64_t undo_position = 0) {
    Add(oni::kRecordMagic);
    Add(type);
    Add(node);
    Add(uint32_t{0});  // size of header and fields
    Add(uint32_t{0});  // payload size
    Add(undo_position);
  }
  template <typename T>
  void Add(T value) {
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(&bytes_[at], &value, sizeof(T));
  }
  // A string as the format stores names: its length with the NUL (u32), then the characters and the NUL.
  void AddString(const std::string& text) {
    Add(static_cast<uint32_t>(text.size() + 1));
    bytes_.append(text.c_str(), text.size() + 1);
  }
  void AddBytes(const void* data, size_t size) { bytes_.append(static_cast<const char*>(data), size); }
  // The record with its sizes: the fields end here; `payload_size` bytes follow it in the file.
  const std::string& Finish(uint32_t payload_size = 0) {
    const auto fields_size = static_cast<uint32_t>(bytes_.size());
    std::memcpy(&bytes_[12], &fields_size, sizeof(fields_size));
    std::memcpy(&bytes_[16], &payload_size, sizeof(payload_size));
    return bytes_;
  }

 private:
  std::string bytes_;
};

// The byte offset of the frame count in a node-added record whose node is called `name`: after the record header,
// the name (u32 length, characters, NUL), the node type (i32) and the codec (u32).
size_t FrameCountOffset(const std::string& name) {
  return oni::kRecordHeaderSize + 4 + name.size() + 1 + 4 + 4;
}

void CheckImage(const cv::Mat& image, int type, const OniWriterOptions& options, const char* what) {
  if (image.type() != type || image.cols != options.width || image.rows != options.height) {
    ThrowInputError(
        "recording", what,
        std::to_string(options.width) + "x" + std::to_string(options.height) + " pixels of type " +
            (type == CV_8UC3 ? "CV_8UC3" : "CV_16UC1"),
        std::to_string(image.cols) + "x" + std::to_string(image.rows) + " of type " + std::to_string(image.type()));
  }
}

}  // namespace

double DepthValuesPerMetre(OniDepthUnit unit) {
  return unit == OniDepthUnit::kMillimetre ? 1000.0 : 10000.0;
}

cv::Mat DepthValues(const cv::Mat& depth_m, OniDepthUnit unit, const std::string& source) {
  const double per_metre = DepthValuesPerMetre(unit);
  double largest = 0.0;
  cv::minMaxLoc(depth_m, nullptr, &largest);
  if (largest * per_metre > 65535.0) {
    ThrowInputError(source, "depth", "depths up to " + std::to_string(65535.0 / per_metre) + " m for 16-bit values",
                    std::to_string(largest) + " m");
  }
  cv::Mat values;
  depth_m.convertTo(values, CV_16U, per_metre);  // rounds to the nearest value
  return values;
}

OniDepthUnit ExactDepthUnit(const cv::Mat& depth_m, bool* exact) {
  for (const OniDepthUnit unit : {OniDepthUnit::kHundredMicrometres, OniDepthUnit::kMillimetre}) {
    double largest = 0.0;
    cv::minMaxLoc(depth_m, nullptr, &largest);
    if (largest * DepthValuesPerMetre(unit) > 65535.0) continue;
    cv::Mat values, back;
    depth_m.convertTo(values, CV_16U, DepthValuesPerMetre(unit));
    values.convertTo(back, CV_32F, 1.0 / DepthValuesPerMetre(unit));  // as DepthImageAsMetres converts
    if (cv::countNonZero(back != depth_m) == 0) {
      *exact = true;
      return unit;
    }
  }
  *exact = false;
  return OniDepthUnit::kHundredMicrometres;
}

void OniWriterOptions::Check() const {
  const double bytes = 3.0 * width * height;
  if (width < 1 || height < 1 || bytes > static_cast<double>(oni::kMaxFrameBytes)) {
    ThrowInputError("recording", "image size", "1x1 to 1600x1200 pixels (OpenNI2's file driver buffer)",
                    std::to_string(width) + "x" + std::to_string(height));
  }
  if (!(std::isfinite(fps) && fps > 0.0)) ThrowInputError("recording", "fps", "a positive number", std::to_string(fps));
  for (const double fov : {horizontal_fov_rad, vertical_fov_rad}) {
    if (!(fov > 0.0 && fov < M_PI)) {
      ThrowInputError("recording", "field of view", "0 to pi radians", std::to_string(fov));
    }
  }
}

OniWriter::OniWriter(const std::string& path, const OniWriterOptions& options) : path_(path), options_(options) {
  options_.Check();
  file_ = std::make_unique<AtomicFile>(path);
  WriteHeader();
  const uint64_t depth_format =
      options_.depth_unit == OniDepthUnit::kMillimetre ? oni::kPixelFormatDepth1mm : oni::kPixelFormatDepth100um;
  depth_node_ = std::make_unique<Node>(Node{kDepthNode, "Depth", oni::kNodeTypeDepth, depth_format, 2});
  color_node_ = std::make_unique<Node>(Node{kColorNode, "Image", oni::kNodeTypeImage, oni::kPixelFormatRgb888, 3});
  depth_node_added_ = static_cast<uint64_t>(file_->stream().tellp());
  WriteNode(*depth_node_);
  color_node_added_ = static_cast<uint64_t>(file_->stream().tellp());
  WriteNode(*color_node_);
  for (const uint32_t node : {kDepthNode, kColorNode}) {
    RecordBytes begin(oni::kNodeDataBegin, node);
    begin.Add(uint32_t{0});  // frames and largest timestamp: the node-added record holds them
    begin.Add(uint64_t{0});
    file_->stream() << begin.Finish();
  }
}

OniWriter::~OniWriter() = default;

void OniWriter::WriteHeader() {
  std::ostream& out = file_->stream();
  out.write(oni::kFileMagic, sizeof(oni::kFileMagic));
  out.put(static_cast<char>(oni::kVersionMajor)).put(static_cast<char>(oni::kVersionMinor));
  out.write(reinterpret_cast<const char*>(&oni::kVersionMaintenance), sizeof(oni::kVersionMaintenance));
  out.write(reinterpret_cast<const char*>(&oni::kVersionBuild), sizeof(oni::kVersionBuild));
  const uint64_t largest_timestamp = 0;  // filled in by Finish
  const uint32_t largest_node = kColorNode;
  out.write(reinterpret_cast<const char*>(&largest_timestamp), sizeof(largest_timestamp));
  out.write(reinterpret_cast<const char*>(&largest_node), sizeof(largest_node));
}

// The node-added record (counts and seek table position filled in by Finish), the properties OpenNI2's player turns
// into the stream's video mode and fields of view, and the state-ready record that ends them.
void OniWriter::WriteNode(const Node& node) {
  std::ostream& out = file_->stream();
  RecordBytes added(oni::kNodeAdded, node.id);
  added.AddString(node.name);
  added.Add(node.type);
  added.Add(oni::kCodecUncompressed);
  added.Add(uint32_t{0});  // frames
  added.Add(uint64_t{0});  // smallest timestamp
  added.Add(uint64_t{0});  // largest timestamp
  added.Add(uint64_t{0});  // seek table position
  out << added.Finish();

  const auto general = [&](const char* name, const void* data, uint32_t size) {
    RecordBytes property(oni::kGeneralProperty, node.id);
    property.AddString(name);
    property.Add(size);
    property.AddBytes(data, size);
    out << property.Finish();
  };
  const auto integer = [&](const char* name, uint64_t value) {
    RecordBytes property(oni::kIntProperty, node.id);
    property.AddString(name);
    property.Add(uint32_t{sizeof(value)});
    property.Add(value);
    out << property.Finish();
  };
  // The output mode first: the pixel format property amends the video mode it makes.
  const uint32_t mode[3] = {static_cast<uint32_t>(options_.width), static_cast<uint32_t>(options_.height),
                            static_cast<uint32_t>(std::lround(options_.fps))};
  general("xnMapOutputMode", mode, sizeof(mode));
  integer("oniPixelFormat", node.pixel_format);
  integer("oniRequiredFrameSize", static_cast<uint64_t>(options_.width) * options_.height * node.bytes_per_pixel);
  if (node.type == oni::kNodeTypeDepth) integer("xnDeviceMaxDepth", 65535);
  const double fov[2] = {options_.horizontal_fov_rad, options_.vertical_fov_rad};
  general("xnFOV", fov, sizeof(fov));
  // No cropping (enabled flag u32, x, y, width, height u16): the player delivers no frame of a stream without it.
  const uint8_t no_cropping[12] = {};
  general("xnCropping", no_cropping, sizeof(no_cropping));
  integer("xnIsGenerating", 1);  // for OpenNI 1's player
  out << RecordBytes(oni::kNodeStateReady, node.id).Finish();
}

uint64_t OniWriter::Timestamp(int frame_number) const {
  return static_cast<uint64_t>(std::llround(frame_number * 1e6 / options_.fps));
}

void OniWriter::WriteNodeData(const Node& node, const cv::Mat& pixels, uint64_t timestamp_us, int frame_number) {
  std::vector<uint64_t>& positions = node.id == kDepthNode ? depth_positions_ : color_positions_;
  const uint64_t undo = positions.empty() ? 0 : positions.back();  // the node's previous frame
  positions.push_back(static_cast<uint64_t>(file_->stream().tellp()));
  const cv::Mat packed = pixels.isContinuous() ? pixels : pixels.clone();
  const size_t bytes = packed.total() * packed.elemSize();
  RecordBytes data(oni::kNewData, node.id, undo);
  data.Add(timestamp_us);
  data.Add(static_cast<uint32_t>(frame_number));
  file_->stream() << data.Finish(static_cast<uint32_t>(bytes));
  file_->stream().write(reinterpret_cast<const char*>(packed.data), static_cast<std::streamsize>(bytes));
}

void OniWriter::Write(const cv::Mat& color, const cv::Mat& depth_values) {
  CheckImage(color, CV_8UC3, options_, "colour image");
  CheckImage(depth_values, CV_16UC1, options_, "depth image");
  const int frame_number = frames() + 1;  // the player counts frames from 1
  const uint64_t timestamp = Timestamp(frame_number);
  WriteNodeData(*depth_node_, depth_values, timestamp, frame_number);
  WriteNodeData(*color_node_, color, timestamp, frame_number);
  if (!file_->stream()) ThrowInputError(path_, "output", "room to write frame " + std::to_string(frame_number));
}

// A seek table: an empty entry 0, then each frame's timestamp, configuration 0 and data record position.
void OniWriter::WriteSeekTable(const Node& node, uint64_t* position) {
  const std::vector<uint64_t>& positions = node.id == kDepthNode ? depth_positions_ : color_positions_;
  *position = static_cast<uint64_t>(file_->stream().tellp());
  RecordBytes table(oni::kSeekTable, node.id);
  file_->stream() << table.Finish(static_cast<uint32_t>((positions.size() + 1) * oni::kSeekEntrySize));
  std::string entry(oni::kSeekEntrySize, '\0');
  file_->stream() << entry;  // entry 0: no frame
  for (size_t i = 0; i < positions.size(); ++i) {
    const uint64_t timestamp = Timestamp(static_cast<int>(i) + 1);
    const uint32_t configuration = 0;
    std::memcpy(&entry[0], &timestamp, 8);
    std::memcpy(&entry[8], &configuration, 4);
    std::memcpy(&entry[12], &positions[i], 8);
    file_->stream() << entry;
  }
}

void OniWriter::PatchCounts(uint64_t depth_seek_table, uint64_t color_seek_table) {
  std::ostream& out = file_->stream();
  const uint64_t last = Timestamp(frames());
  out.seekp(12);  // the file header's largest timestamp, after the magic and the version
  out.write(reinterpret_cast<const char*>(&last), sizeof(last));
  const auto patch = [&](uint64_t node_added, const char* name, uint64_t seek_table) {
    const auto count = static_cast<uint32_t>(frames());
    const uint64_t first = Timestamp(1);
    out.seekp(static_cast<std::streamoff>(node_added + FrameCountOffset(name)));
    out.write(reinterpret_cast<const char*>(&count), sizeof(count));
    out.write(reinterpret_cast<const char*>(&first), sizeof(first));
    out.write(reinterpret_cast<const char*>(&last), sizeof(last));
    out.write(reinterpret_cast<const char*>(&seek_table), sizeof(seek_table));
  };
  patch(depth_node_added_, "Depth", depth_seek_table);
  patch(color_node_added_, "Image", color_seek_table);
  out.seekp(0, std::ios::end);
}

void OniWriter::Finish() {
  if (frames() == 0) ThrowInputError(path_, "frames", "at least one frame to record", "none");
  uint64_t depth_table = 0, color_table = 0;
  WriteSeekTable(*depth_node_, &depth_table);
  WriteSeekTable(*color_node_, &color_table);
  file_->stream() << RecordBytes(oni::kEnd, 0).Finish();
  PatchCounts(depth_table, color_table);
  if (!file_->stream()) ThrowInputError(path_, "output", "room to write the recording's end");
  file_->Commit();
}

}  // namespace ecv
