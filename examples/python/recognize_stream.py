#!/usr/bin/python3
"""Recognises the frames of a folder as a camera stream: prints each object's pose and writes a picture per frame.

    PYTHONPATH=build/python examples/python/recognize_stream.py --db lib.sqlite \\
        ../shared/data/ycbv_subset/Example-Scenes/0001 --out out/stream

SEQUENCE is what `ecvpose recognize --sequence` takes: a YCB-Video video folder, a BOP scene folder, a folder of
frame JSONs or a text file with one frame per line. Objects are followed from frame to frame (track=True); every
--search-every-th frame also looks for the models not followed.
"""

import argparse
import pathlib
import sys
import time

import numpy as np

import ecvpose


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sequence", help="folder of frames (or a list file)")
    parser.add_argument("--db", required=True, help="model library, from `ecvpose modeldb build`")
    parser.add_argument("--out", type=pathlib.Path, help="folder for one overlay PNG per frame")
    parser.add_argument("--search-every", type=int, default=3, help="full search every N-th frame (default 3)")
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()

    try:
        library = ecvpose.ModelLibrary.open(args.db)
        recognizer = ecvpose.Recognizer(library, threads=args.threads, track=True, search_every=args.search_every)
        frames = ecvpose.list_frames(args.sequence)
    except ecvpose.InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
    print(f"{len(library.models)} models, {len(frames)} frames")

    for index, spec in enumerate(frames, start=1):
        try:
            frame = ecvpose.load_frame(spec)
        except ecvpose.InputError as error:  # a broken frame: skipped, the stream starts again after it
            print(f"[{index}] skipped: {error}", file=sys.stderr)
            recognizer.reset()
            continue
        start = time.perf_counter()
        detections = recognizer.recognize(frame.color, frame.depth, frame.K)
        wall_ms = 1000.0 * (time.perf_counter() - start)
        print(f"[{index}/{len(frames)}] {frame.name}: {len(detections)} objects, {wall_ms:.0f} ms")
        for detection in detections:
            x, y, z = detection.camera_from_object[:3, 3]
            followed = "followed" if detection.tracked else "searched"
            print(f"  {detection.model:24s} score {detection.score:.2f} at ({x:+.3f}, {y:+.3f}, {z:.3f}) m, {followed}")
        if args.out:
            picture = recognizer.draw(frame.color, frame.depth, frame.K, detections)
            ecvpose.write_image(str(args.out / f"{index:04d}.png"), np.ascontiguousarray(picture))
    return 0


if __name__ == "__main__":
    sys.exit(main())
