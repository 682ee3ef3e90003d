// Both acceptances (the hand-set score and the learned model, recognize/acceptance.h) on poses of real YCB-Video
// frames that shape has to confirm or refute: each test checks the verdicts and that the geometric evidence (explained
// surface, free space, occluding contour) moves the right way between the right pose and the wrong one.

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "io/frame_io.h"
#include "modeldb/model_library.h"
#include "recognize/acceptance.h"
#include "recognize/evaluation.h"
#include "recognize/recognizer.h"
#include "scenes/composites.h"
#include "support/test_data.h"
#include "support/ycbv_library.h"
#include "verify_prior.h"

namespace ecv {
namespace {

// A pose's verdicts under the two acceptances, each with the default visible-share bar.
struct Verdicts {
  bool hand = false;
  bool learned = false;
};

Verdicts Judge(const Detection& detection) {
  const RecognizerOptions defaults;
  const AcceptanceModel& learned = AcceptanceModel::Learned();
  const bool visible = detection.visible_fraction >= defaults.verify.min_visible_fraction;
  return {visible && detection.score >= defaults.verify.min_score,
          visible && learned.Probability(detection) >= learned.threshold()};
}

double Learned(const Detection& detection) {
  return AcceptanceModel::Learned().Probability(detection);
}

// The evidence a failure message shows.
std::string Describe(const Detection& d) {
  return d.model + ": score " + std::to_string(d.score) + ", learned " + std::to_string(Learned(d)) + ", explained " +
         std::to_string(d.explained_surface) + ", free space " + std::to_string(d.free_space_violation) +
         ", occluding " + std::to_string(d.occluding_contour) + ", creased " + std::to_string(d.creased_contour) +
         ", depth " + std::to_string(d.depth_agreement) + ", colour " + std::to_string(d.color_agreement);
}

using test::TruthOf;

class AcceptanceOnRealFrames : public test::YcbvLibrarySuite {
 protected:
  static ModelLibrary Models(const std::vector<std::string>& names) {
    LibraryLoadOptions load;
    load.build_matchers = false;
    load.names = names;
    return ModelLibrary::Load(library_, load);
  }

  // Every pose reported with its evidence for Judge to decide: as given, or refined by ICP first.
  static RecognizerOptions Reported(bool refine) {
    RecognizerOptions options;
    options.refine = refine;
    options.verify.min_score = 0.0;
    options.verify.min_visible_fraction = 0.0;
    return options;
  }

