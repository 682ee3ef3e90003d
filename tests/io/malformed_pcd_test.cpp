// Malformed PCD files: each is refused with an InputError naming the file and the field, before PCL's reader trusts
// what the header claims; well-formed ones (ascii, binary, binary_compressed) load with their values.

#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "io/pcd_file.h"
#include "io/points_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// The header of a WIDTH x 1 cloud of x y z floats with `data` storage.
std::string Header(int width, const std::string& data, const std::string& points = "") {
  return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
         "COUNT 1 1 1\nWIDTH " +
         std::to_string(width) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
         (points.empty() ? std::to_string(width) : points) + "\nDATA " + data + "\n";
}

std::string Bytes(const std::vector<float>& values) {
  std::string bytes(values.size() * 4, '\0');
  std::memcpy(bytes.data(), values.data(), bytes.size());
  return bytes;
}

std::string Uint32(uint32_t value) {
  std::string bytes(4, '\0');
  for (int i = 0; i < 4; ++i) bytes[i] = static_cast<char>((value >> (8 * i)) & 0xff);
  return bytes;
}

// `raw` as LZF data of literal runs only (a control byte n < 32 copies the next n + 1 bytes): valid, uncompressed.
std::string LzfLiterals(const std::string& raw) {
  std::string out;
  for (size_t at = 0; at < raw.size(); at += 32) {
    const size_t n = std::min<size_t>(32, raw.size() - at);
    out += static_cast<char>(n - 1);
    out += raw.substr(at, n);
  }
  return out;
}

