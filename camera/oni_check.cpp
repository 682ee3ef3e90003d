#include "camera/oni_check.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "camera/oni_format.h"
#include "core/error.h"

namespace ecv {
namespace {

// The driver reads a record's fields and payload into one buffer of this size.
constexpr uint64_t kMaxRecordBytes = oni::kMaxFrameBytes + 121;
constexpr uint32_t kMaxFieldBytes = 1 << 20;  // property tables (shift-to-depth) are a few KB
constexpr uint32_t kMaxNodeId = 1000;

struct NodeInfo {
  uint32_t frames = 0;
  uint64_t seek_table = 0;  // position of its seek table record; 0 for none
};

// The record being checked: its position, header values and fields (header included).
struct Record {
  uint64_t position = 0;
  uint32_t type = 0, node = 0, fields_size = 0, payload_size = 0;
  std::string fields;
};

class OniChecker {
 public:
  explicit OniChecker(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    std::error_code error;
    size_ = std::filesystem::file_size(path, error);
    if (!in_ || error) ThrowInputError(path, "recording", "a readable .oni file", "cannot open it");
  }

  OniFileSummary Check() {
    ReadFileHeader();
    uint64_t position = oni::kFileHeaderSize;
    Record record;
    do {
      record = ReadRecord(position);
      CheckRecord(record);
      position += uint64_t{record.fields_size} + record.payload_size;
    } while (record.type != oni::kEnd);
    CheckSeekTables();
    if (summary_.frames == 0) Fail(position, "at least one frame", "a recording without frames");
    return summary_;
  }

 private:
  [[noreturn]] void Fail(uint64_t position, const std::string& expected, const std::string& got = "") const {
    ThrowInputError(path_, "byte " + std::to_string(position), expected, got);
  }

  template <typename T>
  T At(const std::string& bytes, size_t offset) const {
    T value;
    std::memcpy(&value, bytes.data() + offset, sizeof(T));
    return value;
  }

  std::string ReadBytes(uint64_t position, uint64_t count, const std::string& what) {
    if (position + count > size_) {
      Fail(position, what, "the file ends after " + std::to_string(size_) + " bytes (cut short?)");
    }
    std::string bytes(count, '\0');
    in_.seekg(static_cast<std::streamoff>(position));
    if (!in_.read(bytes.data(), static_cast<std::streamsize>(count))) Fail(position, what, "a read error");
    return bytes;
  }

  void ReadFileHeader() {
    const std::string header = ReadBytes(0, oni::kFileHeaderSize, "an ONI file header (24 bytes)");
    if (std::memcmp(header.data(), oni::kFileMagic, 4) != 0) {
      Fail(0, "an ONI recording (magic \"NI10\")", "other bytes: not an .oni file");
    }
    const auto version = std::make_tuple(At<uint8_t>(header, 4), At<uint8_t>(header, 5), At<uint16_t>(header, 6),
                                         At<uint32_t>(header, 8));
    if (version < std::make_tuple(uint8_t{1}, uint8_t{0}, uint16_t{0}, uint32_t{4}) ||
        version >
            std::make_tuple(oni::kVersionMajor, oni::kVersionMinor, oni::kVersionMaintenance, oni::kVersionBuild)) {
      Fail(4, "file format version 1.0.0.4 to 1.0.1.0");
    }
    header_size_ = std::get<2>(version) >= 1 ? oni::kRecordHeaderSize : oni::kOldRecordHeaderSize;
    max_node_ = At<uint32_t>(header, 20);
    if (max_node_ > kMaxNodeId) Fail(20, "a largest node id up to " + std::to_string(kMaxNodeId));
  }

  Record ReadRecord(uint64_t position) {
    Record record;
    record.position = position;
    const std::string header = ReadBytes(position, header_size_, "a record header or the end record");
    if (At<uint32_t>(header, 0) != oni::kRecordMagic) Fail(position, "a record (magic \"NIR\")", "other bytes");
    record.type = At<uint32_t>(header, 4);
    record.node = At<uint32_t>(header, 8);
    record.fields_size = At<uint32_t>(header, 12);
    record.payload_size = At<uint32_t>(header, 16);
    if (record.type < oni::kNodeAdded_1_0_0_4 || record.type > oni::kSeekTable) {
      Fail(position, "a record type 2 to 14", std::to_string(record.type));
    }
    if (record.node > max_node_) Fail(position, "a node id up to " + std::to_string(max_node_));
    if (record.fields_size < header_size_ || record.fields_size > kMaxFieldBytes ||
        uint64_t{record.fields_size} + record.payload_size > kMaxRecordBytes) {
      Fail(position, "record sizes within the player's buffer",
           std::to_string(record.fields_size) + " + " + std::to_string(record.payload_size) + " bytes");
    }
    record.fields = ReadBytes(position, record.fields_size, "the record's fields");
    if (position + record.fields_size + record.payload_size > size_) {
      Fail(position, "the record's payload", "the file ends after " + std::to_string(size_) + " bytes (cut short?)");
    }
    return record;
  }

  // A name as the format stores it (u32 length with the NUL, then the characters); returns the offset after it.
  size_t CheckName(const Record& record, size_t offset, std::string* name) const {
    if (offset + 4 > record.fields.size()) Fail(record.position, "a name in the record's fields");
    const auto length = At<uint32_t>(record.fields, offset);
    if (length < 1 || length > oni::kMaxNameLength || offset + 4 + length > record.fields.size() ||
        record.fields[offset + 4 + length - 1] != '\0') {
      Fail(record.position, "a name of 1 to 79 characters ending in NUL within the record");
    }
    *name = record.fields.substr(offset + 4, length - 1);
    return offset + 4 + length;
  }

