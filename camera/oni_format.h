#pragma once

// The ONI recording format that OpenNI2's file driver (OniFile) plays: a file header, then records, each a fixed
// record header and its fields, some followed by a payload (a frame, a seek table). Little-endian and packed.
// Layout of the files ecvpose writes:
//   file header | per stream: node added, properties, state ready | per stream: data begin
//   | per frame: depth data, colour data | per stream: seek table | end

#include <cstddef>
#include <cstdint>

namespace ecv::oni {

/// File header: magic "NI10", version (u8 major, u8 minor, u16 maintenance, u32 build), the largest timestamp
/// (u64, microseconds) and the largest node id (u32).
inline constexpr char kFileMagic[4] = {'N', 'I', '1', '0'};
inline constexpr size_t kFileHeaderSize = 24;
/// The newest version the driver reads; files from 1.0.1.0 on have 64-bit file positions.
inline constexpr uint8_t kVersionMajor = 1, kVersionMinor = 0;
inline constexpr uint16_t kVersionMaintenance = 1;
inline constexpr uint32_t kVersionBuild = 0;

/// Record header: magic "NIR\0", record type, node id, size of header and fields, size of the payload (u32 each),
/// position of the record it undoes (u64; u32 in files older than 1.0.1.0).
inline constexpr uint32_t kRecordMagic = 0x0052494E;
inline constexpr size_t kRecordHeaderSize = 28;
inline constexpr size_t kOldRecordHeaderSize = 24;

enum RecordType : uint32_t {
  kNodeAdded_1_0_0_4 = 0x02,
  kIntProperty = 0x03,
  kRealProperty = 0x04,
  kStringProperty = 0x05,
  kGeneralProperty = 0x06,
  kNodeRemoved = 0x07,
  kNodeDataBegin = 0x08,
  kNodeStateReady = 0x09,
  kNewData = 0x0A,
  kEnd = 0x0B,
  kNodeAdded_1_0_0_5 = 0x0C,
  kNodeAdded = 0x0D,
  kSeekTable = 0x0E,
};

/// Node types (OpenNI 1's production nodes).
inline constexpr int32_t kNodeTypeDepth = 2;
inline constexpr int32_t kNodeTypeImage = 3;

/// Codec "NONE": frames stored as they are.
inline constexpr uint32_t kCodecUncompressed = 'N' | ('O' << 8) | ('N' << 16) | (static_cast<uint32_t>('E') << 24);

/// Seek table entry: timestamp (u64), configuration id (u32), file position of the frame's data record (u64).
inline constexpr size_t kSeekEntrySize = 20;

/// The driver's frame buffer: frames of up to 1600 x 1200 pixels of 3 bytes.
inline constexpr size_t kMaxFrameBytes = 1600 * 1200 * 3;
/// The longest node or property name the driver keeps, with its terminating NUL.
inline constexpr size_t kMaxNameLength = 80;

/// OpenNI2 pixel formats (OniPixelFormat), written as the "oniPixelFormat" property.
inline constexpr uint64_t kPixelFormatDepth1mm = 100;
inline constexpr uint64_t kPixelFormatDepth100um = 101;
inline constexpr uint64_t kPixelFormatRgb888 = 200;

}  // namespace ecv::oni
