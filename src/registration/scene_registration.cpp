#include "registration/scene_registration.h"

#include <algorithm>
#include <chrono>

#include "core/error.h"
#include "core/timing.h"

namespace ecv {
RansacOptions RegistrationOptions::SceneRansacOptions() {
  RansacOptions options;
  options.required_inlier_fraction = 0.1;
  options.adaptive = true;  // two views of one scene often share most correspondences: stop once that is clear
  return options;
}

void RegistrationOptions::Check() const {
  features.Check();
  descriptors.Check();
  matching.Check();
  ransac.Check();
  icp.Check();
  if (dense_stride_px < 1) ThrowInputError("registration options", "dense_stride_px", "at least 1");
}

RegistrationView PrepareRegistrationView(const RgbdFrame& frame, const RegistrationOptions& options) {
  options.Check();
  frame.Check();
  RegistrationView view;
  view.primitives = ExtractPrimitives(frame, options.features).primitives;
  view.dense_points = DepthPoints(frame, options.dense_stride_px);
  return view;
}

void TransformView(const Eigen::Isometry3d& new_from_old, RegistrationView* view) {
  const Eigen::Isometry3f transform = new_from_old.cast<float>();
  for (Primitive& primitive : view->primitives) {
    primitive.position = transform * primitive.position;
    primitive.orientation = transform.linear() * primitive.orientation;
  }
  for (Eigen::Vector3f& point : view->dense_points) point = transform * point;
}

RegistrationResult RegisterViews(const RegistrationView& a, const RegistrationView& b,
                                 const RegistrationOptions& options) {
  options.Check();
  RegistrationResult result;
  result.primitives_a = static_cast<int>(a.primitives.size());
  result.primitives_b = static_cast<int>(b.primitives.size());

  auto start = std::chrono::steady_clock::now();
  const Descriptors descriptors_a = ComputeDescriptors(a.primitives, options.descriptors);
  const Descriptors descriptors_b = ComputeDescriptors(b.primitives, options.descriptors);
  result.describe_ms = MillisecondsSince(start);

  start = std::chrono::steady_clock::now();
  std::vector<Correspondence> correspondences;
  if (descriptors_b.values.rows > 0 && descriptors_a.values.rows > 0) {
    const DescriptorMatcher matcher(b.primitives, descriptors_b, options.matching);
    for (const DescriptorMatch& match : matcher.Match(a.primitives, descriptors_a)) {
      correspondences.push_back({match.query, match.train});
    }
  }
  result.correspondences = static_cast<int>(correspondences.size());
  result.match_ms = MillisecondsSince(start);

  start = std::chrono::steady_clock::now();
  result.ransac = EstimatePoseRansac(PrimitivePositions(a.primitives), PrimitivePositions(b.primitives),
                                     correspondences, options.ransac);
  result.ransac_ms = MillisecondsSince(start);
  result.success = result.ransac.success;
  result.b_from_a = result.ransac.scene_from_object;
  if (!result.success || !options.refine) return result;

  start = std::chrono::steady_clock::now();
  IcpOptions icp = options.icp;
  icp.max_correspondence_m = std::max(icp.max_correspondence_m, options.ransac.inlier_threshold_m);
  result.icp = RefinePointToPlane(a.dense_points, b.dense_points, result.b_from_a, icp);
  if (result.icp.success) result.b_from_a = result.icp.scene_from_object;
  result.icp_ms = MillisecondsSince(start);
  return result;
}

}  // namespace ecv
