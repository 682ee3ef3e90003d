#!/usr/bin/python3
"""Stream latency at camera rate: each YCB-Video video looped and fed frame by frame, on time, to `ecvpose recognize
--sequence DIR --follow` (frame JSONs written into DIR) and to `ecvpose serve` (tracked requests on its standard input).

    bench/stream_bench.py --db LIB [--seconds 60] [--fps 30] [--config NAME="FLAGS"]... [--videos 0000 0001 0002]
        [--runs follow serve] [--frames-limit N] [--drain 10] [--cli build/app/ecvpose] [--results FILE]

Each configuration's FLAGS go to both commands (default: "track" = --track, "search every 3" = --track
--search-every 3, "search beside" = --track --search-beside); `recognize` also gets --follow --track --out-json -,
and every serve request "track": true. Latency
of a frame: `recognize`, from its frame JSON appearing (renamed into DIR) to its result line on standard output;
`serve`, from the time its request was due to its answer. Frames wait in turn when the recognizer is slower than the
camera, and the wait counts. Feeding stops after --seconds (or --frames-limit frames); frames not answered --drain
seconds later count with the time they had waited, and a percentile they may change is printed "≥". Prints a markdown
table per configuration, run and video and puts it in bench/RESULTS.md with the date, the machine and the command.
"""

import argparse
import collections
import ctypes
import fcntl
import json
import math
import os
import pathlib
import shlex
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from bench_util import report  # noqa: E402

TITLE = "Stream latency at camera rate: recognize --follow and serve (stream_bench.py)"
DEFAULT_CONFIGS = [("track", "--track"), ("search every 3", "--track --search-every 3"),
                   ("search beside", "--track --search-beside")]
SEARCH_STAGES = ("rank", "ransac", "point_pairs")  # timings_ms keys of a frame in which models were searched
YCBV_DEPTH_SCALE = 10000  # depth PNG units per metre of YCB-Video (checked against its meta files below)
START_TIMEOUT_S = 300  # for a library and its meshes to load
STOP_TIMEOUT_S = 30  # for the frame in hand to finish after SIGTERM
RUNS = {"follow": "`recognize --follow`", "serve": "`serve`"}


class BenchError(Exception):
    """A failure that ends the bench with a message (exit 1)."""


def die_on_signal(number, _frame):
    raise KeyboardInterrupt(f"signal {number}")


PRCTL = ctypes.CDLL(None, use_errno=True).prctl


def parent_death_signal():
    """In the child before exec: SIGKILL when the bench dies, even by SIGKILL (Linux prctl PR_SET_PDEATHSIG)."""
    PRCTL(1, signal.SIGKILL)


