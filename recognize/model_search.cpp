#include "recognize/model_search.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "core/timing.h"
#include "recognize/scoring.h"

namespace ecv {
namespace {

// The given rows of `descriptors`, in that order.
Descriptors CopyRows(const Descriptors& descriptors, const std::vector<int>& rows) {
  Descriptors copy;
  copy.values.create(static_cast<int>(rows.size()), descriptors.values.cols, descriptors.values.type());
  const size_t row_bytes = static_cast<size_t>(descriptors.values.cols) * descriptors.values.elemSize();
  copy.primitive.reserve(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    std::memcpy(copy.values.ptr(static_cast<int>(i)), descriptors.values.ptr(rows[i]), row_bytes);
    copy.primitive.push_back(descriptors.primitive[static_cast<size_t>(rows[i])]);
  }
  return copy;
}

}  // namespace

void CoverSurface(const std::vector<cv::Point>& surface, int stride, cv::Mat* covered) {
  cv::Mat samples = cv::Mat::zeros(covered->size(), CV_8UC1);
  for (const cv::Point& p : surface) samples.at<uchar>(p) = 1;
  cv::dilate(samples, samples, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * stride + 1, 2 * stride + 1)));
  *covered |= samples;
}

double CoveredShare(const std::vector<cv::Point>& surface, const cv::Mat& covered) {
  if (covered.empty() || surface.empty()) return 0.0;
  const auto on =
      std::count_if(surface.begin(), surface.end(), [&](const cv::Point& p) { return covered.at<uchar>(p) != 0; });
  return static_cast<double>(on) / static_cast<double>(surface.size());
}

ModelSearch::ModelSearch(const ModelRecord& record, const RecognizerOptions& options, const Scene& scene,
                         VerifyPose verify, int ransac_threads)
    : record_(record), options_(options), scene_(scene), verify_(std::move(verify)), ransac_threads_(ransac_threads) {}

ConsistencyOptions ModelSearch::Consistency() const {
  ConsistencyOptions consistency = options_.ranking.consistency;
  consistency.max_distance_m = record_.diameter_m;
  return consistency;
}

// A view's ranking subset of descriptor rows (a seeded random max_correspondences of them) and the other rows, each
// in row order.
ModelSearch::RowSplit ModelSearch::RankingRows(size_t view) const {
  const auto rows = static_cast<size_t>(record_.views[view].descriptors.values.rows);
  const auto count = static_cast<size_t>(options_.ranking.max_correspondences);
  RowSplit split;
  split.ranking.resize(rows);
  std::iota(split.ranking.begin(), split.ranking.end(), 0);
  if (rows <= count) return split;
  std::mt19937_64 random(options_.ransac.seed + view);
  std::shuffle(split.ranking.begin(), split.ranking.end(), random);
  split.rest.assign(split.ranking.begin() + static_cast<std::ptrdiff_t>(count), split.ranking.end());
  split.ranking.resize(count);
  std::sort(split.ranking.begin(), split.ranking.end());
  std::sort(split.rest.begin(), split.rest.end());
  return split;
}

// The nearest scene primitive of each of `descriptors` (rows of the view's); `checks` > 0 replaces match.checks.
std::vector<Correspondence> ModelSearch::Correspondences(const ModelView& view, const Descriptors& descriptors,
                                                         int checks) const {
  std::vector<Correspondence> found;
  for (const DescriptorMatch& match : scene_.matcher->Match(view.primitives, descriptors, checks)) {
    if (match.rank == 0) found.push_back({match.query, match.train});
  }
  return found;
}

std::vector<ViewCandidate> ModelSearch::RankViews() const {
  std::vector<ViewCandidate> views;
  if (!scene_.matcher) return views;
  for (size_t v = 0; v < record_.views.size(); ++v) {
    const ModelView& view = record_.views[v];
    if (view.descriptors.values.rows == 0) continue;
    ViewCandidate candidate;
    candidate.view = static_cast<int>(v);
    candidate.correspondences =
        Correspondences(view, CopyRows(view.descriptors, RankingRows(v).ranking), options_.RankingChecks());
    candidate.score = ConsistentSetSize(view.primitives, scene_.primitives, candidate.correspondences, Consistency());
    views.push_back(std::move(candidate));
  }
  std::stable_sort(views.begin(), views.end(),
                   [](const ViewCandidate& a, const ViewCandidate& b) { return a.score > b.score; });
  return views;
}

