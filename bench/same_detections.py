#!/usr/bin/python3
"""Shows that a change to the recognizer keeps its detections: records every detection (model, pose, score) of
`ecvpose recognize` on the 30 YCB-Video frames of ../shared/data (each video a sequence) and the LM-O frame, frame by
frame and with --track --search-every 3, RANSAC seeds 1-3, and compares two such records.

  bench/same_detections.py record OUT_DIR --db YCBV.sqlite --lmo-db LMO.sqlite [--ecvpose PATH] [--seeds 1 2 3]
  bench/same_detections.py compare BEFORE_DIR AFTER_DIR [--tolerance 1e-9]

Libraries: scripts/build_ycbv_library YCBV.sqlite --views 40 --distance 0.9 and
scripts/build_lmo_library LMO.sqlite --views 40 --distance 1.0. `compare` exits 1 on any difference (a detection
missing or added, a pose entry or score off by more than the tolerance) and prints the median time per frame of both.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.environ.get("ECVPOSE_DATA_DIR", os.path.join(ROOT, "..", "shared", "data"))
MODES = {"frames": [], "track3": ["--track", "--search-every", "3"]}


def ycbv_videos():
    scenes = os.path.join(DATA, "ycbv_subset", "Example-Scenes")
    videos = {}
    for video in sorted(os.listdir(scenes)):
        frames = sorted(f[: -len("-color.png")] for f in os.listdir(os.path.join(scenes, video))
                        if f.endswith("-color.png"))
        videos[video] = [os.path.join(scenes, video, f) for f in frames]
    return videos


def run(command):
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit("same_detections: %s failed (exit %d):\n%s" % (" ".join(command), done.returncode, done.stderr))


def record(args):
    os.makedirs(args.out, exist_ok=True)
    lmo_scene = os.path.join(DATA, "lmo_subset", "data", "bop", "lmo", "test", "000002")
    lmo_depth = os.path.join(DATA, "lmo_subset", "SAM-6D", "Data", "Example", "depth.png")
    with tempfile.TemporaryDirectory() as work:
        for seed in args.seeds:
            for mode, flags in MODES.items():
                for video, frames in ycbv_videos().items():
                    listing = os.path.join(work, video + ".txt")
                    with open(listing, "w") as out:
                        out.write("\n".join(frames) + "\n")
                    out_json = os.path.join(args.out, "ycbv_%s_%s_seed%d.jsonl" % (video, mode, seed))
                    run([args.ecvpose, "recognize", "--db", args.db, "--sequence", listing, "--seed", str(seed),
                         "--threads", str(args.threads), "--out-json", out_json] + flags)
                    print("recorded", out_json, flush=True)
            out_json = os.path.join(args.out, "lmo_seed%d.json" % seed)
            run([args.ecvpose, "recognize", "--db", args.lmo_db, lmo_scene + ":3", "--depth", lmo_depth, "--seed",
                 str(seed), "--threads", str(args.threads), "--out-json", out_json])
            print("recorded", out_json, flush=True)


def load(path):
    """The frames of a record file: one JSON object per line (a sequence) or one object (a single frame)."""
    with open(path) as f:
        text = f.read()
    if path.endswith(".jsonl"):
        return [json.loads(line) for line in text.splitlines() if line.strip()]
    return [json.loads(text)]


def differences(name, before, after, tolerance):
    found = []
    if len(before) != len(after):
        return ["%s: %d frames against %d" % (name, len(before), len(after))]
    for i, (a, b) in enumerate(zip(before, after)):
        where = "%s frame %d" % (name, i + 1)
        da, db = a.get("detections", []), b.get("detections", [])
        if [d["model"] for d in da] != [d["model"] for d in db]:
            found.append("%s: models %s against %s" % (where, [d["model"] for d in da], [d["model"] for d in db]))
            continue
        for x, y in zip(da, db):
            if abs(x["score"] - y["score"]) > tolerance:
                found.append("%s: %s score %.12f against %.12f" % (where, x["model"], x["score"], y["score"]))
            pose_a = [v for row in x["camera_from_object"] for v in row]
            pose_b = [v for row in y["camera_from_object"] for v in row]
            worst = max(abs(u - v) for u, v in zip(pose_a, pose_b))
            if worst > tolerance:
                found.append("%s: %s pose differs by %.3g" % (where, x["model"], worst))
            if x.get("tracked") != y.get("tracked"):
                found.append("%s: %s tracked %s against %s" % (where, x["model"], x.get("tracked"), y.get("tracked")))
    return found


def frame_times(frames):
    return [f["timings_ms"]["total"] for f in frames if "timings_ms" in f]


def compare(args):
    names = sorted(f for f in os.listdir(args.before) if f.endswith((".json", ".jsonl")))
    if not names:
        sys.exit("same_detections: no records in %s" % args.before)
    problems, detections = [], 0
    times = {"before": {}, "after": {}}
    for name in names:
        after_path = os.path.join(args.after, name)
        if not os.path.exists(after_path):
            problems.append("%s: missing in %s" % (name, args.after))
            continue
        before, after = load(os.path.join(args.before, name)), load(after_path)
        problems += differences(name, before, after, args.tolerance)
        detections += sum(len(f.get("detections", [])) for f in before)
        mode = "lmo" if name.startswith("lmo") else name.split("_")[2]
        times["before"].setdefault(mode, []).extend(frame_times(before))
        times["after"].setdefault(mode, []).extend(frame_times(after))
    for line in problems:
        print(line)
    print("%d records, %d detections compared: %s" % (len(names), detections,
                                                       "%d differences" % len(problems) if problems else "identical"))
    for mode in sorted(times["before"]):
        print("median ms per frame, %s: %.0f before, %.0f after" %
              (mode, statistics.median(times["before"][mode]), statistics.median(times["after"][mode])))
    return 1 if problems else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="command", required=True)
    rec = commands.add_parser("record")
    rec.add_argument("out")
    rec.add_argument("--db", required=True)
    rec.add_argument("--lmo-db", required=True)
    rec.add_argument("--ecvpose", default=os.path.join(ROOT, "build", "app", "ecvpose"))
    rec.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    rec.add_argument("--threads", type=int, default=2)
    cmp = commands.add_parser("compare")
    cmp.add_argument("before")
    cmp.add_argument("after")
    cmp.add_argument("--tolerance", type=float, default=1e-9)
    args = parser.parse_args()
    if args.command == "record":
        record(args)
        return 0
    return compare(args)


if __name__ == "__main__":
    sys.exit(main())
