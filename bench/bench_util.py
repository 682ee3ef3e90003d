"""Helpers of the Python benches: the machine's description and the 30 YCB-Video frames."""

import os
import pathlib
import platform


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
