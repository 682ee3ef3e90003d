// `ecvpose register FRAME_A FRAME_B`: aligns two views of a scene (the paper's Fig. 8) and reports b_from_a.

#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/pose.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "registration/registration_draw.h"
#include "registration/scene_registration.h"

namespace ecv::app {
namespace {

struct RegisterArgs {
  FrameSpec frame_a, frame_b;
  RegistrationOptions options;
  bool no_icp = false;
  std::string out_json;
  std::string overlay;
};

nlohmann::json ResultJson(const RegistrationResult& result) {
  return {{"success", result.success},
          {"b_from_a", PoseToJson(result.b_from_a)},
          {"inlier_fraction", result.ransac.inlier_fraction},
          {"fit_error", result.ransac.fit_error_m},
          {"icp_rmse", result.icp.success ? result.icp.rmse_m : 0.0},
          {"primitives_a", result.primitives_a},
          {"primitives_b", result.primitives_b},
          {"correspondences", result.correspondences},
          {"iterations", result.ransac.iterations},
          {"rejected_by_polygon", result.ransac.rejected_by_polygon},
          {"timings_ms",
           {{"describe", result.describe_ms},
            {"match", result.match_ms},
            {"ransac", result.ransac_ms},
            {"icp", result.icp_ms}}}};
}

int RunRegister(RegisterArgs& args) {
  args.options.refine = !args.no_icp;
  args.options.Check();
  const LoadedFrame a = app::LoadFrameWithWarnings(args.frame_a), b = app::LoadFrameWithWarnings(args.frame_b);
  const auto start = std::chrono::steady_clock::now();
  const RegistrationView view_a = PrepareRegistrationView(a.rgbd, args.options);
  const RegistrationView view_b = PrepareRegistrationView(b.rgbd, args.options);
  const double extract_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const RegistrationResult result = RegisterViews(view_a, view_b, args.options);

  std::cout << std::fixed << std::setprecision(1) << "A " << a.rgbd.name << ": " << result.primitives_a
            << " primitives\nB " << b.rgbd.name << ": " << result.primitives_b << " primitives\n"
            << result.correspondences << " correspondences, " << result.ransac.iterations << " RANSAC iterations ("
            << result.ransac.rejected_by_polygon << " rejected by the polygon test)\n";
  if (result.success) {
    const Eigen::Isometry3d& pose = result.b_from_a;
    std::cout << "b_from_a: rotation " << RotationAngle(Eigen::Isometry3d::Identity(), pose) * 180.0 / M_PI
              << " deg, translation " << pose.translation().norm() * 1000.0 << " mm; inliers "
              << 100.0 * result.ransac.inlier_fraction << " % of A's primitives, fit error "
              << result.ransac.fit_error_m * 1000.0 << " mm";
    if (result.icp.success) std::cout << ", ICP rmse " << result.icp.rmse_m * 1000.0 << " mm";
    std::cout << '\n' << std::setprecision(6) << pose.matrix() << '\n';
  } else {
    std::cout << "no registration found (need " << 100.0 * args.options.ransac.required_inlier_fraction
              << " % of A's primitives as inliers)\n";
  }
  std::cout << std::setprecision(1) << "time: extract " << extract_ms << " ms, describe " << result.describe_ms
            << " ms, match " << result.match_ms << " ms, RANSAC " << result.ransac_ms << " ms, ICP " << result.icp_ms
            << " ms\n";
  if (!args.out_json.empty()) {
    nlohmann::json json = ResultJson(result);
    json["timings_ms"]["extract"] = extract_ms;
    WriteJsonFile(args.out_json, json);
  }
  if (!args.overlay.empty()) {
    WriteColorImage(args.overlay,
                    DrawAlignedFrame(a.rgbd, b.rgbd, result.success ? result.b_from_a : Eigen::Isometry3d::Identity()));
  }
  return kExitOk;
}

}  // namespace

CommandAction SetupRegisterCommand(CLI::App& command) {
  auto args = std::make_shared<RegisterArgs>();
  const char* frame_help = "Frame JSON, YCB-Video prefix, BOP SCENE_DIR:IMAGE_ID or organized .pcd";
  command.add_option("FRAME_A", args->frame_a.positional, frame_help)->required();
  command.add_option("FRAME_B", args->frame_b.positional, frame_help)->required();
  command.add_option("--out-json", args->out_json, "Result as JSON: b_from_a (4x4, metres), inliers, timings");
  command.add_option("--overlay", args->overlay, "Picture: frame A aligned onto frame B in red (PNG)");
  RansacOptions& ransac = args->options.ransac;
  command.add_option("--inlier-fraction", ransac.required_inlier_fraction, "Of A's primitives that must be inliers")
      ->capture_default_str()
      ->group("RANSAC");
  command.add_option("--iterations", ransac.max_iterations, "RANSAC iterations; 0: from p, w and n (about 37 000)")
      ->capture_default_str()
      ->group("RANSAC");
  command.add_option("--seed", ransac.seed, "Random seed")->capture_default_str()->group("RANSAC");
  command.add_option("--threads", ransac.threads, "RANSAC threads (same result for any count)")
      ->capture_default_str()
      ->check(ThreadCount())
      ->group("RANSAC");
  command.add_flag("--no-icp", args->no_icp, "Skip the point-to-plane ICP refinement")->group("RANSAC");
  command.footer(
      "b_from_a maps frame A's camera points into frame B's camera frame. Example:\n"
      "  ecvpose register ../shared/data/ycbv_subset/Example-Scenes/0001/000001 "
      "../shared/data/ycbv_subset/Example-Scenes/0001/000019 --out-json b_from_a.json --overlay a_on_b.png");
  return [args] { return RunRegister(*args); };
}

}  // namespace ecv::app
