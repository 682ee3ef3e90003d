"""Helpers of the Python benches: the machine's description and the 30 YCB-Video frames."""

import datetime
import os
import pathlib
import platform
import sys


def machine():
    """ "AMD EPYC ... (2 cores)", as the C++ benches write it."""
    name = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as cpuinfo:
            for line in cpuinfo:
                if line.startswith("model name"):
                    name = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{name} ({os.cpu_count()} cores)"


def frame_prefixes(data):
    """The YCB-Video frame prefixes under `data` (ycbv_subset/Example-Scenes), sorted: videos 0000-0002."""
    scenes = pathlib.Path(data) / "ycbv_subset" / "Example-Scenes"
    return sorted(str(p)[: -len("-color.png")] for p in scenes.glob("*/*-color.png"))


def report(results_path, title, lines):
    """Prints the markdown `lines` and appends them to `results_path` under `title`, the date, machine and command."""
    markdown = "\n".join(lines) + "\n"
    print(markdown)
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    command = " ".join(["bench/" + pathlib.Path(sys.argv[0]).name] + sys.argv[1:])
    with open(results_path, "a", encoding="utf-8") as results:
        results.write(f"\n## {title}\n\n{stamp}, {machine()}, `{command}`\n\n{markdown}\n")
