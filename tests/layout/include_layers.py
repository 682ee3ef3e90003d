#!/usr/bin/env python3
"""Checks that each layer's sources include only the layers beneath it (docs/development.md, "Layout").

Usage: include_layers.py CHECKOUT

Every `#include "folder/..."` of a project header in a layer's .h/.cpp files must name a folder the layer may use.
Prints each include that breaks the rule (file:line) and exits 1 when there is one; exits 0 when there is none.
"""

import pathlib
import re
import sys
import tempfile

CORE = {"core", "io", "ecv", "registration"}  # the four parts of ecv_core, under src/
# Each layer's folder and the folders of project headers it may include (its own among them).
ALLOWED = {
    "src": CORE,
    "render": CORE | {"render"},
    "colorcal": CORE | {"colorcal"},
    "modeldb": CORE | {"render", "colorcal", "modeldb"},
    "recognize": CORE | {"render", "colorcal", "modeldb", "recognize"},
    "camera": CORE | {"camera"},
    "python": CORE | {"render", "colorcal", "modeldb", "recognize", "camera"},
}
PROJECT_FOLDERS = CORE | {"render", "colorcal", "modeldb", "recognize", "camera", "app"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([A-Za-z0-9_]+)/')


def violations(checkout):
    """Each include of a folder its layer may not use, as "path:line: includes folder/ (layer may use ...)"."""
    found = []
    for layer, allowed in ALLOWED.items():
        for path in sorted((checkout / layer).rglob("*")):
            if path.suffix not in (".h", ".cpp") or not path.is_file():
                continue
            for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
                match = INCLUDE.match(line)
                if match and match.group(1) in PROJECT_FOLDERS and match.group(1) not in allowed:
                    found.append(f"{path.relative_to(checkout)}:{number}: includes {match.group(1)}/ "
                                 f"({layer}/ may include {', '.join(sorted(allowed))})")
    return found


def planted_violation_is_found():
    """The check itself works: a camera file including a recognizer header is reported."""
    with tempfile.TemporaryDirectory() as folder:
        root = pathlib.Path(folder)
        (root / "camera").mkdir()
        (root / "camera" / "good.h").write_text('#include "io/frame_io.h"\n')
        (root / "camera" / "bad.cpp").write_text('#include "core/frame.h"\n#include "recognize/recognizer.h"\n')
        found = violations(root)
        return len(found) == 1 and found[0].startswith("camera/bad.cpp:2:")


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    if not planted_violation_is_found():
        print("include_layers: the check missed a planted violation", file=sys.stderr)
        return 1
    found = violations(pathlib.Path(sys.argv[1]))
    for line in found:
        print(line)
    print(f"include_layers: {len(found)} include(s) across layers")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