  void RequireNode(const Record& record) const {
    if (nodes_.count(record.node) == 0) Fail(record.position, "a record of a node added before it");
  }

  void CheckRecord(const Record& record) {
    switch (record.type) {
      case oni::kNodeAdded_1_0_0_4:
      case oni::kNodeAdded_1_0_0_5:
      case oni::kNodeAdded: return CheckNodeAdded(record);
      case oni::kIntProperty:
      case oni::kRealProperty:
      case oni::kStringProperty:
      case oni::kGeneralProperty: return CheckProperty(record);
      case oni::kNewData: return CheckNewData(record);
      case oni::kSeekTable: seek_tables_[record.position] = record; return;
      case oni::kEnd: return;
      default:  // node removed, data begin, state ready
        return RequireNode(record);
    }
  }

  void CheckNodeAdded(const Record& record) {
    std::string name;
    size_t offset = CheckName(record, header_size_, &name);
    const size_t needed = offset + 8 + (record.type == oni::kNodeAdded_1_0_0_4 ? 0 : 20) +
                          (record.type == oni::kNodeAdded ? (header_size_ == oni::kRecordHeaderSize ? 8 : 4) : 0);
    if (record.fields.size() < needed) Fail(record.position, "the node's type, codec and counts");
    const auto type = At<int32_t>(record.fields, offset);
    const auto codec = At<uint32_t>(record.fields, offset + 4);
    const bool generator = type == oni::kNodeTypeDepth || type == oni::kNodeTypeImage || type == 5;  // 5: IR
    static const std::set<uint32_t> kCodecs = {oni::kCodecUncompressed, 0x4745504A /* JPEG */, 0x507A3631 /* 16zP */,
                                               0x547A3631 /* 16zT */, 0x7A386D49 /* Im8z */};
    if (generator && kCodecs.count(codec) == 0) Fail(record.position, "a known codec for node '" + name + "'");
    NodeInfo& node = nodes_[record.node];
    if (record.type != oni::kNodeAdded_1_0_0_4) node.frames = At<uint32_t>(record.fields, offset + 8);
    if (record.type == oni::kNodeAdded) {
      node.seek_table = header_size_ == oni::kRecordHeaderSize ? At<uint64_t>(record.fields, offset + 28)
                                                               : At<uint32_t>(record.fields, offset + 28);
      if (node.frames == 0) node.seek_table = 0;  // the player reads no table then
    }
    if (generator) ++summary_.streams;
  }

  // Property records: name, data size (u32), data; the properties the player reads by a fixed size have that size.
  void CheckProperty(const Record& record) {
    RequireNode(record);
    std::string name;
    const size_t offset = CheckName(record, header_size_, &name);
    if (offset + 4 > record.fields.size()) Fail(record.position, "the size of property '" + name + "'");
    const auto size = At<uint32_t>(record.fields, offset);
    if (offset + 4 + size > record.fields.size()) Fail(record.position, "property '" + name + "' within its record");
    const std::map<std::string, uint32_t> kFixedSizes = {{"xnMapOutputMode", 12}, {"xnFOV", 16}, {"xnCropping", 12}};
    uint32_t expected = record.type == oni::kIntProperty || record.type == oni::kRealProperty ? 8 : 0;
    if (kFixedSizes.count(name) > 0) expected = kFixedSizes.at(name);
    if (expected > 0 && size != expected) {
      Fail(record.position, "property '" + name + "' of " + std::to_string(expected) + " bytes", std::to_string(size));
    }
    if (record.type == oni::kStringProperty && (size == 0 || record.fields[offset + 4 + size - 1] != '\0')) {
      Fail(record.position, "string property '" + name + "' ending in NUL");
    }
    if (name == "xnMapOutputMode") {
      const uint64_t width = At<uint32_t>(record.fields, offset + 4), height = At<uint32_t>(record.fields, offset + 8);
      if (width < 1 || height < 1 || width * height * 3 > oni::kMaxFrameBytes) {
        Fail(record.position, "an image size of 1x1 to 1600x1200 pixels",
             std::to_string(width) + "x" + std::to_string(height));
      }
    }
  }

  void CheckNewData(const Record& record) {
    RequireNode(record);
    if (record.fields.size() < header_size_ + 12u) Fail(record.position, "a frame's timestamp and number");
    const auto frame = At<uint32_t>(record.fields, header_size_ + 8);
    const NodeInfo& node = nodes_.at(record.node);
    if (frame > node.frames) {
      Fail(record.position, "a frame number up to the node's " + std::to_string(node.frames), std::to_string(frame));
    }
    if (record.payload_size > oni::kMaxFrameBytes) Fail(record.position, "a frame of at most 1600x1200x3 bytes");
    ++summary_.frames;
  }

  // Each node's seek table position names a seek table record of that node with an entry per frame and one more.
  void CheckSeekTables() const {
    const uint32_t entry = header_size_ == oni::kRecordHeaderSize ? oni::kSeekEntrySize : 16;
    for (const auto& [id, node] : nodes_) {
      if (node.seek_table == 0) continue;
      const auto table = seek_tables_.find(node.seek_table);
      if (table == seek_tables_.end() || table->second.node != id ||
          table->second.payload_size != (uint64_t{node.frames} + 1) * entry) {
        Fail(node.seek_table,
             "the seek table of node " + std::to_string(id) + " with " + std::to_string(node.frames + 1) + " entries");
      }
    }
  }

  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
  size_t header_size_ = oni::kRecordHeaderSize;
  uint32_t max_node_ = 0;
  std::map<uint32_t, NodeInfo> nodes_;
  std::map<uint64_t, Record> seek_tables_;
  OniFileSummary summary_;
};

}  // namespace

OniFileSummary CheckOniFile(const std::string& path) {
  return OniChecker(path).Check();
}

}  // namespace ecv
