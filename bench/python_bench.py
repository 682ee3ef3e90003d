#!/usr/bin/python3
"""The Python module's overhead: wall time of Recognizer.recognize against the time measured inside the C++ call.

    PYTHONPATH=build/python bench/python_bench.py --db LIB [--data ../shared/data] [--runs 2] [--results FILE]

Per frame of the 30 YCB-Video frames (videos 0000-0002), frame by frame: the wall time of recognize() on numpy
arrays (float32 depth in metres, read in place; uint16 depth with depth_scale, converted) and of recognize_frame(),
each minus the recognizer's own "total" for that call. Prints a markdown table and puts it in bench/RESULTS.md
with the date, the machine and the command.
"""

import argparse
import pathlib
import statistics
import sys
import time

import numpy as np

import ecvpose
from bench_util import frame_prefixes, report

HERE = pathlib.Path(__file__).resolve().parent


def timed(recognizer, call):
    start = time.perf_counter()
    call()
    wall_ms = 1000.0 * (time.perf_counter() - start)
    return wall_ms, wall_ms - recognizer.last_timings_ms["total"]


def row(name, values):
    values = sorted(values)
    p90 = values[min(len(values) - 1, int(0.9 * len(values)))]
    return f"| {name} | {statistics.median(values):.2f} | {p90:.2f} | {values[-1]:.2f} |"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--db", required=True, help="model library (e.g. scripts/build_ycbv_library LIB)")
    parser.add_argument("--data", default=str(HERE.parent.parent / "shared" / "data"), help="the shared data folder")
    parser.add_argument("--runs", type=int, default=2, help="passes over the frames (default 2)")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--results", default=str(HERE / "RESULTS.md"))
    args = parser.parse_args()

    library = ecvpose.ModelLibrary.open(args.db)
    recognizer = ecvpose.Recognizer(library, threads=args.threads)
    frames = [ecvpose.load_frame(prefix) for prefix in frame_prefixes(args.data)]
    if len(frames) != 30:
        print(f"python_bench: expected the 30 YCB-Video frames under {args.data}, found {len(frames)}", file=sys.stderr)
        return 1
    depth_units = [np.round(f.depth * 10000.0).astype(np.uint16) for f in frames]
    walls, overheads = [], {"recognize(color, float32 depth, K)": [], "recognize(color, uint16 depth, K, "
                            "depth_scale)": [], "recognize_frame(frame)": []}
    for _ in range(args.runs):
        for frame, units in zip(frames, depth_units):
            wall, extra = timed(recognizer, lambda: recognizer.recognize(frame.color, frame.depth, frame.K))
            walls.append(wall)
            overheads["recognize(color, float32 depth, K)"].append(extra)
            overheads["recognize(color, uint16 depth, K, depth_scale)"].append(
                timed(recognizer, lambda: recognizer.recognize(frame.color, units, frame.K, depth_scale=10000))[1])
            overheads["recognize_frame(frame)"].append(timed(recognizer, lambda: recognizer.recognize_frame(frame))[1])

    lines = [f"Library: {len(library.models)} models (`{args.db}`); {len(frames)} YCB-Video frames x {args.runs} "
             f"runs, {args.threads} thread(s), frame by frame. Overhead = wall time of the Python call - the "
             f"recognizer's own total for it; median recognition wall time {statistics.median(walls):.0f} ms per "
             "frame.", "", "| call | median overhead ms | 90th percentile ms | max ms |", "|---|---:|---:|---:|"]
    lines += [row(name, values) for name, values in overheads.items()]
    report(args.results, "Python module overhead (python_bench.py)", lines)
    return 0


if __name__ == "__main__":
    sys.exit(main())
