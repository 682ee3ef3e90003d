// Colour images: RGB in memory, round trip through PNG, the caller's image left alone.

#include <gtest/gtest.h>

#include "io/frame_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

TEST(ImageIo, WritingKeepsTheCallersImageAndRoundTrips) {
  cv::Mat image(4, 5, CV_8UC3, cv::Scalar(200, 30, 10));  // red in RGB
  image.at<cv::Vec3b>(1, 2) = {1, 2, 3};
  const cv::Mat original = image.clone();
  const test::TemporaryDirectory directory;
  WriteColorImage(directory.File("a.png"), image);
  EXPECT_EQ(cv::norm(image, original, cv::NORM_INF), 0.0) << "the caller's image must not change";
  WriteColorImage(directory.File("b.png"), image);
  for (const char* name : {"a.png", "b.png"}) {
    const cv::Mat read = ReadColorImage(directory.File(name));
    EXPECT_EQ(cv::norm(read, original, cv::NORM_INF), 0.0) << name;
  }
}

}  // namespace
}  // namespace ecv
