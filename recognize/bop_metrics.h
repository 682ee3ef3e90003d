#pragma once

// The pose errors and recall of the BOP challenge (Hodaň et al., "BOP Challenge 2020 on 6D Object Localization",
// ECCVW 2020): VSD, MSSD and MSPD, each turned into an average recall over BOP's thresholds, and AR their mean.

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/camera.h"

namespace ecv {

/// The object's symmetry transformations in its own frame, as BOP uses them for MSSD and MSPD: the identity, each of
/// `symmetries_discrete` (4x4, row-major, translation in the unit of the entry), and each continuous symmetry
/// (`axis`, `offset`) turned in steps of at most `max_step_rad` (BOP: the step that moves a point at the diameter's end
/// by 1 % of the diameter, 0.01 rad; 315 steps a turn), combined with every discrete one. `unit_to_m` converts the
/// entry's translations (BOP's models_info.json: millimetres, 0.001). Throws InputError naming `source` and the field.
std::vector<Eigen::Isometry3d> BopSymmetries(const nlohmann::json& model_info, double unit_to_m,
                                             const std::string& source, double max_step_rad = 0.01);

/// Maximum symmetry-aware surface distance: min over `symmetries` S of max over `points` x of
/// |estimate x - truth S x|, metres (points in the object frame, metres; BOP uses the mesh's vertices).
double Mssd(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& estimate,
            const Eigen::Isometry3d& truth, const std::vector<Eigen::Isometry3d>& symmetries);

/// Maximum symmetry-aware projection distance: the same as Mssd with the points' pixels in `camera`, pixels.
double Mspd(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& estimate,
            const Eigen::Isometry3d& truth, const std::vector<Eigen::Isometry3d>& symmetries,
            const PinholeCamera& camera);

/// Visible surface discrepancy for each misalignment tolerance of `taus_m`: from the model's depth rendered at the
/// estimate and at the truth and the test image's depth (CV_32F metres, 0 = none, all of `camera`'s size), the
/// visible parts of the two renderings (a pixel of a rendering is visible where it lies at most `delta_m` behind the
/// test surface or the test image has no depth; the estimate's is also visible where the truth's is), and the share
/// of their union not in both or with distances from the camera centre differing by tau or more. 1 when neither is
/// visible. BOP: delta 15 mm, tau 5 % to 50 % of the diameter.
std::vector<double> Vsd(const cv::Mat& depth_estimate, const cv::Mat& depth_truth, const cv::Mat& depth_test,
                        const PinholeCamera& camera, double delta_m, const std::vector<double>& taus_m);

/// BOP's thresholds: VSD's taus and correctness thresholds and MSSD's, as fractions of the diameter (0.05 to 0.5 in
/// steps of 0.05), and MSPD's in pixels for an image of `width` (5 to 50 in steps of 5, times width / 640).
std::vector<double> BopFractions();
std::vector<double> BopMspdThresholdsPx(int width);

/// The errors of one estimate against one ground-truth instance.
struct BopPoseErrors {
  std::vector<double> vsd;  ///< one per tau of BopFractions() x diameter
  double mssd_m = 0.0;
  double mspd_px = 0.0;
};

/// One object in one image: the errors of its estimates against its ground-truth instances, as BOP matches them.
struct BopObjectErrors {
  double diameter_m = 0.0;
  int instances = 0;  ///< ground-truth instances (those BOP counts: at least 10 % visible)
  /// [estimate][instance]: the estimates best score first, at most as many as the task's target count.
  std::vector<std::vector<BopPoseErrors>> errors;
};

/// Average recalls, each the mean over BOP's thresholds of the share of ground-truth instances matched at that
/// threshold; ar = the mean of the three. VSD's is over taus x correctness thresholds.
struct BopRecall {
  double ar_vsd = 0.0;
  double ar_mssd = 0.0;
  double ar_mspd = 0.0;
  double ar = 0.0;
  int instances = 0;
};

/// BopRecall over objects in images of `width` pixels. At each threshold the estimates of an object, best score
/// first, each take the unmatched instance with the smallest error below the threshold (BOP's greedy matching).
BopRecall AverageRecall(const std::vector<BopObjectErrors>& objects, int width);

}  // namespace ecv