class Child:
    """An ecvpose process: standard error read on a thread (its last lines kept; `ready` set when a line holds
    `ready_text`), standard output left to the caller; stopped when its `with` block ends. Only started while no
    other thread of the bench runs (preexec_fn)."""

    def __init__(self, command, ready_text, stdin=subprocess.DEVNULL):
        self.command = command
        self.tail = collections.deque(maxlen=30)
        self.info = []  # the lines before ready
        self.ready = threading.Event()
        self.process = subprocess.Popen(command, stdin=stdin, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        preexec_fn=parent_death_signal)
        self._ready_text = ready_text
        self._reader = threading.Thread(target=self._read_stderr, daemon=True)
        self._reader.start()

    def __enter__(self):
        return self

    def __exit__(self, *_):
        self.stop()

    def _read_stderr(self):
        for raw in iter(self.process.stderr.readline, b""):
            line = raw.decode("utf-8", "replace").rstrip("\n")
            self.tail.append(line)
            if not self.ready.is_set():
                self.info.append(line)
                if self._ready_text in line:
                    self.ready.set()

    def wait_ready(self):
        deadline = time.perf_counter() + START_TIMEOUT_S
        while not self.ready.wait(0.1):
            if self.process.poll() is not None or time.perf_counter() > deadline:
                self._reader.join(1)
                raise BenchError(self.failure("did not get ready"))

    def failure(self, what):
        code = self.process.poll()
        state = f"exit code {code}" if code is not None else "still running"
        return f"{shlex.join(self.command)}: {what} ({state}); its last messages:\n  " + "\n  ".join(self.tail)

    def stop(self):
        """SIGTERM (the frame in hand is finished), then SIGKILL after STOP_TIMEOUT_S."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        for stream in (self.process.stdin, self.process.stdout):
            if stream is not None:
                try:
                    stream.close()
                except OSError:
                    pass
        self._reader.join(5)


def ycbv_camera(cli, prefix):
    """[fx, fy, cx, cy] of a YCB-Video frame and its median depth, as `ecvpose info` reads them."""
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        done = subprocess.run([cli, "info", prefix, "--out-json", out.name], stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True)
        if done.returncode != 0:
            raise BenchError(f"ecvpose info {prefix} failed (exit {done.returncode}): {done.stderr.strip()}")
        with open(out.name, encoding="utf-8") as info:
            item = json.load(info)["items"][0]
    return item["camera"], item["depth_median_m"]


def frame_json_text(prefix, camera):
    """A frame JSON of a YCB-Video frame (absolute image paths)."""
    return json.dumps({"color": os.path.abspath(prefix + "-color.png"),
                       "depth": os.path.abspath(prefix + "-depth.png"), "depth_scale": YCBV_DEPTH_SCALE,
                       "camera": camera}) + "\n"


def video_sources(cli, data, video, folder):
    """The frame JSONs (text, path under `folder`) of a video's frames, in order; checked to read as the YCB-Video
    prefix does (same camera, same median depth)."""
    scenes = pathlib.Path(data) / "ycbv_subset" / "Example-Scenes" / video
    prefixes = sorted(str(p)[: -len("-color.png")] for p in scenes.glob("*-color.png"))
    if not prefixes:
        raise BenchError(f"no frames *-color.png in {scenes}")
    camera, depth = ycbv_camera(cli, prefixes[0])
    sources = []
    for prefix in prefixes:
        path = os.path.join(folder, f"{video}_{os.path.basename(prefix)}.json")
        text = frame_json_text(prefix, camera)
        with open(path, "w", encoding="utf-8") as out:
            out.write(text)
        sources.append((text, path))
    json_camera, json_depth = ycbv_camera(cli, sources[0][1])
    if json_camera != camera or abs(json_depth - depth) > 1e-6:
        raise BenchError(f"the frame JSON of {prefixes[0]} does not read as the frame itself (camera {json_camera} "
                         f"against {camera}, median depth {json_depth} against {depth} m)")
    return sources


def recognize_command(args, folder, flags, idle_timeout):
    return [args.cli, "recognize", "--db", args.db, "--sequence", folder, "--follow", "--idle-timeout",
            str(idle_timeout), "--track", "--out-json", "-"] + flags


def serve_command(args, flags):
    return [args.cli, "serve", "--db", args.db] + flags


def check_configs(args, configs, work):
    """Each configuration's flags through each command to run: refused flags end the bench (exit 2)."""
    empty = os.path.join(work, "empty")
    os.makedirs(empty, exist_ok=True)
    for name, flags in configs:
        commands = {"follow": recognize_command(args, empty, flags, 0), "serve": serve_command(args, flags)}
        for run in args.runs:
            done = subprocess.run(commands[run], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.PIPE, text=True, preexec_fn=parent_death_signal)
            if done.returncode != 0:
                message = done.stderr.strip().replace("\n", "\n  ")
                print(f"stream_bench: configuration '{name}' ({shlex.join(flags)}): {shlex.join(commands[run])} "
                      f"exited {done.returncode}:\n  {message}", file=sys.stderr)
                sys.exit(2)


