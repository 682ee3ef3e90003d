#!/usr/bin/env python3
"""Open3D's global registration recipe on one RGB-D frame, every model (issue 9, the peer it names).

Called by recognize_bench once per frame; not a test. Needs Open3D for the interpreter it runs under:
    apt-get install -y python3-open3d      (Debian 12: Open3D 0.16 for /usr/bin/python3)
Threads: Open3D's feature RANSAC is OpenMP; recognize_bench sets OMP_NUM_THREADS.

    recognition_open3d.py INPUT_DIR OUTPUT_FILE [--voxel 0.005] [--normal-radius 0.01] [--fpfh-radius 0.025]
                          [--iterations 100000] [--confidence 0.999] [--distance 0.01] [--similarity 0.9]
                          [--icp-iterations 30] [--seed 1]

INPUT_DIR holds camera.txt ("width height fx fy cx cy"), depth.bin (height x width float32, metres, 0 where
there is none) and, per model K = 0, 1, ..., model_K.bin (N x 6 float32: a point on the mesh surface in the
object frame, metres, and that surface's outward normal).
The recipe, per frame: the depth image to a point cloud, a voxel grid, normals (turned to the camera) and FPFH;
per model (its voxelised points, normals estimated and turned to agree with the mesh's, FPFH; not timed):
registration_ransac_based_on_feature_matching (3 points, edge-length and distance checkers), then point-to-plane
ICP from its pose.
OUTPUT_FILE gets "scene_ms scene_points" and then one line per model, in input order: "time_ms fitness r11 r12 r13
tx r21 r22 r23 ty r31 r32 r33 tz": the wall time of its RANSAC and ICP, Open3D's ICP fitness and the pose
camera_from_object (metres). The frame's time is scene_ms plus the models' times.
Exit code 3 when Open3D cannot be imported, 2 for bad usage or input.
"""

import argparse
import os
import sys
import time


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input_dir")
    parser.add_argument("output_file")
    parser.add_argument("--voxel", type=float, default=0.005, help="voxel grid, metres")
    parser.add_argument("--normal-radius", type=float, default=0.01, help="metres")
    parser.add_argument("--fpfh-radius", type=float, default=0.025, help="metres")
    parser.add_argument("--iterations", type=int, default=100000, help="RANSAC iterations at most")
    parser.add_argument("--confidence", type=float, default=0.999, help="RANSAC early exit")
    parser.add_argument("--distance", type=float, default=0.01, help="inlier and ICP distance, metres")
    parser.add_argument("--similarity", type=float, default=0.9, help="edge-length similarity")
    parser.add_argument("--icp-iterations", type=int, default=30)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    try:
        import numpy as np
        import open3d as o3d
    except ImportError as error:
        print(f"recognition_open3d.py: {error} (install with: apt-get install -y python3-open3d)", file=sys.stderr)
        return 3

    registration = o3d.pipelines.registration
    camera_path = os.path.join(args.input_dir, "camera.txt")
    fields = np.loadtxt(camera_path, ndmin=1)
    if fields.size != 6:
        print(f"recognition_open3d.py: {camera_path}: expected 'width height fx fy cx cy'", file=sys.stderr)
        return 2
    width, height = int(fields[0]), int(fields[1])
    depth = np.fromfile(os.path.join(args.input_dir, "depth.bin"), dtype=np.float32)
    if depth.size != width * height:
        print(f"recognition_open3d.py: depth.bin: expected {width} x {height} floats, got {depth.size}",
              file=sys.stderr)
        return 2
    intrinsic = o3d.camera.PinholeCameraIntrinsic(width, height, *fields[2:6])

    def features(cloud):
        return registration.compute_fpfh_feature(
            cloud, o3d.geometry.KDTreeSearchParamHybrid(radius=args.fpfh_radius, max_nn=100))

    def normals(cloud):
        cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=args.normal_radius, max_nn=30))

    models = []
    k = 0
    while os.path.exists(os.path.join(args.input_dir, f"model_{k}.bin")):
        data = np.fromfile(os.path.join(args.input_dir, f"model_{k}.bin"), dtype=np.float32).reshape(-1, 6)
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(data[:, :3].astype(np.float64)))
        cloud.normals = o3d.utility.Vector3dVector(data[:, 3:].astype(np.float64))
        cloud = cloud.voxel_down_sample(args.voxel)
        mesh_normals = np.asarray(cloud.normals).copy()
        normals(cloud)
        estimated = np.asarray(cloud.normals)
        flip = np.sum(estimated * mesh_normals, axis=1) < 0.0
        estimated[flip] *= -1.0
        cloud.normals = o3d.utility.Vector3dVector(estimated)
        models.append((cloud, features(cloud)))
        k += 1

    start = time.perf_counter()
    image = o3d.geometry.Image(depth.reshape(height, width))
    scene = o3d.geometry.PointCloud.create_from_depth_image(image, intrinsic, depth_scale=1.0, depth_trunc=1e6)
    scene = scene.voxel_down_sample(args.voxel)
    normals(scene)
    scene.orient_normals_towards_camera_location()
    scene_features = features(scene)
    scene_ms = 1000.0 * (time.perf_counter() - start)

    checkers = [registration.CorrespondenceCheckerBasedOnEdgeLength(args.similarity),
                registration.CorrespondenceCheckerBasedOnDistance(args.distance)]
    criteria = registration.RANSACConvergenceCriteria(args.iterations, args.confidence)
    lines = [f"{scene_ms:.3f} {len(scene.points)}"]
    for cloud, cloud_features in models:
        o3d.utility.random.seed(args.seed)
        start = time.perf_counter()
        coarse = registration.registration_ransac_based_on_feature_matching(
            cloud, scene, cloud_features, scene_features, False, args.distance,
            registration.TransformationEstimationPointToPoint(False), 3, checkers, criteria)
        fine = registration.registration_icp(
            cloud, scene, args.distance, coarse.transformation, registration.TransformationEstimationPointToPlane(),
            registration.ICPConvergenceCriteria(max_iteration=args.icp_iterations))
        milliseconds = 1000.0 * (time.perf_counter() - start)
        pose = " ".join(f"{v:.9g}" for v in np.asarray(fine.transformation)[:3, :].ravel())
        lines.append(f"{milliseconds:.3f} {fine.fitness:.6f} {pose}")
    with open(args.output_file, "w") as output:
        output.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
