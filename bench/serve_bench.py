#!/usr/bin/python3
"""`ecvpose serve` against one-shot `ecvpose recognize` per frame: what keeping the library loaded saves.

    bench/serve_bench.py --db LIB [--cli build/app/ecvpose] [--data ../shared/data] [--results FILE]

Over the 30 YCB-Video frames (videos 0000-0002), frame by frame, one thread: the wall time of a one-shot
`recognize` process per frame (library and meshes loaded each time), and of each request answered by one `serve`
process (its first answer counted from the process's start). Both give the same detections (checked). Prints a
markdown table and puts it in bench/RESULTS.md with the date, the machine and the command, in place of the
previous run's section.
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from bench_util import frame_prefixes, report  # noqa: E402


def one_shot(cli, db, frame, out):
    start = time.perf_counter()
    subprocess.run([cli, "recognize", "--db", db, frame, "--threads", "1", "--out-json", out], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return 1000.0 * (time.perf_counter() - start), json.load(open(out, encoding="utf-8"))["detections"]


def served(cli, db, frames):
    start = time.perf_counter()
    process = subprocess.Popen([cli, "serve", "--db", db, "--threads", "1"], stdin=subprocess.PIPE,
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    times, answers = [], []
    for frame in frames:
        process.stdin.write(json.dumps({"frame": frame}) + "\n")
        process.stdin.flush()
        answers.append(json.loads(process.stdout.readline())["detections"])
        now = time.perf_counter()
        times.append(1000.0 * (now - start))
        start = now
    process.stdin.close()
    process.wait()
    return times, answers


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--db", required=True)
    parser.add_argument("--cli", default=str(HERE.parent / "build" / "app" / "ecvpose"))
    parser.add_argument("--data", default=str(HERE.parent.parent / "shared" / "data"))
    parser.add_argument("--results", default=str(HERE / "RESULTS.md"))
    args = parser.parse_args()
    frames = frame_prefixes(args.data)
    with tempfile.TemporaryDirectory() as work:
        shots = [one_shot(args.cli, args.db, frame, os.path.join(work, "d.json")) for frame in frames]
    serve_times, serve_answers = served(args.cli, args.db, frames)
    same = sum(answer == shot[1] for answer, shot in zip(serve_answers, shots))
    shot_times = [shot[0] for shot in shots]
    lines = [f"Library `{args.db}`; {len(frames)} YCB-Video frames, frame by frame, 1 thread. Wall time per frame "
             f"as the caller sees it; the same detections from both on {same} of {len(frames)} frames.", "",
             "| | first frame ms | median ms per frame after it | total s |", "|---|---:|---:|---:|",
             f"| one-shot `recognize` per frame | {shot_times[0]:.0f} | {statistics.median(shot_times[1:]):.0f} | "
             f"{sum(shot_times) / 1000:.1f} |",
             f"| one `serve` process | {serve_times[0]:.0f} | {statistics.median(serve_times[1:]):.0f} | "
             f"{sum(serve_times) / 1000:.1f} |"]
    report(args.results, "serve against one-shot recognize (serve_bench.py)", lines)
    return 0 if same == len(frames) else 1


if __name__ == "__main__":
    sys.exit(main())