  static std::string Scene(const std::string& frame) { return test::DataPath("ycbv_subset/Example-Scenes/" + frame); }
};

// 0002/000009: point pairs alone (--models 009_gelatin_box --hypotheses ppf) put the gelatin box on the potted meat
// can's front face (the pose below), where the depth fits. Both acceptances reject it; the can at its ground truth
// (refined) passes the hand-set bar, and the learned model, which rejects it too (0.49 against 0.50), rates it far
// above the box. The can's surface is explained better and its outline is a crease where the table turns away; the
// box's outline runs over the can's face. (The occluding contour does not separate them: the can lies on the table.)
TEST_F(AcceptanceOnRealFrames, TheGelatinBoxPointPairsLayOnThePottedMeatCanIsRejected) {
  const LoadedFrame frame = LoadYcbvFrame(Scene("0002/000009"));
  Eigen::Isometry3d on_can;
  on_can.matrix() << -0.90201, 0.43164, -0.00830, 0.12552,  //
      -0.28647, -0.58403, 0.75950, 0.04274,                 //
      0.32298, 0.68745, 0.65045, 1.06137,                   //
      0.0, 0.0, 0.0, 1.0;
  on_can.linear() = Eigen::Quaterniond(on_can.linear()).normalized().toRotationMatrix();
  const Detection box =
      test::VerifyPrior(Models({"009_gelatin_box"}), Reported(false), frame.rgbd, "009_gelatin_box", on_can);
  const Detection can =
      test::VerifyPrior(Models({"010_potted_meat_can"}), Reported(true), frame.rgbd, "010_potted_meat_can",
                        TruthOf(frame, "010_potted_meat_can").camera_from_object);
  const std::string evidence = Describe(box) + "\n" + Describe(can);
  EXPECT_GT(box.depth_agreement, 0.9) << evidence;  // the box fits the can's face
  EXPECT_FALSE(Judge(box).hand) << evidence;
  EXPECT_FALSE(Judge(box).learned) << evidence;
  EXPECT_TRUE(Judge(can).hand) << evidence;
  EXPECT_GT(Learned(can), Learned(box) + 0.3) << evidence;
  EXPECT_GT(can.explained_surface, box.explained_surface + 0.03) << evidence;
  EXPECT_GT(can.creased_contour, box.creased_contour + 0.15) << evidence;
}

// 0002/000005: the banana at its ground truth against the banana turned end to end (half a turn about the table's
// normal through its middle), which lies on the same pixels: the scene explains less of the turned banana's surface
// and sees more of the table behind it. Both acceptances take the true pose and reject the turned one.
TEST_F(AcceptanceOnRealFrames, TheBananaTurnedEndToEndIsRejectedAndItsTruePoseAccepted) {
  const bench::SourceFrame source = bench::LoadSourceFrame(Scene("0002/000005"));
  const Eigen::Isometry3d truth = TruthOf(source.frame, "011_banana").camera_from_object;
  const std::vector<Eigen::Vector3d>& points = source.model_points.at("011_banana");
  Eigen::Vector3d middle = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) middle += p;
  middle /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) scatter += (p - middle) * (p - middle).transpose();
  const Eigen::Vector3d length = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2);
  Eigen::Vector3d up = truth.linear().transpose() * source.table.normal;  // the table's normal, object frame
  up = (up - up.dot(length) * length).normalized();
  Eigen::Isometry3d end_to_end = Eigen::Isometry3d::Identity();
  end_to_end.translate(middle).rotate(Eigen::AngleAxisd(M_PI, up)).translate(-middle);

  const ModelLibrary banana = Models({"011_banana"});
  const Detection right = test::VerifyPrior(banana, Reported(false), source.frame.rgbd, "011_banana", truth);
  const Detection turned =
      test::VerifyPrior(banana, Reported(false), source.frame.rgbd, "011_banana", truth * end_to_end);
  const std::string evidence = Describe(right) + "\n" + Describe(turned);
  EXPECT_TRUE(Judge(right).hand) << evidence;
  EXPECT_TRUE(Judge(right).learned) << evidence;
  EXPECT_FALSE(Judge(turned).hand) << evidence;
  EXPECT_FALSE(Judge(turned).learned) << evidence;
  EXPECT_GT(turned.depth_agreement, 0.85) << evidence;  // on the banana's pixels still
  EXPECT_GT(right.explained_surface, turned.explained_surface + 0.05) << evidence;
  EXPECT_LT(right.free_space_violation, turned.free_space_violation - 0.01) << evidence;
}

