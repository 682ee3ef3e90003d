// A PLY file's structure checked before an importer trusts its counts and indices.

#include "io/ply_check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "io/files.h"

namespace ecv {
namespace {

enum class PlyFormat { kAscii, kBinaryLittle, kBinaryBig };

struct PlyProperty {
  std::string name;
  int size = 0;           // bytes of a value (binary)
  bool is_float = false;  // float or double (else an integer type)
  bool is_list = false;
  int count_size = 0;  // bytes of a list's count (binary)
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

// Bytes of a PLY scalar type, 0 for an unknown name.
int TypeSize(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32") {
    return 4;
  }
  if (type == "double" || type == "float64") return 8;
  return 0;
}

// A value as the file gives it: whole numbers without decimals.
std::string Show(double value) {
  if (std::isfinite(value) && value == std::floor(value) && std::abs(value) < 1e15) {
    return std::to_string(static_cast<long long>(value));
  }
  return std::to_string(value);
}

bool IsFloatType(const std::string& type) {
  return type == "float" || type == "double" || type == "float32" || type == "float64";
}

// Reads the values of a PLY body, ASCII or binary, one at a time, and says where it is.
class PlyBody {
 public:
  PlyBody(const std::string& path, std::string bytes, size_t offset, PlyFormat format)
      : path_(path), bytes_(std::move(bytes)), offset_(offset), format_(format) {
    if (format_ == PlyFormat::kAscii) ascii_.str(bytes_.substr(offset_));
  }

  // The next value, of `size` bytes (binary), as a double; throws naming `what` when the file ends first.
  double Next(int size, bool is_float, const std::string& what) {
    if (format_ == PlyFormat::kAscii) {
      std::string token;
      if (!(ascii_ >> token)) ThrowInputError(path_, what, "a number (the header counts more values)", "end of data");
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);  // also "nan" and "inf", which the importer reads
      if (end == token.c_str() || *end != '\0') ThrowInputError(path_, what, "a number", "'" + token + "'");
      return value;
    }
    if (bytes_.size() - offset_ < static_cast<size_t>(size)) {
      ThrowInputError(path_, what, "as many bytes as the header counts",
                      "the file ends " + std::to_string(bytes_.size()) + " bytes in");
    }
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + offset_, static_cast<size_t>(size));
    offset_ += static_cast<size_t>(size);
    if (format_ == PlyFormat::kBinaryBig) std::reverse(raw, raw + size);
    return Decode(raw, size, is_float);
  }

 private:
  // A little-endian value of `size` bytes; integers as unsigned (a negative index is out of range either way).
  static double Decode(const unsigned char* raw, int size, bool is_float) {
    if (is_float && size == 4) {
      float value;
      std::memcpy(&value, raw, 4);
      return value;
    }
    if (is_float) {
      double value;
      std::memcpy(&value, raw, 8);
      return value;
    }
    uint64_t value = 0;
    for (int i = size - 1; i >= 0; --i) value = (value << 8) | raw[i];
    return static_cast<double>(value);
  }

  const std::string& path_;
  const std::string bytes_;
  size_t offset_;
  const PlyFormat format_;
  std::istringstream ascii_;
};

