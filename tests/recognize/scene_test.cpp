// The scene's descriptors: the library's descriptor settings under the recognizer's caps.
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "ecv/descriptor.h"
#include "ecv/primitives.h"
#include "recognize/recognizer_options.h"
#include "recognize/scene.h"

namespace ecv {
namespace {

// The scene's descriptors (ComputeSceneDescriptors) keep the library's settings but for the two caps: every n-th
// primitive a source beyond scene_max_descriptors, and no more neighbours than scene_max_neighbours unless the
// library asks for fewer.
TEST(SceneDescriptors, FollowTheRecognizersCaps) {
  std::vector<Primitive> primitives;  // 1000 texlets 4 mm apart: most have over a hundred within 2.5 cm
  for (int i = 0; i < 1000; ++i) {
    Primitive texlet;
    texlet.position = Eigen::Vector3f(0.004F * static_cast<float>(i % 40), 0.004F * static_cast<float>(i / 40), 1.0F);
    texlet.color = Eigen::Vector3f(0.3F, 0.5F, static_cast<float>(i % 7) / 7.0F);
    primitives.push_back(texlet);
  }
  DescriptorOptions library;
  RecognizerOptions options;
  options.threads = 1;
  options.scene_max_descriptors = 300;  // 1000 primitives: every 4th is a source
  options.scene_max_neighbours = 16;
  const Descriptors capped = ComputeSceneDescriptors(primitives, library, options);
  ASSERT_EQ(capped.values.rows, 250);
  for (const int source : capped.primitive) EXPECT_EQ(source % 4, 0);
  DescriptorOptions sixteen = library;
  sixteen.max_neighbours = 16;
  const Descriptors expected = ComputeDescriptors(primitives, sixteen, 1, 4);
  EXPECT_EQ(cv::norm(capped.values, expected.values, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(capped.values, ComputeDescriptors(primitives, library, 1, 4).values, cv::NORM_INF), 0.01);

  DescriptorOptions eight = library;  // the library's own tighter cap stays
  eight.max_neighbours = 8;
  EXPECT_EQ(cv::norm(ComputeSceneDescriptors(primitives, eight, options).values,
                     ComputeDescriptors(primitives, eight, 1, 4).values, cv::NORM_INF),
            0.0);

  options.scene_max_descriptors = 0;  // 0: every primitive; scene_max_neighbours 0: the library's setting
  options.scene_max_neighbours = 0;
  const Descriptors all = ComputeSceneDescriptors(primitives, library, options);
  EXPECT_EQ(all.values.rows, 1000);
  EXPECT_EQ(cv::norm(all.values, ComputeDescriptors(primitives, library).values, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace ecv
