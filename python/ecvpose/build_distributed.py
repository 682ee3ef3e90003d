"""Builds a model library on a Dask cluster: one part of the meshes per task, then one merge.

    /usr/bin/python3 -m ecvpose.build_distributed MESH_DIR LIB [--scheduler ADDRESS] [--parts N] [--views V] ...

Each task builds part I of N of the meshes (split by model name, the same on every machine, as
`ecvpose modeldb build --shard I/N`) into LIB.parts/part-I-of-N.sqlite; when all have run, the parts are merged into
LIB in name order, as one build of all the meshes would have stored them. Without --scheduler a local cluster of
--workers processes is started. On a real cluster MESH_DIR and LIB's folder must be the same path on every worker (a
shared file system) and the workers must import ecvpose. A part whose meshes fail is named with each failed mesh;
the models of every part are still merged and kept, and the exit code is 1.
"""

import argparse
import os
import pathlib
import sys
import time

import ecvpose


def part_path(parts_dir, part, parts):
    """The library file of part `part` of `parts`."""
    return pathlib.Path(parts_dir) / f"part-{part}-of-{parts}.sqlite"


def build_part(meshes, path, part, parts, options):
    """Builds part `part` of `parts` of `meshes` into `path` (a new file). Runs on a worker; returns
    (part, models built, seconds, failure message or None)."""
    start = time.monotonic()
    for suffix in ("", "-wal", "-shm", "-journal"):  # a part is built anew, never added to an older one
        pathlib.Path(str(path) + suffix).unlink(missing_ok=True)
    try:
        built = ecvpose.build_models(str(path), meshes, shard=(part, parts), **options)
        return part, len(built), time.monotonic() - start, None
    except ecvpose.InputError as error:  # names each failed mesh; the part's other models are stored
        return part, None, time.monotonic() - start, str(error)


def parse_arguments(argv):
    parser = argparse.ArgumentParser(
        prog="python3 -m ecvpose.build_distributed",
        description="Build a model library on a Dask cluster: one part of the meshes per task, then a merge.",
    )
    parser.add_argument("meshes", nargs="+", metavar="MESH_OR_DIR",
                        help="mesh files, or directories of <name>/<name>.obj folders, as for `modeldb build`")
    parser.add_argument("library", metavar="LIB", help="the library built (created if missing; models replaced)")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                        help="processes of the local cluster (default: one per core)")
    parser.add_argument("--parts", type=int, default=0,
                        help="parts the meshes are split into, one task each (default: twice the workers)")
    parser.add_argument("--parts-dir", help="folder of the parts' libraries (default: LIB.parts beside LIB)")
    parser.add_argument("--threads", type=int, default=1, help="threads of each part's build (default: 1)")
    parser.add_argument("--views", type=int, help="rendered views per model (default: modeldb build's)")
    parser.add_argument("--distance", type=float, help="camera distance of the views, metres")
    parser.add_argument("--no-ppf", action="store_true", help="store no point pair points")
    args = parser.parse_args(argv)
    if args.workers < 1 or args.parts < 0 or args.threads < 1:
        parser.error("--workers and --threads take a number >= 1, --parts one >= 0")
    return args


def build_options(args):
    options = {"threads": args.threads, "point_pairs": not args.no_ppf}
    if args.views is not None:
        options["views"] = args.views
    if args.distance is not None:
        options["distance"] = args.distance
    return options


def run(args, client):
    """Submits the parts to `client`, waits for them with progress on stderr, merges; returns the exit code."""
    from distributed import as_completed

    from ecvpose import build_distributed  # the task by reference, also when this file runs as __main__

    workers = max(1, len(client.scheduler_info().get("workers", {})))
    parts = args.parts or 2 * workers
    parts_dir = pathlib.Path(args.parts_dir or str(args.library) + ".parts")
    parts_dir.mkdir(parents=True, exist_ok=True)
    meshes = [str(pathlib.Path(m).resolve()) for m in args.meshes]
    options = build_options(args)
    print(f"build_distributed: {parts} parts on {workers} workers into {parts_dir}", file=sys.stderr)
    start = time.monotonic()
    futures = [
        client.submit(build_distributed.build_part, meshes, str(part_path(parts_dir, part, parts)), part, parts, options, pure=False)
        for part in range(parts)
    ]
    failures = []
    for done, future in enumerate(as_completed(futures), start=1):
        try:
            part, models, seconds, failure = future.result()
        except Exception as error:  # the worker died or could not run the task: the part is missing
            failures.append(f"a part: {type(error).__name__}: {error}")
            print(f"build_distributed: [{done}/{parts}] a part FAILED: {error}", file=sys.stderr)
            continue
        if failure is None:
            state = f"{models} models in {seconds:.1f} s"
        else:
            state = "FAILED: " + failure.replace("\n", "\n    ")
            failures.append(f"part {part} of {parts}: {failure}")
        elapsed = time.monotonic() - start
        left = elapsed / done * (parts - done)
        print(f"build_distributed: [{done}/{parts}] part {part}: {state} ({elapsed:.0f} s, about {left:.0f} s left)",
              file=sys.stderr)
    built = [str(p) for p in (part_path(parts_dir, i, parts) for i in range(parts)) if p.exists()]
    merged = ecvpose.merge_libraries(str(args.library), built)
    print(f"merged {merged} models of {len(built)} parts into {args.library} ({time.monotonic() - start:.1f} s)")
    for failure in failures:
        print(f"build_distributed: FAILED: {failure}", file=sys.stderr)
    return 1 if failures else 0


def main(argv=None):
    args = parse_arguments(sys.argv[1:] if argv is None else argv)
    from distributed import Client, LocalCluster

    try:
        if args.scheduler:
            with Client(args.scheduler) as client:
                return run(args, client)
        with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            return run(args, client)
    except ecvpose.InputError as error:
        print(f"build_distributed: error: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
