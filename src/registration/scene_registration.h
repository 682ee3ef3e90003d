#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "core/frame.h"
#include "ecv/descriptor.h"
#include "ecv/matching.h"
#include "ecv/primitives.h"
#include "registration/icp.h"
#include "registration/ransac.h"

namespace ecv {

/// Registration of two views of a scene (paper Sect. IV-B, Fig. 8): ECV primitives and context descriptors
/// of both, nearest-neighbour matches from A to B, the prerejective RANSAC, then point-to-plane ICP.
struct RegistrationOptions {
  EcvOptions features;
  DescriptorOptions descriptors;
  MatchOptions matching;
  RansacOptions ransac = SceneRansacOptions();
  bool refine = true;       ///< ICP on the dense points after RANSAC
  IcpOptions icp;           ///< its correspondence distance is the RANSAC inlier threshold unless set larger
  int dense_stride_px = 4;  ///< dense points for ICP: every n-th pixel in each direction

  /// The paper's RANSAC for scene registration: 10 % of the points of view A must be inliers; with the
  /// adaptive iteration count.
  static RansacOptions SceneRansacOptions();
  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// What registration needs of one view: its primitives and dense points, in its camera frame (metres).
struct RegistrationView {
  std::vector<Primitive> primitives;
  std::vector<Eigen::Vector3f> dense_points;
};

/// The primitives and dense points of a frame.
RegistrationView PrepareRegistrationView(const RgbdFrame& frame, const RegistrationOptions& options = {});

/// Moves a view's primitives (positions and orientations) and dense points by `new_from_old`.
void TransformView(const Eigen::Isometry3d& new_from_old, RegistrationView* view);

struct RegistrationResult {
  bool success = false;                                        ///< RANSAC found a pose with enough inliers
  Eigen::Isometry3d b_from_a = Eigen::Isometry3d::Identity();  ///< maps view A's points into view B's frame
  RansacResult ransac;                                         ///< before refinement
  IcpResult icp;                                               ///< refinement (success false when not run)
  int primitives_a = 0, primitives_b = 0;                      ///< primitives of each view
  int correspondences = 0;                                     ///< descriptor matches fed to RANSAC
  double describe_ms = 0.0, match_ms = 0.0, ransac_ms = 0.0, icp_ms = 0.0;
};

/// Registers view A onto view B.
RegistrationResult RegisterViews(const RegistrationView& a, const RegistrationView& b,
                                 const RegistrationOptions& options = {});

}  // namespace ecv