class Stream:
    """Frames fed at a fixed rate on a thread (`send(i, due)` returns the time frame i counts from), answers read from
    the child's standard output on another (`index(answer)` names the frame an answer line is for)."""

    def __init__(self, child, count, fps, send, index):
        self.child, self.count, self.fps, self.send, self.index = child, count, fps, send, index
        self.origin = None  # when frame 0 was due
        self.start = [None] * count  # the time each frame counts from (None: never sent)
        self.late = [0.0] * count  # how late each frame was fed (s)
        self.answers = {}  # frame -> (time, answer)
        self.skipped = set()  # frames passed over for a newer one (recognize --latest)
        self.stopped_at = None
        self.ended = False  # standard output closed
        self.problem = None  # what went wrong feeding or reading
        self.lock = threading.Condition()
        self.stopping = threading.Event()  # feed no more

    def counts_from(self, i):
        return self.start[i] if self.start[i] is not None else self.origin + i / self.fps

    def _fail(self, problem):
        with self.lock:
            if self.stopped_at is None and self.problem is None:
                self.problem = problem
            self.lock.notify()

    def _feed(self):
        for i in range(self.count):
            due = self.origin + i / self.fps
            if self.stopping.wait(max(0.0, due - time.perf_counter())):
                return
            try:
                start = self.send(i, due)
            except (OSError, ValueError) as error:  # ValueError: the child's input closed after it was stopped
                self._fail(f"feeding frame {i}: {error}")
                return
            with self.lock:
                self.start[i] = start
                self.late[i] = time.perf_counter() - due

    def _read(self):
        for raw in iter(self.child.process.stdout.readline, b""):
            now = time.perf_counter()
            try:
                answer = json.loads(raw)
                frame = self.index(answer)
            except (ValueError, KeyError, TypeError) as error:
                self._fail(f"an answer line that names no frame fed ({error}): {raw[:200]!r}")
                continue
            with self.lock:
                if self.stopped_at is None:
                    self.answers[frame] = (now, answer)
                    self.skipped.update(range(frame - answer.get("skipped_before", 0), frame))
                    self.lock.notify()
        with self.lock:
            self.ended = True
            self.lock.notify()

    def run(self, drain):
        """Feeds every frame, waits until all are answered or `drain` s after the last one was due; then stops the
        child."""
        reader = threading.Thread(target=self._read, daemon=True)
        reader.start()
        self.origin = time.perf_counter()
        feeder = threading.Thread(target=self._feed, daemon=True)
        feeder.start()
        deadline = self.origin + (self.count - 1) / self.fps + drain
        with self.lock:
            while (len(self.answers) + len(self.skipped) < self.count and not self.ended and self.problem is None
                   and time.perf_counter() < deadline):
                self.lock.wait(0.1)
            self.stopped_at = time.perf_counter()
            self.stopping.set()
            problem = self.problem
            if problem is None and self.ended and len(self.answers) + len(self.skipped) < self.count:
                problem = f"ended after {len(self.answers)} of {self.count} answers"
        self.child.stop()
        feeder.join()
        reader.join(5)
        if problem is not None:
            raise BenchError(self.child.failure(problem))
        return self


def run_follow(args, flags, sources, count, work):
    """`recognize --follow` fed frame JSONs (written, then renamed into its folder): the Stream and the child's
    messages before it was ready."""
    folder = tempfile.mkdtemp(prefix="frames-", dir=work)
    paths = [os.path.join(folder, f"{i:07d}.json") for i in range(count)]
    frame_of = {path: i for i, path in enumerate(paths)}

    def send(i, _due):
        partial = paths[i] + ".partial"
        with open(partial, "w", encoding="utf-8") as out:
            out.write(sources[i % len(sources)][0])
        os.rename(partial, paths[i])
        return time.perf_counter()

    with Child(recognize_command(args, folder, flags, args.drain + 10), "descriptors matched by") as child:
        child.wait_ready()
        stream = Stream(child, count, args.fps, send, lambda answer: frame_of[answer["frame"]]).run(args.drain)
    return stream, child.info


def run_serve(args, flags, sources, count):
    """`serve` fed tracked requests on its standard input: the Stream and the child's messages before it was ready."""
    with Child(serve_command(args, flags), "ready", stdin=subprocess.PIPE) as child:
        child.wait_ready()
        try:  # room for every request in the pipe: the client never waits to write
            fcntl.fcntl(child.process.stdin.fileno(), fcntl.F_SETPIPE_SZ, 1 << 20)
        except OSError:
            pass

        def send(i, due):
            request = {"id": i, "frame": sources[i % len(sources)][1], "track": True}
            child.process.stdin.write((json.dumps(request) + "\n").encode())
            child.process.stdin.flush()
            return due

        stream = Stream(child, count, args.fps, send, lambda answer: answer["id"]).run(args.drain)
    return stream, child.info


