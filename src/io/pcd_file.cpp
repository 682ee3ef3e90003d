// PCD files read without trusting what their header claims: the header checked line by line, the body's size against
// it, LZF data decompressed within bounds.

#include "io/pcd_file.h"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <system_error>

#include "core/error.h"
#include "io/files.h"

namespace ecv {
namespace {

constexpr size_t kMaxHeaderBytes = 1 << 16;   // a header longer than this is not a point cloud's
constexpr uint64_t kMaxPointBytes = 1 << 20;  // bytes of one point, over all its fields
constexpr uint64_t kMaxFields = 4096;

// The header's keywords in the order a PCD file gives them; the optional ones may be left out.
constexpr std::array<const char*, 10> kKeywords = {"VERSION", "FIELDS", "SIZE",      "TYPE",   "COUNT",
                                                   "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
constexpr std::array<bool, 10> kOptional = {true, false, false, false, true, false, false, true, false, false};

// `token` as a whole number in [1, max], else an InputError naming `field`.
uint64_t ParseCount(const std::string& path, const std::string& field, const std::string& token, uint64_t max) {
  uint64_t value = 0;
  bool digits = !token.empty() && token.size() <= 19;
  for (const char c : token) digits = digits && c >= '0' && c <= '9';
  if (digits) value = std::stoull(token);
  if (!digits || value > max || value == 0) {
    ThrowInputError(path, field, "a whole number from 1 to " + std::to_string(max), "'" + token + "'");
  }
  return value;
}

// The words of a header line after its keyword, exactly `expected` of them.
std::vector<std::string> Values(const std::string& path, const std::string& keyword, std::istringstream& words,
                                size_t expected) {
  std::vector<std::string> values;
  for (std::string word; words >> word;) values.push_back(word);
  if (values.size() != expected) {
    ThrowInputError(path, keyword, std::to_string(expected) + " value" + (expected == 1 ? "" : "s"),
                    std::to_string(values.size()));
  }
  return values;
}

// The header's lines, from the first up to DATA, as keyword -> rest of the line; `body_offset` is set to the byte
// after the DATA line.
std::array<std::string, kKeywords.size()> ReadHeaderLines(const std::string& path, uint64_t* body_offset) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) ThrowInputError(path, "PCD", "a readable file");
  std::array<std::string, kKeywords.size()> lines;
  size_t next = 0;  // keywords before this one are behind us
  size_t read = 0;
  for (std::string line; std::getline(stream, line);) {
    read += line.size() + 1;
    if (read > kMaxHeaderBytes) ThrowInputError(path, "PCD header", "a DATA line in the first 64 KB");
    for (const char c : line) {
      if ((c < 32 || c > 126) && c != '\t' && c != '\r') {
        ThrowInputError(path, "PCD header", "printable ASCII lines", "byte " + std::to_string(int(c) & 0xff));
      }
    }
    std::istringstream words(line);
    std::string keyword;
    if (!(words >> keyword) || keyword[0] == '#') continue;
    size_t index = next;
    while (index < kKeywords.size() && keyword != kKeywords[index]) ++index;
    if (index == kKeywords.size()) {
      std::string known;
      for (size_t k = next; k < kKeywords.size(); ++k) known += std::string(k == next ? "" : ", ") + kKeywords[k];
      ThrowInputError(path, "PCD header", "one of " + known + " (in this order, each once)", "'" + keyword + "'");
    }
    for (size_t skipped = next; skipped < index; ++skipped) {
      if (!kOptional[skipped]) {
        ThrowInputError(path, kKeywords[skipped], std::string("a ") + kKeywords[skipped] + " line before " + keyword);
      }
    }
    std::string rest;
    std::getline(words, rest);
    lines[index] = rest;
    next = index + 1;
    if (index == kKeywords.size() - 1) {
      *body_offset = read;
      return lines;
    }
  }
  ThrowInputError(path, "DATA", "a DATA line ending the header", "none");
}

uint32_t LittleEndian32(const unsigned char* bytes) {
  return static_cast<uint32_t>(bytes[0]) | static_cast<uint32_t>(bytes[1]) << 8 |
         static_cast<uint32_t>(bytes[2]) << 16 | static_cast<uint32_t>(bytes[3]) << 24;
}

// Decompresses LZF data (a control byte below 32 starts a run of that many + 1 literal bytes; above, its top 3 bits
// (7: plus the next byte) + 2 bytes are copied from 1 + its low 5 bits and the next byte back) into exactly
// out->size() bytes; false if the data is not that.
bool DecompressLzf(const unsigned char* in, size_t in_size, std::string* out) {
  size_t from = 0, to = 0;
  const size_t out_size = out->size();
  while (from < in_size) {
    const unsigned control = in[from++];
    if (control < 32) {
      const size_t length = control + 1;
      if (length > in_size - from || length > out_size - to) return false;
      std::memcpy(&(*out)[to], in + from, length);
      from += length;
      to += length;
      continue;
    }
    size_t length = control >> 5;
    if (length == 7) {
      if (from >= in_size) return false;
      length += in[from++];
    }
    if (from >= in_size) return false;
    const size_t back = ((control & 0x1fU) << 8) + in[from++] + 1;
    length += 2;
    if (back > to || length > out_size - to) return false;
    for (size_t i = 0; i < length; ++i, ++to) (*out)[to] = (*out)[to - back];  // may overlap what it writes
  }
  return to == out_size;
}

// Writes `value` into `size` little-endian bytes at `out` as a field of `type` holds it; false if it does not fit.
bool StoreAscii(const std::string& token, char type, uint32_t size, char* out) {
  char* end = nullptr;
  errno = 0;
  if (type == 'F') {
    const double value = std::strtod(token.c_str(), &end);  // also nan and inf, which PCL writes for missing points
    if (*end != '\0') return false;
    if (size == 4) {
      const float narrow = static_cast<float>(value);
      std::memcpy(out, &narrow, 4);
    } else {
      std::memcpy(out, &value, 8);
    }
    return true;
  }
  const int bits = static_cast<int>(size) * 8;
  uint64_t raw = 0;
  if (type == 'U') {
    if (token[0] == '-') return false;
    raw = std::strtoull(token.c_str(), &end, 10);
    if (*end != '\0' || errno == ERANGE || (bits < 64 && raw >> bits != 0)) return false;
  } else {
    const long long value = std::strtoll(token.c_str(), &end, 10);
    const long long limit = bits < 64 ? 1LL << (bits - 1) : 0;
    if (*end != '\0' || errno == ERANGE || (bits < 64 && (value < -limit || value >= limit))) return false;
    raw = static_cast<uint64_t>(value);
  }
  for (uint32_t i = 0; i < size; ++i) out[i] = static_cast<char>((raw >> (8 * i)) & 0xff);
  return true;
}

}  // namespace

