// Colour-pair CSV files (issue 8): RGB triplets and pixel pairs written and read back, window means of pixel pairs,
// and errors that name the file, the line and the field (and the pixel and image size for pixels outside).

#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "colorcal/pairs_csv.h"
#include "core/error.h"
#include "io/frame_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

// InputError message of reading `path`, or "" when it reads.
std::string ReadError(const std::string& path) {
  try {
    ReadColorPairsCsv(path);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// A 20x10 image whose pixel (x, y) is (10 x, 20 y, 100 + x + y).
cv::Mat GradientImage() {
  cv::Mat image(10, 20, CV_8UC3);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 20; ++x) image.at<cv::Vec3b>(y, x) = cv::Vec3b(10 * x, 20 * y, 100 + x + y);
  }
  return image;
}

TEST(PairsCsvTest, TripletsRoundTripExactly) {
  test::TemporaryDirectory directory;
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<ColorPair> pairs(25);
  for (ColorPair& pair : pairs) {
    pair.model = {uniform(random), uniform(random), uniform(random)};
    pair.scene = {uniform(random), uniform(random), uniform(random)};
  }
  pairs[0].model = {0.0, 1.0, 0.5};
  WriteColorPairsCsv(directory.File("pairs.csv"), pairs);
  const std::vector<ColorPair> read = ReadColorPairsCsv(directory.File("pairs.csv"));
  ASSERT_EQ(read.size(), pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    EXPECT_EQ(read[i].model, pairs[i].model);
    EXPECT_EQ(read[i].scene, pairs[i].scene);
  }
}

TEST(PairsCsvTest, HeaderIsTrimmedAndCaseInsensitiveCommentsAndBlankLinesSkipped) {
  test::TemporaryDirectory directory;
  WriteText(directory.File("pairs.csv"),
            "# hand-labelled\n\n MR, mg ,mb,sr,sg,sb\n0.1, 0.2,0.3,0.4,0.5,0.6\n\n# end\n");
  const std::vector<ColorPair> pairs = ReadColorPairsCsv(directory.File("pairs.csv"));
  ASSERT_EQ(pairs.size(), 1U);
  EXPECT_EQ(pairs[0].model, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(pairs[0].scene, Eigen::Vector3d(0.4, 0.5, 0.6));
}

TEST(PairsCsvTest, PixelPairsRoundTripAndGiveWindowMeansRelativeToTheCsv) {
  test::TemporaryDirectory directory;
  std::filesystem::create_directories(directory.path() / "scene");
  WriteColorImage(directory.File("model.png"), GradientImage());
  WriteColorImage(directory.File("scene/real.png"), GradientImage());  // a fresh one: WriteColorImage swaps R and B in
                                                                       // its argument (io/frame_io.cpp, reported)
  const std::vector<PixelPair> written = {{"model.png", {5, 4}, "scene/real.png", {0, 0}, 0},
                                          {"model.png", {19, 9}, "scene/real.png", {7, 2}, 0}};
  WritePixelPairsCsv(directory.File("pairs.csv"), written);

  const std::vector<PixelPair> read = ReadPixelPairsCsv(directory.File("pairs.csv"));
  ASSERT_EQ(read.size(), 2U);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(read[i].model_image, written[i].model_image);
    EXPECT_EQ(read[i].model_pixel, written[i].model_pixel);
    EXPECT_EQ(read[i].scene_image, written[i].scene_image);
    EXPECT_EQ(read[i].scene_pixel, written[i].scene_pixel);
    EXPECT_EQ(read[i].line, int(i) + 2);
  }

  const std::vector<ColorPair> colors = ReadColorPairsCsv(directory.File("pairs.csv"));  // 5x5 windows
  ASSERT_EQ(colors.size(), 2U);
  // The gradient is linear, so a window mean is the colour at the window's centre (clipped windows: their centre).
  EXPECT_LT((colors[0].model - Eigen::Vector3d(50, 80, 109) / 255.0).norm(), 1e-12);
  EXPECT_LT((colors[0].scene - Eigen::Vector3d(10, 20, 102) / 255.0).norm(), 1e-12);    // window x, y in 0..2
  EXPECT_LT((colors[1].model - Eigen::Vector3d(180, 160, 126) / 255.0).norm(), 1e-12);  // x 17..19, y 7..9
  PairCsvOptions single_pixel;
  single_pixel.window_radius_px = 0;
  EXPECT_LT(
      (ReadColorPairsCsv(directory.File("pairs.csv"), single_pixel)[1].scene - Eigen::Vector3d(70, 40, 109) / 255.0)
          .norm(),
      1e-12);
}

