#!/usr/bin/env python3
"""Open3D's RANSAC on the correspondences that ransac_bench writes (issue 6, "Benchmarks").

Called by ransac_bench in the same run; not a test. Needs Open3D for the interpreter it runs under:
    apt-get install -y python3-open3d      (Debian 12: Open3D 0.16 for /usr/bin/python3)
Threads: Open3D's RANSAC loop is OpenMP; ransac_bench sets OMP_NUM_THREADS.

    ransac_open3d.py INPUT_DIR OUTPUT_FILE --runs N --iterations K --confidence C
                     [--distance 0.01] [--similarity 0.75]

INPUT_DIR holds a.txt and b.txt (one point "x y z" per line, metres) and correspondences.txt (one "i j"
per line: point i of a matched to point j of b). OUTPUT_FILE gets one line per run (seeds 1..N):
"seed time_ms cpu_ms fitness r11 r12 r13 tx r21 r22 r23 ty r31 r32 r33 tz": wall and process CPU time of
the call, Open3D's fitness and the pose b_from_a (metres).
Exit code 3 when Open3D cannot be imported, 2 for bad usage.
"""

import argparse
import sys
import time


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input_dir")
    parser.add_argument("output_file")
    parser.add_argument("--runs", type=int, default=100)
    parser.add_argument("--iterations", type=int, default=5000)
    parser.add_argument("--confidence", type=float, default=1.0,
                        help="1.0: always all iterations; Open3D's default 0.999 exits early")
    parser.add_argument("--distance", type=float, default=0.01, help="inlier distance, metres")
    parser.add_argument("--similarity", type=float, default=0.75, help="edge-length similarity (1 - t_poly)")
    args = parser.parse_args()
    try:
        import numpy as np
        import open3d as o3d
    except ImportError as error:
        print(f"ransac_open3d.py: {error} (install with: apt-get install -y python3-open3d)", file=sys.stderr)
        return 3

    registration = o3d.pipelines.registration
    source = o3d.geometry.PointCloud(
        o3d.utility.Vector3dVector(np.loadtxt(f"{args.input_dir}/a.txt", ndmin=2)))
    target = o3d.geometry.PointCloud(
        o3d.utility.Vector3dVector(np.loadtxt(f"{args.input_dir}/b.txt", ndmin=2)))
    correspondences = o3d.utility.Vector2iVector(
        np.loadtxt(f"{args.input_dir}/correspondences.txt", dtype=np.int32, ndmin=2))
    checkers = [registration.CorrespondenceCheckerBasedOnEdgeLength(args.similarity)]
    estimation = registration.TransformationEstimationPointToPoint(False)
    criteria = registration.RANSACConvergenceCriteria(args.iterations, args.confidence)
    with open(args.output_file, "w") as output:
        for seed in range(1, args.runs + 1):
            o3d.utility.random.seed(seed)
            start, cpu_start = time.perf_counter(), time.process_time()
            result = registration.registration_ransac_based_on_correspondence(
                source, target, correspondences, args.distance, estimation, 3, checkers, criteria)
            milliseconds = 1000.0 * (time.perf_counter() - start)
            cpu_milliseconds = 1000.0 * (time.process_time() - cpu_start)
            pose = " ".join(f"{v:.9g}" for v in np.asarray(result.transformation)[:3, :].ravel())
            output.write(f"{seed} {milliseconds:.3f} {cpu_milliseconds:.3f} {result.fitness:.6f} {pose}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