const PcdField* PcdLayout::Find(const std::string& name) const {
  for (const PcdField& field : fields) {
    if (field.name == name) return &field;
  }
  return nullptr;
}

PcdLayout CheckPcdFile(const std::string& path) {
  RequireRegularFile(path, "PCD");
  std::error_code error;
  const uint64_t file_bytes = std::filesystem::file_size(path, error);
  if (error) ThrowInputError(path, "PCD", "a readable file", error.message());
  PcdLayout layout;
  const std::array<std::string, kKeywords.size()> lines = ReadHeaderLines(path, &layout.body_offset);
  auto words = [&](size_t index) { return std::istringstream(lines[index]); };

  std::istringstream field_words = words(1);
  for (std::string name; field_words >> name;) layout.fields.push_back({name});
  if (layout.fields.empty() || layout.fields.size() > kMaxFields) {
    ThrowInputError(path, "FIELDS", "1 to " + std::to_string(kMaxFields) + " names",
                    std::to_string(layout.fields.size()));
  }
  const size_t n = layout.fields.size();
  std::istringstream size_words = words(2), type_words = words(3), count_words = words(4);
  const std::vector<std::string> sizes = Values(path, "SIZE", size_words, n);
  const std::vector<std::string> types = Values(path, "TYPE", type_words, n);
  const std::vector<std::string> counts =
      lines[4].empty() ? std::vector<std::string>(n, "1") : Values(path, "COUNT", count_words, n);
  uint64_t values_per_point = 0;
  for (size_t i = 0; i < n; ++i) {
    PcdField& field = layout.fields[i];
    const std::string& name = field.name;
    const uint64_t size = ParseCount(path, "SIZE of " + name, sizes[i], 8);
    const bool integer = types[i] == "I" || types[i] == "U";
    if (!(integer && (size == 1 || size == 2 || size == 4 || size == 8)) &&
        !(types[i] == "F" && (size == 4 || size == 8))) {
      ThrowInputError(path, "TYPE of " + name, "F with SIZE 4 or 8, I or U with SIZE 1, 2, 4 or 8",
                      types[i] + " with SIZE " + sizes[i]);
    }
    const uint64_t count = ParseCount(path, "COUNT of " + name, counts[i], kMaxPointBytes);
    field.type = types[i][0];
    field.size = static_cast<uint32_t>(size);
    field.count = static_cast<uint32_t>(count);
    field.offset = layout.point_bytes;
    values_per_point += count;
    layout.point_bytes += size * count;
  }
  if (layout.point_bytes > kMaxPointBytes) {
    ThrowInputError(path, "SIZE x COUNT", "at most " + std::to_string(kMaxPointBytes) + " bytes a point",
                    std::to_string(layout.point_bytes));
  }

  std::istringstream width_words = words(5), height_words = words(6), point_words = words(8);
  layout.width = ParseCount(path, "WIDTH", Values(path, "WIDTH", width_words, 1)[0], file_bytes);
  layout.height = ParseCount(path, "HEIGHT", Values(path, "HEIGHT", height_words, 1)[0], file_bytes);
  const uint64_t points = ParseCount(path, "POINTS", Values(path, "POINTS", point_words, 1)[0], file_bytes);
  if (points % layout.height != 0 || points / layout.height != layout.width) {
    ThrowInputError(path, "POINTS",
                    "WIDTH x HEIGHT (" + std::to_string(layout.width) + " x " + std::to_string(layout.height) + ")",
                    std::to_string(points));
  }
  if (!lines[7].empty()) {
    std::istringstream viewpoint_words = words(7);
    for (const std::string& value : Values(path, "VIEWPOINT", viewpoint_words, 7)) {
      char* end = nullptr;
      const double number = std::strtod(value.c_str(), &end);
      if (*end != '\0' || !std::isfinite(number)) {
        ThrowInputError(path, "VIEWPOINT", "7 finite numbers (tx ty tz qw qx qy qz)", "'" + value + "'");
      }
    }
  }
  std::istringstream data_words = words(9);
  const std::string data = Values(path, "DATA", data_words, 1)[0];
  if (data == "ascii") {
    layout.data = PcdData::kAscii;
  } else if (data == "binary") {
    layout.data = PcdData::kBinary;
  } else if (data == "binary_compressed") {
    layout.data = PcdData::kBinaryCompressed;
  } else {
    ThrowInputError(path, "DATA", "ascii, binary or binary_compressed", "'" + data + "'");
  }

  // The body against the header.
  const uint64_t body_bytes = file_bytes > layout.body_offset ? file_bytes - layout.body_offset : 0;
  const uint64_t data_bytes = points * layout.point_bytes;
  auto refuse = [&](const std::string& expected, const std::string& found) {
    ThrowInputError(path, "DATA " + data, expected, found);
  };
  if (layout.data == PcdData::kAscii && points * values_per_point > body_bytes) {
    refuse(std::to_string(points * values_per_point) + " values (POINTS x COUNT)",
           std::to_string(body_bytes) + " bytes");
  }
  if (layout.data == PcdData::kBinary && data_bytes > body_bytes) {
    refuse(std::to_string(data_bytes) + " bytes (POINTS x SIZE x COUNT)", std::to_string(body_bytes) + " bytes");
  }
  if (layout.data == PcdData::kBinaryCompressed) {
    if (body_bytes < 8) refuse("the compressed and uncompressed sizes (8 bytes)", std::to_string(body_bytes));
    std::ifstream stream(path, std::ios::binary);
    stream.seekg(static_cast<std::streamoff>(layout.body_offset));
    unsigned char raw[8];  // the compressed and the uncompressed size, little-endian as PCL writes them
    if (!stream.read(reinterpret_cast<char*>(raw), 8)) refuse("8 bytes of sizes", "a read error");
    const uint32_t compressed = LittleEndian32(raw), uncompressed = LittleEndian32(raw + 4);
    if (uncompressed != data_bytes) {
      refuse("an uncompressed size of " + std::to_string(data_bytes) + " bytes (POINTS x SIZE x COUNT)",
             std::to_string(uncompressed));
    }
    if (compressed == 0 || compressed > body_bytes - 8) {
      refuse("a compressed size from 1 to the " + std::to_string(body_bytes - 8) + " bytes that follow",
             std::to_string(compressed));
    }
    layout.compressed_bytes = compressed;
  }
  return layout;
}