def percentile(values, p):
    """Nearest-rank percentile of (ms, exact) pairs: its text, "≥ " when a frame not answered may move it."""
    ordered = sorted(values)
    value = ordered[max(0, math.ceil(p / 100 * len(ordered)) - 1)][0]
    unsure = any(not exact and ms <= value for ms, exact in ordered)
    return ("≥ " if unsure else "") + f"{value:.0f}"


def summary(streams):
    """The table cells of one or more streams: fed, answered, p50/95/99, searched, objects, recognizer ms."""
    latencies, totals, searched, objects, fed, errors, skipped = [], [], 0, [], 0, 0, 0
    for stream in streams:
        for i in range(stream.count):
            answered = stream.answers.get(i)
            fed += 1
            if i in stream.skipped:
                skipped += 1
                continue
            if answered is None:
                latencies.append((1000 * (stream.stopped_at - stream.counts_from(i)), False))
                continue
            latencies.append((1000 * (answered[0] - stream.counts_from(i)), True))
            answer = answered[1]
            if "error" in answer:
                errors += 1
                continue
            timings = answer.get("timings_ms", {})
            totals.append(timings.get("total", 0.0))
            searched += any(stage in timings for stage in SEARCH_STAGES) or "searched_frames_ago" in answer
            objects.append(len(answer.get("detections", [])))
    answered = len(totals) + errors
    cells = [str(fed), str(answered) + (f" ({errors} errors)" if errors else "") +
             (f" ({skipped} skipped)" if skipped else "")]
    cells += [percentile(latencies, p) for p in (50, 95, 99)]
    cells += [f"{100 * searched / len(totals):.0f} %" if totals else "-",
              f"{statistics.mean(objects):.2f}" if objects else "-",
              f"{statistics.median(totals):.0f}" if totals else "-"]
    return cells, errors


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--db", required=True, help="model library (e.g. scripts/build_ycbv_library LIB)")
    parser.add_argument("--seconds", type=float, default=60.0, help="feeding time per video and run (default 60)")
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second fed (default 30)")
    parser.add_argument("--config", action="append", metavar='NAME="FLAGS"',
                        help="a configuration: its name and the flags given to both commands; repeatable (default: "
                             + ", ".join(f'{n}="{f}"' for n, f in DEFAULT_CONFIGS) + ")")
    parser.add_argument("--videos", nargs="+", default=["0000", "0001", "0002"], help="YCB-Video videos (default all)")
    parser.add_argument("--runs", nargs="+", choices=list(RUNS), default=list(RUNS),
                        help="follow (recognize --follow), serve, or both (default)")
    parser.add_argument("--frames-limit", type=int, default=0,
                        help="at most N frames per video and run, for a short check (default 0: --seconds x --fps)")
    parser.add_argument("--drain", type=float, default=10.0,
                        help="seconds to wait for answers after the last frame was due (default 10)")
    parser.add_argument("--cli", default=str(HERE.parent / "build" / "app" / "ecvpose"), help="ecvpose")
    parser.add_argument("--data", default=os.environ.get("ECVPOSE_DATA_DIR", str(HERE.parent.parent / "shared" /
                                                                                 "data")), help="the shared data")
    parser.add_argument("--results", default=str(HERE / "RESULTS.md"), help="markdown file whose section is replaced")
    args = parser.parse_args()
    if not (args.seconds > 0 and args.fps > 0 and args.drain >= 0 and args.frames_limit >= 0):
        parser.error("--seconds and --fps must be > 0, --drain and --frames-limit >= 0")
    if not os.path.isfile(args.db):
        parser.error(f"--db {args.db}: no such file")
    if not os.access(args.cli, os.X_OK):
        parser.error(f"--cli {args.cli}: not an executable (build ecvpose, or give --cli)")
    configs = []
    for text in args.config or [f"{n}={f}" for n, f in DEFAULT_CONFIGS]:
        name, equals, flags = text.partition("=")
        if not equals or not name.strip():
            parser.error(f'--config {text!r}: expected NAME="FLAGS"')
        try:
            configs.append((name.strip(), shlex.split(flags)))
        except ValueError as error:
            parser.error(f"--config {text!r}: {error}")
    if len({name for name, _ in configs}) != len(configs):
        parser.error("--config: two configurations of one name")
    for video in args.videos:
        if not (pathlib.Path(args.data) / "ycbv_subset" / "Example-Scenes" / video).is_dir():
            parser.error(f"--videos {video}: no such video under {args.data}/ycbv_subset/Example-Scenes")
    args.runs = list(dict.fromkeys(args.runs))
    args.frames = max(1, round(args.seconds * args.fps))
    if args.frames_limit:
        args.frames = min(args.frames, args.frames_limit)
    return args, configs