TEST(PairsCsvTest, PixelOutsideTheImageNamesThePixelAndTheSize) {
  test::TemporaryDirectory directory;
  WriteColorImage(directory.File("model.png"), GradientImage());
  WriteText(directory.File("pairs.csv"),
            "model_image,x,y,scene_image,x,y\nmodel.png,1,1,model.png,2,2\n"
            "model.png,3,3,model.png,20,3\n");
  EXPECT_THAT(ReadError(directory.File("pairs.csv")),
              AllOf(HasSubstr("pairs.csv:3"), HasSubstr("scene x,y"), HasSubstr("20x10"), HasSubstr("model.png"),
                    HasSubstr("got (20, 3)")));
  WriteText(directory.File("pairs.csv"), "model_image,x,y,scene_image,x,y\nmodel.png,-1,0,model.png,2,2\n");
  EXPECT_THAT(ReadError(directory.File("pairs.csv")),
              AllOf(HasSubstr("pairs.csv:2"), HasSubstr("model x,y"), HasSubstr("got (-1, 0)")));
}

TEST(PairsCsvTest, ParsingErrorsNameTheFileLineAndField) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("pairs.csv");
  const std::string triplets = "mr,mg,mb,sr,sg,sb\n";
  const std::string pixels = "model_image,x,y,scene_image,x,y\n";
  const struct {
    std::string text;
    std::vector<std::string> expected;
  } cases[] = {
      {"", {"pairs.csv", "header", "an empty file"}},
      {"# only a comment\n", {"header", "an empty file"}},
      {"r,g,b\n0,0,0\n", {"pairs.csv:1", "header", "mr,mg,mb,sr,sg,sb", "got 'r,g,b'"}},
      {triplets + "0.1,0.2,0.3,0.4,0.5\n", {"pairs.csv:2", "6 comma-separated fields", "got 5"}},
      {triplets + "# note\n0.1,0.2,abc,0.4,0.5,0.6\n", {"pairs.csv:3", "mb", "a number", "got 'abc'"}},
      {triplets + "0.1,0.2,0.3,0.4,,0.6\n", {"pairs.csv:2", "sg", "a number"}},
      {triplets + "0.1,0.2,0.3,0.4,128,0.6\n", {"pairs.csv:2", "sg", "[0, 1]", "divide by 255", "got 128"}},
      {triplets + "0.1,0.2,0.3,-0.1,0.5,0.6\n", {"pairs.csv:2", "sr", "[0, 1]", "got -0.1"}},
      {triplets + "0.1,0.2,0.3,nan,0.5,0.6\n", {"pairs.csv:2", "sr", "a number"}},
      {pixels + "m.png,1.5,2,s.png,3,4\n", {"pairs.csv:2", "model x", "an integer pixel coordinate", "got 1.5"}},
      {pixels + " ,1,2,s.png,3,4\n", {"pairs.csv:2", "model_image", "an image path"}},
      {pixels + "m.png,1,2,s.png,3,y\n", {"pairs.csv:2", "scene y", "a number"}},
      {pixels + "missing.png,1,2,s.png,3,4\n", {"pairs.csv:2", "model_image", "missing.png", "no such file"}},
  };
  for (const auto& bad : cases) {
    SCOPED_TRACE(bad.text);
    WriteText(path, bad.text);
    const std::string message = ReadError(path);
    for (const std::string& part : bad.expected) EXPECT_THAT(message, HasSubstr(part));
  }
  EXPECT_THAT(ReadError(directory.File("absent.csv")), AllOf(HasSubstr("absent.csv"), HasSubstr("readable")));
  WriteText(path, triplets + "0.1,0.2,0.3,0.4,0.5,0.6\n");
  EXPECT_THROW(ReadPixelPairsCsv(path), InputError);
  EXPECT_THROW(WritePixelPairsCsv(path, {{"a,b.png", {0, 0}, "s.png", {0, 0}, 0}}), InputError);
}

}  // namespace
}  // namespace ecv