double PcdCloud::Value(uint64_t point, const PcdField& field, uint32_t element) const {
  const char* at = bytes.data() + point * layout.point_bytes + field.offset + element * field.size;
  uint64_t raw = 0;
  for (uint32_t i = field.size; i-- > 0;) raw = (raw << 8) | static_cast<unsigned char>(at[i]);
  if (field.type == 'F' && field.size == 4) {
    float value;
    const uint32_t narrow = static_cast<uint32_t>(raw);
    std::memcpy(&value, &narrow, 4);
    return value;
  }
  if (field.type == 'F') {
    double value;
    std::memcpy(&value, &raw, 8);
    return value;
  }
  if (field.type == 'I' && field.size < 8 && (raw >> (field.size * 8 - 1)) != 0) {
    return static_cast<double>(static_cast<int64_t>(raw | (~uint64_t{0} << (field.size * 8))));  // sign-extended
  }
  return field.type == 'I' ? static_cast<double>(static_cast<int64_t>(raw)) : static_cast<double>(raw);
}

uint32_t PcdCloud::Bits32(uint64_t point, const PcdField& field) const {
  return LittleEndian32(reinterpret_cast<const unsigned char*>(bytes.data()) + point * layout.point_bytes +
                        field.offset);
}

PcdCloud ReadPcdFile(const std::string& path) {
  PcdCloud cloud;
  cloud.layout = CheckPcdFile(path);
  const PcdLayout& layout = cloud.layout;
  std::ifstream stream(path, std::ios::binary);
  stream.seekg(static_cast<std::streamoff>(layout.body_offset));
  std::string body((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  const uint64_t points = layout.Points();
  cloud.bytes.assign(points * layout.point_bytes, '\0');

  if (layout.data == PcdData::kBinary) {
    cloud.bytes.assign(body, 0, cloud.bytes.size());  // CheckPcdFile saw that the body holds them
    return cloud;
  }
  if (layout.data == PcdData::kAscii) {
    std::istringstream values(body);
    std::string token;
    for (uint64_t point = 0; point < points; ++point) {
      for (const PcdField& field : layout.fields) {
        for (uint32_t element = 0; element < field.count; ++element) {
          const std::string where = "point " + std::to_string(point) + " " + field.name;
          if (!(values >> token)) ThrowInputError(path, where, "a value (POINTS counts more)", "end of file");
          char* out = &cloud.bytes[point * layout.point_bytes + field.offset + element * field.size];
          if (!StoreAscii(token, field.type, field.size, out)) {
            ThrowInputError(path, where,
                            std::string("a number of TYPE ") + field.type + " SIZE " + std::to_string(field.size),
                            "'" + token + "'");
          }
        }
      }
    }
    return cloud;
  }
  // binary_compressed: two sizes, then LZF data holding each field's values for all points, field after field.
  std::string by_field(cloud.bytes.size(), '\0');
  if (!DecompressLzf(reinterpret_cast<const unsigned char*>(body.data()) + 8, layout.compressed_bytes, &by_field)) {
    ThrowInputError(path, "DATA binary_compressed",
                    "LZF data that decompresses to " + std::to_string(by_field.size()) + " bytes",
                    "data that does not");
  }
  uint64_t start = 0;  // of the current field's block
  for (const PcdField& field : layout.fields) {
    const uint64_t field_bytes = uint64_t{field.size} * field.count;
    for (uint64_t point = 0; point < points; ++point) {
      std::memcpy(&cloud.bytes[point * layout.point_bytes + field.offset], &by_field[start + point * field_bytes],
                  field_bytes);
    }
    start += points * field_bytes;
  }
  return cloud;
}

}  // namespace ecv