// Gives `candidate` its correspondences, once: the nearest scene descriptor of each of its descriptors (paper: object
// to scene). When the ranking searched as matching does (or the search is exact), only the rows it did not match are
// searched here. They are put in the order that matching all rows at once gives (MatchOrderLess), so that RANSAC
// draws the same samples.
void ModelSearch::Match(ViewCandidate* candidate) const {
  if (candidate->matched) return;
  const auto view = static_cast<size_t>(candidate->view);
  const ModelView& model_view = record_.views[view];
  const bool reuse_ranking =
      options_.RankingChecks() == options_.match.checks || options_.match.index == MatchIndex::kBytes;
  std::vector<Correspondence> found;
  if (reuse_ranking) {
    found = Correspondences(model_view, CopyRows(model_view.descriptors, RankingRows(view).rest));
    found.insert(found.end(), candidate->correspondences.begin(), candidate->correspondences.end());
  } else {
    found = Correspondences(model_view, model_view.descriptors);
  }
  std::sort(found.begin(), found.end(), [&](const Correspondence& a, const Correspondence& b) {
    return MatchOrderLess(model_view.primitives, options_.match.structure_specific, a.object, b.object);
  });
  candidate->correspondences = std::move(found);
  candidate->matched = true;
}

// Matches, RANSAC and verification of one view, once per frame (a later instance of the model reuses them).
void ModelSearch::Try(ViewCandidate* candidate, StageTimes* times) const {
  if (candidate->tried) return;
  candidate->tried = true;
  Clock::time_point stage = Clock::now();
  Match(candidate);
  times->Add(Stage::kMatch, MillisecondsSince(stage));

  stage = Clock::now();
  RansacOptions ransac = options_.ransac;
  ransac.threads = ransac_threads_;
  ransac.sample_radius_m = options_.sample_radius_diameters * record_.diameter_m;
  Hypothesis hypothesis;
  hypothesis.view = candidate->view;
  const std::vector<Eigen::Vector3f> object_points =
      PrimitivePositions(record_.views[static_cast<size_t>(candidate->view)].primitives);
  if (options_.projective_inliers) {
    ransac.projective_stride_px = options_.ransac_stride_px;
    hypothesis.ransac =
        EstimatePoseRansac(object_points, scene_.ransac_points, candidate->correspondences, ransac, &scene_.visibility);
  } else {
    hypothesis.ransac = EstimatePoseRansac(object_points, scene_.ransac_points, *scene_.ransac_grid,
                                           candidate->correspondences, ransac, &scene_.visibility);
  }
  hypothesis.pose = hypothesis.ransac.scene_from_object;
  times->Add(Stage::kRansac, MillisecondsSince(stage));
  if (!hypothesis.ransac.success) return;

  stage = Clock::now();
  candidate->verified = verify_(hypothesis);
  candidate->hypothesis = hypothesis;
  times->Add(Stage::kVerify, MillisecondsSince(stage));
}

std::optional<VerifiedPose> ModelSearch::BestPose(int count, int give_up_after, const cv::Mat& covered,
                                                  std::vector<ViewCandidate>* ranked, StageTimes* times) const {
  const ViewCandidate* best_view = nullptr;
  for (size_t i = 0; i < std::min(ranked->size(), static_cast<size_t>(count)); ++i) {
    if (give_up_after > 0 && i == static_cast<size_t>(give_up_after) &&
        (best_view == nullptr || best_view->verified->search_score < options_.give_up_below_score)) {
      break;
    }
    ViewCandidate& candidate = (*ranked)[i];
    Try(&candidate, times);
    if (!candidate.verified || CoveredShare(candidate.verified->surface, covered) > options_.max_overlap) continue;
    if (best_view == nullptr || candidate.verified->search_score > best_view->verified->search_score) {
      best_view = &candidate;
    }
    if (options_.good_enough_score > 0.0 && best_view->verified->search_score >= options_.good_enough_score) break;
  }
  if (best_view == nullptr) return std::nullopt;
  std::optional<VerifiedPose> best = best_view->verified;
  if (!options_.refine) return best;

  // Of a bottle's front and back, coarse poses that score alike, the one ICP refines usually wins: both are refined.
  const ViewCandidate* rival = TurnedRival(*ranked, count, *best_view, covered);
  for (const ViewCandidate* view : {best_view, rival}) {
    if (view == nullptr) continue;
    Clock::time_point stage = Clock::now();
    Hypothesis refined = *view->hypothesis;
    Refine(view->verified->depth, &refined);
    times->Add(Stage::kRefine, MillisecondsSince(stage));
    stage = Clock::now();
    VerifiedPose verified = verify_(refined);
    times->Add(Stage::kVerify, MillisecondsSince(stage));
    // A refined pose is kept only if ICP did not lower its score.
    const VerifiedPose& pose = verified.detection.score >= view->verified->detection.score ? verified : *view->verified;
    if (view == best_view || pose.detection.score > best->detection.score) best = pose;
  }
  return best;
}