// 0001/000001 with the mustard bottle's print painted over: every pixel its label marks set to one yellow (the
// median of its yellow pixels), depth unchanged. At its ground truth (refined) the geometric evidence is what it was
// before the paint, to the digit, and the unpainted bottle is accepted by both acceptances. (Painted, neither accepts
// it and no hypothesis comes within 0.1 d of it: bench/EXPERIMENTS.md, 2026-12-06.)
TEST_F(AcceptanceOnRealFrames, TheGeometricEvidenceOfTheMustardBottleIsBlindToItsPaint) {
  const bench::SourceFrame source = bench::LoadSourceFrame(Scene("0001/000001"));
  constexpr int kMustardLabel = 5;
  const cv::Mat bottle = source.labels == kMustardLabel;
  cv::Mat hsv;
  cv::cvtColor(source.frame.rgbd.color, hsv, cv::COLOR_RGB2HSV);
  std::vector<int> channel[3];
  for (int v = 0; v < bottle.rows; ++v) {
    for (int u = 0; u < bottle.cols; ++u) {
      const cv::Vec3b h = hsv.at<cv::Vec3b>(v, u);
      if (bottle.at<uint8_t>(v, u) == 0 || h[0] < 20 || h[0] > 35 || h[1] < 120) continue;  // yellow: hue 40-70 deg
      const cv::Vec3b rgb = source.frame.rgbd.color.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c) channel[c].push_back(rgb[c]);
    }
  }
  ASSERT_GT(channel[0].size(), 500U);
  cv::Vec3b yellow;
  for (int c = 0; c < 3; ++c) {
    std::nth_element(channel[c].begin(), channel[c].begin() + channel[c].size() / 2, channel[c].end());
    yellow[c] = static_cast<uint8_t>(channel[c][channel[c].size() / 2]);
  }
  RgbdFrame painted = source.frame.rgbd;
  painted.color = source.frame.rgbd.color.clone();
  painted.color.setTo(yellow, bottle);

  const ModelLibrary mustard = Models({"006_mustard_bottle"});
  const Eigen::Isometry3d truth = TruthOf(source.frame, "006_mustard_bottle").camera_from_object;
  const Detection plain = test::VerifyPrior(mustard, Reported(true), painted, "006_mustard_bottle", truth);
  const Detection printed = test::VerifyPrior(mustard, Reported(true), source.frame.rgbd, "006_mustard_bottle", truth);
  const std::string evidence = Describe(plain) + "\n" + Describe(printed);
  EXPECT_TRUE(Judge(printed).hand) << evidence;
  EXPECT_TRUE(Judge(printed).learned) << evidence;
  EXPECT_LT(plain.color_agreement, printed.color_agreement - 0.3) << evidence;  // the paint took
  EXPECT_GT(plain.explained_surface, 0.6) << evidence;
  EXPECT_EQ(plain.explained_surface, printed.explained_surface) << evidence;
  EXPECT_EQ(plain.free_space_violation, printed.free_space_violation) << evidence;
  EXPECT_EQ(plain.occluding_contour, printed.occluding_contour) << evidence;
  EXPECT_EQ(plain.creased_contour, printed.creased_contour) << evidence;
}

// 0000/000001, the foam brick built without its texture (one grey model): accepted by both acceptances at its ground
// truth (refined), rejected by both 2 cm off along either image axis. Off, the scene explains little of its surface,
// its outline no longer steps back from the scene, and mostly the table is seen behind where it should be.
TEST_F(AcceptanceOnRealFrames, AGreyFoamBrickIsAcceptedAtItsPoseAndRejectedTwoCentimetresOff) {
  const std::string path = directory_->File("foam_brick.sqlite");
  ASSERT_NO_FATAL_FAILURE(AddUntexturedModel("061_foam_brick", true, path));
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary brick = ModelLibrary::Load(path, load);
  const LoadedFrame frame = LoadYcbvFrame(Scene("0000/000001"));
  const Eigen::Isometry3d truth = TruthOf(frame, "061_foam_brick").camera_from_object;
  const Detection right = test::VerifyPrior(brick, Reported(true), frame.rgbd, "061_foam_brick", truth);
  EXPECT_TRUE(Judge(right).hand) << Describe(right);
  EXPECT_TRUE(Judge(right).learned) << Describe(right);
  int behind = 0;  // offsets with the scene seen behind the brick
  for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0.02, 0, 0), Eigen::Vector3d(-0.02, 0, 0),
                                        Eigen::Vector3d(0, 0.02, 0), Eigen::Vector3d(0, -0.02, 0)}) {
    Eigen::Isometry3d moved = truth;
    moved.pretranslate(offset);
    const Detection off = test::VerifyPrior(brick, Reported(false), frame.rgbd, "061_foam_brick", moved);
    const std::string evidence = Describe(right) + "\n" + Describe(off);
    EXPECT_FALSE(Judge(off).hand) << evidence;
    EXPECT_FALSE(Judge(off).learned) << evidence;
    EXPECT_LT(off.explained_surface, right.explained_surface - 0.5) << evidence;
    EXPECT_LT(off.occluding_contour, right.occluding_contour - 0.2) << evidence;
    behind += off.free_space_violation > right.free_space_violation + 0.2 ? 1 : 0;
  }
  EXPECT_GE(behind, 3);
}

}  // namespace
}  // namespace ecv
