#!/usr/bin/python3
"""recognizer_settings: each front end of the recognizer's settings has every setting of the table, with the table's
default, and no recognizer setting the table lacks (issue 56).

The table is what `ecvpose recognize --settings-json` prints (recognize/recognizer_settings.cpp). Checked against it:
- the flags of `ecvpose recognize --help`, `ecvpose serve --help` and `ecvpose bop --help`;
- the flags of `recognize_bench --help` and `generalisation_bench --help` (--bench; skipped, saying so, without);
- the Python Recognizer (--python-dir; skipped, saying so, without): a recognizer made with every keyword set to a
  value other than its default shows those values in `settings`, one made without keywords the defaults, and
  help(ecvpose.Recognizer) names each keyword; an unknown keyword is refused, naming it;
- the tuning table of docs/how-it-works.md: each setting's flag and default.
A flag of a front end that is no setting must be in that front end's list below (its files, frames and runs).

Usage: recognizer_settings.py --ecvpose BUILD/app/ecvpose --source CHECKOUT [--bench BUILD/bench]
                              [--python-dir BUILD/python]
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

# The flags of each front end that are not recognizer settings.
OWN_FLAGS = {
    "recognize": {"--help", "--db", "--models", "--sequence", "--follow", "--latest", "--idle-timeout", "--out-json",
                  "--out-bop", "--scene-id", "--image-id", "--overlay", "--color", "--depth", "--depth-scale",
                  "--camera", "--targets"},
    "bop": {"--help", "--db", "--models", "--dataset", "--split", "--targets", "--out", "--models-info", "--restart",
            "--out-md", "--out-json"},
    "serve": {"--help", "--db", "--models", "--socket", "--max-clients", "--idle-timeout", "--root", "--socket-mode",
              "--max-request-bytes"},
    "recognize_bench": {"--help", "--db", "--lmo-db", "--peers", "--peers-only", "--object-pixels", "--bytes",
                        "--seeds", "--turned", "--casts", "--python", "--figure", "--results", "--frames",
                        "--frame-step", "--ppf-sampling", "--ppf-scene-distance", "--min-inlier-fraction"},
    "generalisation_bench": {"--help", "--db", "--data", "--seeds", "--rendered", "--composites", "--split",
                             "--cast-step", "--figures", "--figure-format", "--results",
                             "--detections", "--judged", "--verified"},
}
# Settings a front end does not take, and why: the benches run frames in a fixed order, and a search beside the
# tracking would make their detections depend on the machine's speed.
NOT_TAKEN = {"recognize_bench": {"--search-beside"}, "generalisation_bench": {"--search-beside"}}
CORES = min(256, os.cpu_count() or 1)
# Defaults a front end sets apart from the table's: the worker threads.
OWN_DEFAULTS = {"recognize": {"threads": CORES}, "serve": {"threads": CORES}, "bop": {"threads": CORES},
                "generalisation_bench": {"threads": 2}, "python": {"threads": 2}}


def run(command, **kwargs):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=120,
                            **kwargs)
    if result.returncode != 0:
        raise RuntimeError(f"`{' '.join(command)}` exited {result.returncode}:\n{result.stdout}")
    return result.stdout


def help_flags(text):
    """{flag: default text or None} of a CLI11 --help: each entry's name, and what follows its last '='."""
    flags = {}
    for line in text.splitlines():
        m = re.match(r"^  (-\S+(?: \S+)*)", line)  # two spaces, the entry up to the next two spaces
        if not m:
            continue
        name, _, rest = m.group(1).partition(" ")
        default = rest.rsplit("=", 1)[1].removesuffix(" ...") if "=" in rest else None
        for part in name.split(","):
            if part.startswith("--"):
                flags[part] = default
    return flags


def same_value(setting, text, expected):
    if setting["type"] in ("count", "number"):
        try:
            return abs(float(text) - float(expected)) <= 1e-12 * max(1.0, abs(float(expected)))
        except (TypeError, ValueError):
            return False
    return text == str(expected)


