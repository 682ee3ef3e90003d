// Colour calibration on real YCB-Video frames (issue 8): the textured mustard bottle is rendered (unlit, as the model
// library renders it) at its ground-truth pose; pairs are sampled automatically where the render's depth agrees with
// the real depth. A fitted on frames of video 0001 must lower the mean colour error between rendered model and real
// object on frames of video 0002, and the other way round.

#include <iostream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "colorcal/color_pairs.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "render/renderer.h"
#include "support/test_data.h"

namespace ecv {
namespace {

constexpr const char* kObject = "006_mustard_bottle";

// Pairs of `kObject` on frames `frames` of `video`: `fit` sampled for fitting (skipping dark and saturated pixels),
// `all` every pixel where the render lies on the object (for the error).
struct VideoPairs {
  std::vector<ColorPair> fit, all;
};

VideoPairs CollectPairs(Renderer& renderer, MeshId mesh, const std::string& video, const std::vector<int>& frames) {
  PosePairOptions every_pixel;
  every_pixel.max_pairs = 0;
  every_pixel.window_radius_px = 0;
  every_pixel.min_value = 0.0;
  every_pixel.max_value = 1.0;
  VideoPairs pairs;
  for (int frame_id : frames) {
    const std::string name = std::to_string(1000000 + frame_id).substr(1);
    const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/" + video + "/" + name));
    for (const GroundTruth& truth : frame.ground_truth) {
      if (truth.object_name != kObject) continue;
      const RenderResult render = renderer.Render(mesh, frame.rgbd.camera, truth.camera_from_object);
      const cv::Mat mask = DepthAgreementMask(render.depth, frame.rgbd.depth, 0.01);
      const PosePairs fit = ColorPairsFromPose(render.color, frame.rgbd.color, mask);
      const PosePairs all = ColorPairsFromPose(render.color, frame.rgbd.color, mask, every_pixel);
      EXPECT_GT(fit.pairs.size(), 500U) << video << "/" << name;
      pairs.fit.insert(pairs.fit.end(), fit.pairs.begin(), fit.pairs.end());
      pairs.all.insert(pairs.all.end(), all.pairs.begin(), all.pairs.end());
    }
  }
  return pairs;
}

TEST(ColorcalRealTest, MatrixFromOneVideoLowersTheColourErrorOnAnother) {
  MeshLoadOptions options;
  options.object_from_mesh =
      ReadTransformTable(test::DataPath("ycbv_subset/derived/google16k_to_ycbv.txt")).at(kObject);
  Renderer renderer;
  const MeshId mesh = renderer.AddMesh(LoadMesh(
      test::DataPath(std::string("ycbv_subset/ycb_google16k_textured/") + kObject + "_textured.obj"), options));
  const std::vector<int> frames = {1, 7, 13, 19};
  const VideoPairs first = CollectPairs(renderer, mesh, "0001", frames);
  const VideoPairs second = CollectPairs(renderer, mesh, "0002", frames);
  ASSERT_GT(first.fit.size(), 2000U);
  ASSERT_GT(second.fit.size(), 2000U);

  for (const auto& [fit_on, test_on, name] :
       {std::tuple(&first, &second, "fit 0001, test 0002"), std::tuple(&second, &first, "fit 0002, test 0001")}) {
    SCOPED_TRACE(name);
    const ColorFit fit = FitColorMatrix(fit_on->fit);
    const double before = MeanColorError(test_on->all);
    const double after = MeanColorError(test_on->all, fit.A);
    std::cout << kObject << ", " << name << ": mean colour error " << before << " -> " << after << " ("
              << fit.num_inliers << "/" << fit_on->fit.size() << " inliers, rms " << fit.rms << ", condition "
              << fit.condition_number << ")\n";
    EXPECT_LT(after, 0.8 * before);
    // Fitting on the test video itself is the best a matrix can do there; the transferred one comes near it.
    const double own = MeanColorError(test_on->all, FitColorMatrix(test_on->fit).A);
    EXPECT_LT(after, own + 0.5 * (before - own));
  }
}

}  // namespace
}  // namespace ecv
