// The tracking rules without rendering: which priors are followed, which models are searched, and how a confirming
// search and the tracks it set aside are merged.

#include <gtest/gtest.h>

#include "recognize/tracking.h"

namespace ecv {
namespace {

const cv::Size kImage(64, 48);

Detection Prior(const std::string& model, double score, int frames_followed = 0) {
  Detection detection;
  detection.model = model;
  detection.score = score;
  detection.tracked = frames_followed > 0;
  detection.frames_followed = frames_followed;
  return detection;
}

// A verified instance whose surface is the rectangle's pixels.
VerifiedPose Instance(double score, const cv::Rect& surface, bool tracked, int frames_followed = 0) {
  VerifiedPose verified;
  verified.detection = Prior("box", score, tracked ? frames_followed : 0);
  verified.detection.tracked = tracked;
  for (int v = surface.y; v < surface.y + surface.height; ++v) {
    for (int u = surface.x; u < surface.x + surface.width; ++u) verified.surface.emplace_back(u, v);
  }
  return verified;
}

TEST(Tracking, APriorIsFollowedOnlyFromTheFollowScoreAndOnlyForAKnownModel) {
  TrackingOptions tracking;
  tracking.min_follow_score = 0.3;
  const std::vector<Detection> priors = {Prior("box", 0.5), Prior("can", 0.29), Prior("mug", 0.9), Prior("box", 0.3)};
  const std::vector<ModelInFrame> models = AssignPriors(priors, {"box", "can"}, tracking);
  ASSERT_EQ(models.size(), 2U);
  ASSERT_EQ(models[0].priors.size(), 2U);
  EXPECT_EQ(models[0].priors[0], &priors[0]);
  EXPECT_EQ(models[0].priors[1], &priors[3]);
  EXPECT_FALSE(models[0].lost);
  EXPECT_TRUE(models[1].priors.empty());
  EXPECT_TRUE(models[1].lost);  // seen, too weak to follow: looked for even between full searches
}

TEST(Tracking, ModelsSearchedAreThoseNotFoundUnderTheScopeAndThoseDueForConfirmation) {
  TrackingOptions tracking;
  tracking.confirm_every = 5;
  std::vector<ModelInFrame> models(4);
  AddInstance(Instance(0.6, {0, 0, 4, 4}, true, 2), 1, kImage, &models[0]);  // followed, not due ...
  models[0].instances[0].detection.confirmed = true;                         // ... once confirmed
  models[1].lost = true;                                                     // its prior failed
  AddInstance(Instance(0.6, {8, 8, 4, 4}, true, 5), 1, kImage, &models[3]);  // followed 5 frames: due
  EXPECT_EQ(ChooseModels(SearchScope::kLostTracks, tracking, 1, &models), 2);
  EXPECT_FALSE(models[0].search);
  EXPECT_TRUE(models[1].search);
  EXPECT_FALSE(models[2].search);  // never seen: waits for a full search
  EXPECT_TRUE(models[3].search);
  EXPECT_TRUE(models[3].instances.empty());  // set aside while its model is searched
  ASSERT_EQ(models[3].to_confirm.size(), 1U);
  EXPECT_TRUE(models[3].covered.empty());

  std::vector<ModelInFrame> full(2);
  AddInstance(Instance(0.6, {0, 0, 4, 4}, true, 1), 1, kImage, &full[0]);
  EXPECT_EQ(ChooseModels(SearchScope::kAllModels, tracking, 2, &full), 2);  // a second instance is looked for
  // A track no search has confirmed is due after tracking.confirm_first frames; a confirmed one after confirm_every.
  tracking.confirm_first = 1;
  std::vector<ModelInFrame> young(2);
  AddInstance(Instance(0.6, {0, 0, 4, 4}, true, 1), 1, kImage, &young[0]);
  AddInstance(Instance(0.6, {8, 8, 4, 4}, true, 1), 1, kImage, &young[1]);
  young[1].instances[0].detection.confirmed = true;
  EXPECT_EQ(ChooseModels(SearchScope::kLostTracks, tracking, 1, &young), 1);
  EXPECT_TRUE(young[0].search);
  EXPECT_FALSE(young[1].search);
  tracking.confirm_first = 0;  // as the others
  std::vector<ModelInFrame> as_others(1);
  AddInstance(Instance(0.6, {0, 0, 4, 4}, true, 4), 1, kImage, &as_others[0]);
  EXPECT_EQ(ChooseModels(SearchScope::kLostTracks, tracking, 1, &as_others), 0);
  tracking.confirm_first = 1;
  tracking.confirm_every = 0;  // never confirmed, young or not
  std::vector<ModelInFrame> never(1);
  AddInstance(Instance(0.6, {0, 0, 4, 4}, true, 50), 1, kImage, &never[0]);
  EXPECT_EQ(ChooseModels(SearchScope::kLostTracks, tracking, 1, &never), 0);
}

TEST(Tracking, FollowingThePriorsOnlySearchesNoModelNeitherLostNorDue) {
  TrackingOptions tracking;
  std::vector<ModelInFrame> models(3);
  models[0].lost = true;
  AddInstance(Instance(0.6, {8, 8, 4, 4}, true, 50), 1, kImage, &models[1]);  // long due for confirmation
  EXPECT_EQ(ChooseModels(SearchScope::kPriorsOnly, tracking, 1, &models), 0);
  for (const ModelInFrame& model : models) EXPECT_FALSE(model.search);
  EXPECT_EQ(models[1].instances.size(), 1U);  // not set aside
  EXPECT_TRUE(models[1].to_confirm.empty());
}

// The priors of one model, followed: a search's detection beside the tracks (RecognitionStream's search beside the
// tracking) competes with them on score.
TEST(Tracking, FollowedPriorsCompeteOnScoreAndASearchsDetectionConfirmsATrackOnItsSurface) {
  // One instance allowed: the better of a track and a search's detection elsewhere, whichever prior came first.
  ModelInFrame one;
  std::vector<Followed> elsewhere;
  elsewhere.push_back({Instance(0.5, {0, 0, 10, 10}, true, 7), false});
  elsewhere.push_back({Instance(0.8, {30, 30, 10, 10}, true, 2), true});
  KeepBestFollowed(std::move(elsewhere), kImage, 0.3, 1, 1, &one);
  ASSERT_EQ(one.instances.size(), 1U);
  EXPECT_DOUBLE_EQ(one.instances[0].detection.score, 0.8);
  EXPECT_FALSE(one.instances[0].detection.confirmed);  // no track on its surface
  EXPECT_EQ(cv::countNonZero(one.covered), 12 * 12);   // its surface and a pixel round it

  // On one surface: the better kept, confirmed, counting from the search; two instances allowed, one is kept.
  for (const bool search_better : {false, true}) {
    ModelInFrame same;
    std::vector<Followed> followed;
    followed.push_back({Instance(search_better ? 0.6 : 0.7, {0, 0, 10, 10}, true, 7), false});
    followed.push_back({Instance(search_better ? 0.7 : 0.6, {1, 1, 10, 10}, true, 2), true});
    KeepBestFollowed(std::move(followed), kImage, 0.3, 2, 1, &same);
    ASSERT_EQ(same.instances.size(), 1U) << search_better;
    EXPECT_DOUBLE_EQ(same.instances[0].detection.score, 0.7) << search_better;
    EXPECT_TRUE(same.instances[0].detection.confirmed) << search_better;
    EXPECT_EQ(same.instances[0].detection.frames_followed, 2) << search_better;
  }

  // Two tracks on one surface (no search among them): one kept, not confirmed.
  ModelInFrame tracks;
  std::vector<Followed> two;
  two.push_back({Instance(0.6, {0, 0, 10, 10}, true, 7), false});
  two.push_back({Instance(0.7, {1, 1, 10, 10}, true, 3), false});
  KeepBestFollowed(std::move(two), kImage, 0.3, 2, 1, &tracks);
  ASSERT_EQ(tracks.instances.size(), 1U);
  EXPECT_FALSE(tracks.instances[0].detection.confirmed);
  EXPECT_EQ(tracks.instances[0].detection.frames_followed, 3);
}

TEST(Tracking, AConfirmingSearchKeepsTheBetterPoseOfASurfaceAndConfirmsATrackItFound) {
  // The search finds the tracked surface with a lower score: the track stays, confirmed (its count starts again).
  ModelInFrame confirmed;
  confirmed.to_confirm.push_back(Instance(0.7, {0, 0, 10, 10}, true, 5));
  AddInstance(Instance(0.6, {1, 1, 10, 10}, false), 1, kImage, &confirmed);
  MergeConfirmation(kImage, 0.3, 1, 1, &confirmed);
  ASSERT_EQ(confirmed.instances.size(), 1U);
  EXPECT_TRUE(confirmed.instances[0].detection.tracked);
  EXPECT_EQ(confirmed.instances[0].detection.frames_followed, 0);
  EXPECT_TRUE(confirmed.instances[0].detection.confirmed);
  EXPECT_TRUE(confirmed.to_confirm.empty());
  EXPECT_EQ(cv::countNonZero(confirmed.covered), 11 * 11);  // its 10x10 surface and a pixel round it (at the corner)

  // A better pose elsewhere replaces the track (one instance allowed).
  ModelInFrame replaced;
  replaced.to_confirm.push_back(Instance(0.5, {0, 0, 10, 10}, true, 5));
  AddInstance(Instance(0.8, {30, 30, 10, 10}, false), 1, kImage, &replaced);
  MergeConfirmation(kImage, 0.3, 1, 1, &replaced);
  ASSERT_EQ(replaced.instances.size(), 1U);
  EXPECT_FALSE(replaced.instances[0].detection.tracked);
  EXPECT_DOUBLE_EQ(replaced.instances[0].detection.score, 0.8);

  // Nothing found: the track is kept and keeps counting, so its model is searched again next frame.
  ModelInFrame unconfirmed;
  unconfirmed.to_confirm.push_back(Instance(0.5, {0, 0, 10, 10}, true, 5));
  MergeConfirmation(kImage, 0.3, 1, 1, &unconfirmed);
  ASSERT_EQ(unconfirmed.instances.size(), 1U);
  EXPECT_EQ(unconfirmed.instances[0].detection.frames_followed, 5);
  EXPECT_FALSE(unconfirmed.instances[0].detection.confirmed);

  // Two instances allowed: the track and a search elsewhere both stay.
  ModelInFrame both;
  both.to_confirm.push_back(Instance(0.5, {0, 0, 10, 10}, true, 5));
  AddInstance(Instance(0.8, {30, 30, 10, 10}, false), 1, kImage, &both);
  MergeConfirmation(kImage, 0.3, 2, 1, &both);
  EXPECT_EQ(both.instances.size(), 2U);
}

TEST(Tracking, SharedFractionIsTheShareOfTheFirstSurfaceTheOtherCovers) {
  const VerifiedPose a = Instance(0.5, {0, 0, 10, 10}, false), b = Instance(0.5, {5, 0, 10, 10}, false);
  EXPECT_DOUBLE_EQ(SharedFraction(a.surface, b.surface, kImage), 0.5);
  EXPECT_DOUBLE_EQ(SharedFraction(a.surface, a.surface, kImage), 1.0);
  EXPECT_DOUBLE_EQ(SharedFraction({}, a.surface, kImage), 0.0);
}

}  // namespace
}  // namespace ecv