def measure(args, configs, work):
    """Every configuration, run and video in turn: the table rows and the notes' figures."""
    rows, models, late_ms, errors = [], "", 0.0, 0
    sources = {}
    for video in args.videos:
        folder = os.path.join(work, "sources")
        os.makedirs(folder, exist_ok=True)
        sources[video] = video_sources(args.cli, args.data, video, folder)
    count = args.frames
    for name, flags in configs:
        for run in args.runs:
            streams = []
            for video in args.videos:
                print(f"stream_bench: {name}, {run}, video {video}: {count} frames at {args.fps:g} per second",
                      file=sys.stderr, flush=True)
                if run == "follow":
                    stream, info = run_follow(args, flags, sources[video], count, work)
                else:
                    stream, info = run_serve(args, flags, sources[video], count)
                models = models or next((line.split(": ", 1)[1].split(" from ")[0] for line in info
                                         if " models, " in line), "")
                late_ms = max([late_ms] + [1000 * late for late in stream.late])
                cells, stream_errors = summary([stream])
                errors += stream_errors
                print(f"stream_bench:   answered {cells[1]}, latency p50/95/99 {', '.join(cells[2:5])} ms",
                      file=sys.stderr, flush=True)
                rows.append(f"| {name} | {RUNS[run]} | {video} | " + " | ".join(cells) + " |")
                streams.append(stream)
            if len(streams) > 1:
                rows.append(f"| {name} | {RUNS[run]} | all | " + " | ".join(summary(streams)[0]) + " |")
    return rows, models, late_ms, errors


def main():
    args, configs = parse_args()
    signal.signal(signal.SIGTERM, die_on_signal)
    try:
        with tempfile.TemporaryDirectory(prefix="stream_bench-") as work:
            check_configs(args, configs, work)
            rows, models, late_ms, errors = measure(args, configs, work)
    except BenchError as error:
        print(f"stream_bench: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("stream_bench: interrupted", file=sys.stderr)
        return 130
    lines = [f"Library `{args.db}` ({models}). Each video's frames looped, {args.frames} frames fed at {args.fps:g} "
             f"per second to a process started per configuration, run and video (timed from its ready message). "
             f"`recognize --sequence DIR --follow --track --out-json -`: each frame a frame JSON renamed into DIR, "
             f"its latency from then to its line on standard output; `serve`: requests with \"track\": true on "
             f"standard input, latency from when the request was due to its answer. Frames queue when the recognizer "
             f"is slower than the camera, and the wait counts; frames still unanswered {args.drain:g} s after the "
             f"last was due count with the time they had waited (≥: a percentile they may raise). Searched: the "
             f"answered frames in which models were searched (timings_ms has rank, ransac or point_pairs), or that a "
             f"search beside the tracking joined (searched_frames_ago). Skipped: frames passed over for a newer one "
             f"(recognize --latest), without a latency. The feed "
             f"was at most {late_ms:.1f} ms late. Configurations: "
             + "; ".join(f"{name}: `{shlex.join(flags)}`" for name, flags in configs) + ".", "",
             "| configuration | run | video | frames fed | answered | latency p50 ms | p95 ms | p99 ms | searched | "
             "objects per frame | recognizer ms per frame (median) |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"] + rows
    report(args.results, TITLE, lines)
    if errors:
        print(f"stream_bench: {errors} frames answered with an error", file=sys.stderr)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