// The header's format and elements; `body` is set to the offset of the first byte after "end_header\n".
PlyFormat ReadHeader(const std::string& path, const std::string& bytes, std::vector<PlyElement>* elements,
                     size_t* body) {
  // "end_header" as a line of its own, ending in \n (or \r\n).
  size_t end = std::string::npos;
  for (size_t at = bytes.find("\nend_header"); at != std::string::npos; at = bytes.find("\nend_header", at + 1)) {
    const size_t after = at + 11;
    if (after < bytes.size() &&
        (bytes[after] == '\n' || (bytes[after] == '\r' && after + 1 < bytes.size() && bytes[after + 1] == '\n'))) {
      end = at + 1;
      break;
    }
  }
  if (bytes.compare(0, 4, "ply\n") != 0 && bytes.compare(0, 5, "ply\r\n") != 0) {
    ThrowInputError(path, "PLY header", "a first line 'ply'");
  }
  if (end == std::string::npos) ThrowInputError(path, "PLY header", "a line 'end_header'");
  *body = bytes.find('\n', end) + 1;
  std::istringstream header(bytes.substr(0, end));
  std::string line, format_name;
  while (std::getline(header, line)) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "format") {
      words >> format_name;
    } else if (keyword == "element") {
      PlyElement element;
      long double count = -1;
      if (!(words >> element.name >> count) || count < 0 || count > 1e12L) {
        ThrowInputError(path, "PLY header", "element NAME COUNT", "'" + line + "'");
      }
      element.count = static_cast<uint64_t>(count);
      elements->push_back(element);
    } else if (keyword == "property") {
      if (elements->empty()) ThrowInputError(path, "PLY header", "a property after its element", "'" + line + "'");
      PlyProperty property;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type;
        words >> count_type >> type;
        property.is_list = true;
        property.count_size = TypeSize(count_type);
        if (property.count_size == 0 || IsFloatType(count_type)) {
          ThrowInputError(path, "PLY header", "an integer list count type", "'" + line + "'");
        }
      }
      property.size = TypeSize(type);
      property.is_float = IsFloatType(type);
      words >> property.name;
      if (property.size == 0 || property.name.empty()) {
        ThrowInputError(path, "PLY header", "property TYPE NAME with a PLY type", "'" + line + "'");
      }
      elements->back().properties.push_back(property);
    }
  }
  if (format_name == "ascii") return PlyFormat::kAscii;
  if (format_name == "binary_little_endian") return PlyFormat::kBinaryLittle;
  if (format_name == "binary_big_endian") return PlyFormat::kBinaryBig;
  ThrowInputError(path, "PLY format", "ascii, binary_little_endian or binary_big_endian", "'" + format_name + "'");
}

}  // namespace

void CheckPlyFile(const std::string& path) {
  constexpr size_t kMaxBytes = size_t{1} << 30;  // 1 GB: tens of millions of triangles, more than any model renders
  std::string bytes = ReadFileBytes(path, "PLY", kMaxBytes);
  std::vector<PlyElement> elements;
  size_t body = 0;
  const PlyFormat format = ReadHeader(path, bytes, &elements, &body);
  uint64_t vertices = 0, faces = 0;
  for (const PlyElement& element : elements) {
    if (element.name == "vertex") vertices = element.count;
    if (element.name == "face") faces = element.count;
  }
  if (vertices == 0 || faces == 0) {
    ThrowInputError(path, "PLY header", "a mesh: elements vertex and face, each with a count above 0",
                    std::to_string(vertices) + " vertices, " + std::to_string(faces) + " faces");
  }
  // Every value after the header, element by element; the face indices against the vertex count.
  PlyBody values(path, std::move(bytes), body, format);
  for (const PlyElement& element : elements) {
    for (uint64_t i = 0; i < element.count; ++i) {
      const std::string where = element.name + " " + std::to_string(i);
      for (const PlyProperty& property : element.properties) {
        if (!property.is_list) {
          const double value = values.Next(property.size, property.is_float, where);
          const bool coordinate = property.name == "x" || property.name == "y" || property.name == "z";
          if (element.name == "vertex" && coordinate && !std::isfinite(value)) {
            ThrowInputError(path, where + " " + property.name, "a finite coordinate", Show(value));
          }
          continue;
        }
        const double count = values.Next(property.count_size, false, where + " " + property.name + " count");
        if (!(count >= 0.0 && count <= 1000.0)) {
          ThrowInputError(path, where + " " + property.name, "a list of at most 1000 values", Show(count));
        }
        const bool indices =
            element.name == "face" && (property.name == "vertex_indices" || property.name == "vertex_index");
        for (int k = 0; k < static_cast<int>(count); ++k) {
          const double value = values.Next(property.size, property.is_float, where + " " + property.name);
          if (indices && !(value >= 0.0 && value < static_cast<double>(vertices))) {
            ThrowInputError(path, where + " " + property.name,
                            "vertex indices below the vertex count " + std::to_string(vertices), Show(value));
          }
        }
      }
    }
  }
}

}  // namespace ecv