class MalformedPcd : public ::testing::Test {
 protected:
  std::string Write(const std::string& bytes) {
    const std::string path = directory_.File("cloud" + std::to_string(++files_) + ".pcd");
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  // The message of ReadPcdPoints's InputError on `bytes` ("" when it reads them).
  std::string Refusal(const std::string& bytes) {
    const std::string path = Write(bytes);
    try {
      ReadPcdPoints(path);
    } catch (const InputError& error) {
      EXPECT_THAT(error.what(), HasSubstr(path));
      return error.what();
    }
    return "";
  }

  test::TemporaryDirectory directory_;
  int files_ = 0;
};

const std::vector<float> kTwoPoints = {0.1F, 0.2F, 0.3F, -1.0F, 2.0F, 0.5F};

void ExpectTwoPoints(const std::vector<Eigen::Vector3f>& points) {
  ASSERT_EQ(points.size(), 2U);
  EXPECT_EQ(points[0], Eigen::Vector3f(0.1F, 0.2F, 0.3F));
  EXPECT_EQ(points[1], Eigen::Vector3f(-1.0F, 2.0F, 0.5F));
}

TEST_F(MalformedPcd, WellFormedAsciiBinaryAndCompressedCloudsRead) {
  ExpectTwoPoints(ReadPcdPoints(Write(Header(2, "ascii") + "0.1 0.2 0.3\n-1 2 0.5\n")));
  ExpectTwoPoints(ReadPcdPoints(Write(Header(2, "binary") + Bytes(kTwoPoints))));
  // Compressed data is stored field by field: all x, then all y, then all z.
  const std::string by_field = Bytes({0.1F, -1.0F, 0.2F, 2.0F, 0.3F, 0.5F});
  const std::string lzf = LzfLiterals(by_field);
  const std::string path = Write(Header(2, "binary_compressed") + Uint32(lzf.size()) + Uint32(24) + lzf);
  const PcdLayout layout = CheckPcdFile(path);
  ASSERT_EQ(layout.fields.size(), 3U);
  EXPECT_EQ(layout.fields[2].name, "z");
  EXPECT_EQ(layout.fields[2].offset, 8U);
  EXPECT_EQ(layout.point_bytes, 12U);
  EXPECT_EQ(layout.data, PcdData::kBinaryCompressed);
  ExpectTwoPoints(ReadPcdPoints(path));
}

TEST_F(MalformedPcd, RealCompressedCloudsPassTheCheck) {
  const PcdLayout layout = CheckPcdFile(test::DataPath("pcl_milk_scene/test/milk_cartoon_all_small_clorox.pcd"));
  EXPECT_EQ(layout.width, 640U);
  EXPECT_EQ(layout.height, 480U);
  EXPECT_EQ(layout.data, PcdData::kBinaryCompressed);
}

TEST_F(MalformedPcd, ACompressedBodyWhoseSizesDisagreeWithTheHeaderIsRefused) {
  const std::string lzf = LzfLiterals(Bytes(kTwoPoints));
  // An uncompressed size of 2 GB: PCL would allocate it, then copy the header's 24 bytes out of what it decompressed.
  EXPECT_THAT(Refusal(Header(2, "binary_compressed") + Uint32(lzf.size()) + Uint32(2184856955U) + lzf),
              AllOf(HasSubstr("DATA binary_compressed"), HasSubstr("24 bytes"), HasSubstr("2184856955")));
  EXPECT_THAT(Refusal(Header(2, "binary_compressed") + Uint32(lzf.size()) + Uint32(12) + lzf),
              HasSubstr("uncompressed size of 24 bytes"));
  // A compressed size past the end of the file.
  EXPECT_THAT(Refusal(Header(2, "binary_compressed") + Uint32(1000) + Uint32(24) + lzf),
              AllOf(HasSubstr("compressed size"), HasSubstr("1000")));
  EXPECT_THAT(Refusal(Header(2, "binary_compressed") + "\x01\x02"), HasSubstr("8 bytes"));
}

TEST_F(MalformedPcd, ABodyShorterThanTheHeaderClaimsIsRefused) {
  EXPECT_THAT(Refusal(Header(3, "binary") + Bytes(kTwoPoints)), AllOf(HasSubstr("DATA binary"), HasSubstr("36")));
  EXPECT_THAT(Refusal(Header(50, "ascii") + "0.1 0.2 0.3\n"), AllOf(HasSubstr("DATA ascii"), HasSubstr("150 values")));
}

TEST_F(MalformedPcd, CountsThatDisagreeOrExceedTheFileAreRefused) {
  EXPECT_THAT(Refusal(Header(2, "binary", "3") + Bytes(kTwoPoints)), AllOf(HasSubstr("POINTS"), HasSubstr("2 x 1")));
  EXPECT_THAT(Refusal(Header(2, "binary", "1000000000000") + Bytes(kTwoPoints)), HasSubstr("POINTS"));
  EXPECT_THAT(Refusal(Header(2, "binary", "-2") + Bytes(kTwoPoints)), AllOf(HasSubstr("POINTS"), HasSubstr("'-2'")));
  std::string header = Header(2, "binary");
  header.replace(header.find("WIDTH 2"), 7, "WIDTH 99999999999");
  EXPECT_THAT(Refusal(header + Bytes(kTwoPoints)), HasSubstr("WIDTH"));
}

TEST_F(MalformedPcd, AHeaderOutOfOrderOrWithUnknownLinesIsRefused) {
  std::string swapped = Header(2, "binary");
  swapped.replace(swapped.find("SIZE 4 4 4\nTYPE F F F"), 21, "TYPE F F F\nSIZE 4 4 4");
  EXPECT_THAT(Refusal(swapped + Bytes(kTwoPoints)), AllOf(HasSubstr("SIZE"), HasSubstr("a SIZE line before TYPE")));
  std::string unknown = Header(2, "binary");
  unknown.replace(unknown.find("HEIGHT 1"), 8, "HEIGHT 1\nSHAPE 2");
  EXPECT_THAT(Refusal(unknown + Bytes(kTwoPoints)), AllOf(HasSubstr("'SHAPE'"), HasSubstr("VIEWPOINT")));
  EXPECT_THAT(Refusal("VERSION 0.7\nFIELDS x y z\n"), AllOf(HasSubstr("DATA"), HasSubstr("none")));
}

TEST_F(MalformedPcd, ABodyIsNeverReadAsHeader) {
  // PCL's own reader parses header keywords after DATA too, and then indexes past its buffer.
  const std::string body = "COLUMNS x\nFIELDS x\nPOINTS 99\n";
  const std::vector<Eigen::Vector3f> points =
      ReadPcdPoints(Write(Header(3, "binary") + body + std::string(36 - body.size(), 'a')));
  EXPECT_EQ(points.size(), 3U);
  EXPECT_THAT(Refusal(Header(2, "ascii") + "0.1 0.2 0.3\n-1 FIELDS 0.5\n"),
              AllOf(HasSubstr("point 1 y"), HasSubstr("'FIELDS'")));
  EXPECT_THAT(Refusal(Header(2, "ascii") + "0.1 0.2 0.3\n-1 2\n"), AllOf(HasSubstr("point 1 z"), HasSubstr("end")));
}

TEST_F(MalformedPcd, CompressedDataThatDoesNotDecompressToItsSizeIsRefused) {
  std::string lzf = LzfLiterals(Bytes(kTwoPoints));
  lzf[0] = 31;  // a literal run longer than the data left
  EXPECT_THAT(Refusal(Header(2, "binary_compressed") + Uint32(lzf.size()) + Uint32(24) + lzf),
              HasSubstr("decompresses to 24 bytes"));
  // A back reference before the start of the output.
  const std::string back = std::string("\x20\x05") + std::string(22, '\0');
  EXPECT_THAT(Refusal(Header(2, "binary_compressed") + Uint32(back.size()) + Uint32(24) + back),
              HasSubstr("decompresses"));
}

TEST_F(MalformedPcd, FieldTypesAndSizesMustAgree) {
  std::string header = Header(2, "binary");
  header.replace(header.find("SIZE 4 4 4"), 10, "SIZE 4 2 4");
  EXPECT_THAT(Refusal(header + Bytes(kTwoPoints)), AllOf(HasSubstr("TYPE of y"), HasSubstr("F with SIZE 2")));
  header = Header(2, "binary");
  header.replace(header.find("COUNT 1 1 1"), 11, "COUNT 1 1");
  EXPECT_THAT(Refusal(header + Bytes(kTwoPoints)), AllOf(HasSubstr("COUNT"), HasSubstr("3 values")));
  header = Header(2, "binary");
  header.replace(header.find("DATA binary"), 11, "DATA packed");
  EXPECT_THAT(Refusal(header + Bytes(kTwoPoints)), AllOf(HasSubstr("DATA"), HasSubstr("'packed'")));
}

}  // namespace
}  // namespace ecv
