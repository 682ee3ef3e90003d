"""Helpers of the Python benches: the machine's description, the YCB-Video frames, the report's section."""

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


def replace_section(text, title, section):
    """`text` with the section headed "## `title`" (up to the next "## " heading) replaced by `section`, or with
    `section` appended when it has none: the C++ benches' ReportSection (bench_util.h)."""
    heading = f"## {title}\n"
    if text.startswith(heading):
        begin = 0
    else:
        begin = text.rfind("\n" + heading)
        if begin < 0:  # a new section, after a blank line
            text = text.rstrip("\n")
            return text + ("\n\n" if text else "") + section
        begin += 1
    end = text.find("\n## ", begin + len(heading))
    return text[:begin] + section + ("" if end < 0 else text[end + 1 :])


def report(results_path, title, lines):
    """Prints the markdown `lines` and puts them in `results_path` under `title`, the date, machine and command, in
    place of the section of that title (the previous run's), or at the end when there is none. `title` must not change
    from run to run; `lines` must not start a line with "## "."""
    markdown = "\n".join(lines) + "\n"
    print(markdown)
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    command = " ".join(["bench/" + pathlib.Path(sys.argv[0]).name] + sys.argv[1:])
    section = f"## {title}\n\n{stamp}, {machine()}, `{command}`\n\n{markdown}\n"
    try:
        with open(results_path, encoding="utf-8") as results:
            text = results.read()
    except FileNotFoundError:
        text = ""
    temporary = f"{results_path}.tmp"
    with open(temporary, "w", encoding="utf-8") as results:
        results.write(replace_section(text, title, section))
    os.replace(temporary, results_path)