// Of the first `count` tried views, the one whose verified pose is turned more than 90 degrees from `best`'s and
// scores highest, at least rival_min_ratio of `best`'s score, not lying mostly on `covered` pixels; or nullptr.
const ViewCandidate* ModelSearch::TurnedRival(const std::vector<ViewCandidate>& ranked, int count,
                                              const ViewCandidate& best, const cv::Mat& covered) const {
  if (options_.rival_min_ratio <= 0.0) return nullptr;
  const double best_score = best.verified->search_score;
  const Eigen::Matrix3d best_rotation = best.verified->detection.camera_from_object.linear();
  const ViewCandidate* rival = nullptr;
  for (size_t i = 0; i < std::min(ranked.size(), static_cast<size_t>(count)); ++i) {
    const ViewCandidate& candidate = ranked[i];
    if (&candidate == &best || !candidate.verified) continue;
    const double score = candidate.verified->search_score;
    if (score <= 0.0 || score < options_.rival_min_ratio * best_score) continue;
    if (rival != nullptr && score <= rival->verified->search_score) continue;
    const Eigen::AngleAxisd turn(best_rotation.transpose() * candidate.verified->detection.camera_from_object.linear());
    if (turn.angle() <= M_PI / 2.0) continue;
    if (CoveredShare(candidate.verified->surface, covered) > options_.max_overlap) continue;
    rival = &candidate;
  }
  return rival;
}

void ModelSearch::Refine(const cv::Mat& rendered_depth, Hypothesis* hypothesis) const {
  const PinholeCamera camera = scene_.frame->camera.Sampled(options_.dense_stride_px);
  const Eigen::Isometry3f object_from_camera = hypothesis->pose.inverse().cast<float>();
  std::vector<Eigen::Vector3f> object_points;
  for (int v = 0; v < rendered_depth.rows; ++v) {
    for (int u = 0; u < rendered_depth.cols; ++u) {
      const float z = rendered_depth.at<float>(v, u);
      if (z > 0.0F) object_points.push_back(object_from_camera * camera.BackProject({u, v}, z).cast<float>());
    }
  }
  if (options_.icp_max_points > 0 && object_points.size() > static_cast<size_t>(options_.icp_max_points)) {
    const size_t step = (object_points.size() + options_.icp_max_points - 1) / options_.icp_max_points;
    for (size_t i = 0; i * step < object_points.size(); ++i) object_points[i] = object_points[i * step];
    object_points.resize((object_points.size() + step - 1) / step);
  }
  if (object_points.size() < 10) return;
  if (options_.projective_icp) {
    const IcpResult icp = RefinePointToPlaneProjective(object_points, scene_.organized, hypothesis->pose, options_.icp);
    if (icp.success) hypothesis->pose = icp.scene_from_object;
    return;
  }
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& point : object_points) centre += point;
  centre = hypothesis->pose.cast<float>() * (centre / static_cast<float>(object_points.size()));
  const float radius = 0.5F * static_cast<float>(record_.diameter_m) + 0.03F;
  std::vector<Eigen::Vector3f> near;
  for (size_t i = 0; i < scene_.points.size(); i += 2) {  // half the dense points suffice
    if ((scene_.points[i] - centre).squaredNorm() < radius * radius) near.push_back(scene_.points[i]);
  }
  const IcpResult icp = RefinePointToPlane(object_points, near, hypothesis->pose, options_.icp);
  if (icp.success) hypothesis->pose = icp.scene_from_object;
}

}  // namespace ecv