def check_help(front_end, text, table, failures):
    flags = help_flags(text)
    known = OWN_FLAGS[front_end]
    for setting in table:
        flag = setting["flag"]
        if flag in NOT_TAKEN.get(front_end, set()):
            if flag in flags:
                failures.append(f"{front_end}: {flag} is a flag, but NOT_TAKEN says it is not")
            continue
        if flag not in flags:
            failures.append(f"{front_end}: no flag {flag}")
            continue
        if setting["type"] == "flag":
            if flags[flag] is not None:
                failures.append(f"{front_end}: {flag} takes a value ({flags[flag]}), the table's is an on/off flag")
            continue
        expected = OWN_DEFAULTS.get(front_end, {}).get(setting["name"], setting["default"])
        if not same_value(setting, flags[flag], expected):
            failures.append(f"{front_end}: {flag} defaults to {flags[flag]}, the table to {expected}")
    table_flags = {s["flag"] for s in table}
    for flag in sorted(set(flags) - table_flags - known):
        failures.append(f"{front_end}: {flag} is neither a setting of the table nor in {front_end}'s own flags "
                        f"(tests/recognize/recognizer_settings.py, OWN_FLAGS)")
    for flag in sorted(known & table_flags):
        failures.append(f"{front_end}: {flag} is a setting of the table and in OWN_FLAGS")


def check_table(table, failures):
    names = [s["name"] for s in table]
    for name in sorted({n for n in names if names.count(n) > 1}):
        failures.append(f"table: {name} twice")
    for s in table:
        if s["keyword"] != s["name"].replace("-", "_"):
            failures.append(f"table: {s['name']}'s keyword is {s['keyword']}")
        if s["type"] == "flag" and s["flag"].startswith("--no-") != s["default"]:
            failures.append(f"table: {s['flag']} and a default of {s['default']}: --no-X flags turn on settings off")
        if s["type"] in ("count", "number") and not (s["min"] <= s["default"] <= (s["max"] or float("inf"))):
            failures.append(f"table: {s['name']} defaults to {s['default']}, outside its range ({s['expected']})")
        if s["type"] == "choice" and s["default"] not in s["choices"]:
            failures.append(f"table: {s['name']} defaults to {s['default']}, not one of {s['choices']}")
        if not s["help"]:
            failures.append(f"table: {s['name']} has no help")


def other_value(setting):
    """A valid value of `setting` other than its default."""
    default, kind = setting["default"], setting["type"]
    if kind == "flag":
        return not default
    if kind == "choice":
        return next(c for c in setting["choices"] if c != default)
    low, high = setting["min"], setting["max"]
    value = low if low != default else (high if high is not None else default + 1)
    return int(value) if kind == "count" else float(value)


