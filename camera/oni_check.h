#pragma once

#include <string>

namespace ecv {

/// What CheckOniFile found in a recording.
struct OniFileSummary {
  int streams = 0;  ///< nodes with frames (depth, colour, IR)
  int frames = 0;   ///< data records over all streams
};

/// Walks every record of the ONI recording at `path` within bounds before OpenNI2's file driver (which trusts the
/// file's sizes) reads it: the file header, each record's magic, type, node, sizes, names and the properties the
/// driver reads by fixed size, the seek tables the node records point to, and an end record. Throws InputError naming
/// the file, the byte offset and what was expected for anything else: a file that is no recording, cut short, or
/// holds no frame.
OniFileSummary CheckOniFile(const std::string& path);

}  // namespace ecv