def check_python(python_dir, source, table, failures):
    sys.path.insert(0, python_dir)
    import ecvpose  # noqa: E402 (the module of this build)

    keywords = {s["keyword"]: s for s in table}
    doc = ecvpose.Recognizer.__init__.__doc__ or ""
    for keyword in keywords:
        if not re.search(rf"^{keyword}=", doc, re.MULTILINE):
            failures.append(f"python: help(ecvpose.Recognizer) does not list {keyword}")
    with tempfile.TemporaryDirectory(prefix="recognizer_settings.") as folder:
        db = os.path.join(folder, "one.sqlite")
        ecvpose.build_models(db, os.path.join(source, "models", "meshes", "004_sugar_box"), views=2, threads=1)
        library = ecvpose.ModelLibrary.open(db)
        defaults = ecvpose.Recognizer(library).settings
        for keyword in sorted(set(defaults) - set(keywords)):
            failures.append(f"python: Recognizer.settings has {keyword}, which the table lacks")
        for keyword, setting in keywords.items():
            expected = OWN_DEFAULTS["python"].get(setting["name"], setting["default"])
            if keyword not in defaults:
                failures.append(f"python: Recognizer.settings lacks {keyword}")
            elif defaults[keyword] != expected:
                failures.append(f"python: {keyword} defaults to {defaults[keyword]!r}, the table to {expected!r}")
        changed = {keyword: other_value(setting) for keyword, setting in keywords.items()}
        changed["track"] = True  # search_every > 1 needs it
        try:
            shown = ecvpose.Recognizer(library, **changed).settings
        except ecvpose.InputError as error:
            failures.append(f"python: Recognizer(**{changed}) raised {error}")
            shown = changed
        for keyword, value in changed.items():
            if shown.get(keyword) != value:
                failures.append(f"python: {keyword}={value!r} gives settings[{keyword!r}] = {shown.get(keyword)!r}")
        try:
            ecvpose.Recognizer(library, no_such_setting=1)
            failures.append("python: Recognizer(no_such_setting=1) was accepted")
        except ecvpose.InputError as error:
            if "no_such_setting" not in str(error):
                failures.append(f"python: the error of an unknown keyword does not name it: {error}")
    return f"{len(keywords)} python keywords checked"


def check_docs(source, table, failures):
    """Each setting is a row of the tuning table of docs/how-it-works.md, with its default."""
    path = os.path.join(source, "docs", "how-it-works.md")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    section = text.split("\n## Tuning\n", 1)[1].split("\n## ", 1)[0]
    documented = {}  # flag -> default cell's part
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 3 or not cells[0].startswith("`--"):
            continue
        flags = re.findall(r"`(--[\w-]+)", cells[0])
        parts = cells[1].split(", ") if len(flags) > 1 else [cells[1]]
        for flag, part in zip(flags, parts):
            documented[flag] = part.strip("`")
    by_flag = {s["flag"]: s for s in table}
    for flag in sorted(set(documented) - set(by_flag)):
        failures.append(f"docs/how-it-works.md, Tuning: {flag} is no setting of the table")
    for flag, setting in by_flag.items():
        if flag not in documented:
            failures.append(f"docs/how-it-works.md, Tuning: no row for {flag}")
            continue
        cell = documented[flag]
        if setting["type"] == "flag":
            good = cell.endswith(" on") if setting["default"] else cell == "off"
        elif setting["name"] == "threads":
            good = cell == "every core"
        else:
            good = same_value(setting, cell.split(" ")[0].strip("`"), setting["default"])
        if not good:
            failures.append(f"docs/how-it-works.md, Tuning: {flag}'s default is `{cell}`, the table's "
                            f"{setting['default']}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--ecvpose", required=True)
    parser.add_argument("--source", required=True)
    parser.add_argument("--bench", help="folder of recognize_bench and generalisation_bench")
    parser.add_argument("--python-dir", help="folder of the built Python package")
    args = parser.parse_args()

    table = json.loads(run([args.ecvpose, "recognize", "--settings-json"]))
    failures = []
    check_table(table, failures)
    for command in ("recognize", "serve", "bop"):
        check_help(command, run([args.ecvpose, command, "--help"]), table, failures)
    notes = [f"{len(table)} settings"]
    for bench in ("recognize_bench", "generalisation_bench"):
        program = os.path.join(args.bench or "", bench)
        if args.bench and os.path.exists(program):
            check_help(bench, run([program, "--help"]), table, failures)
        else:
            notes.append(f"{bench} not checked (not built)")
    if args.python_dir and os.path.exists(os.path.join(args.python_dir, "ecvpose", "__init__.py")):
        notes.append(check_python(args.python_dir, args.source, table, failures))
    else:
        notes.append("python not checked (no module)")
    check_docs(args.source, table, failures)
    print("recognizer_settings: " + "; ".join(notes) + f"; {len(failures)} failures")
    for failure in failures:
        print(f"FAILED {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
