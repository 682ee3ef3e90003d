#!/usr/bin/python3
"""docs_commands: the commands in README.md and docs/*.md work with the ecvpose that was built (issue 56).

- A ```sh or ```bash block right after a line `<!-- runnable -->` is run with bash (-e -o pipefail, standard input
  empty) in a temporary folder holding `lib.sqlite` (the demo library built from models/meshes) and `models/` (a link
  to the checkout's models/), with the built `ecvpose` first on the PATH. The runnable blocks of one file run in
  order in one folder (a later block may read what an earlier one wrote); each file gets a folder of its own. A block
  fails on a non-zero exit, or when a line it prints to standard output is a JSON object with an "error" key (what
  `ecvpose serve` answers for a request it cannot serve, with exit 0).
- Every other shell block (```sh, ```bash, ```console; in an unmarked ``` block and in a block with `$ ` prompts only
  the prompt lines) and every inline `ecvpose ...` code span is checked without running: each `ecvpose SUBCOMMAND`
  names a subcommand that exists (nested ones too: `modeldb build`) and each `--flag` after it is one of that
  subcommand's flags, as `ecvpose SUBCOMMAND --help` lists them.
- In ```python blocks, each `ecvpose.name` (and `ecvpose.Name.attribute`) exists in the built Python module, when it
  was built (--python-dir; skipped otherwise).

Each failure names the file and the line. Usage:
  docs_commands.py --ecvpose BUILD/app/ecvpose --source CHECKOUT [--python-dir BUILD/python] [--keep]
"""

import argparse
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

MARKER = "<!-- runnable -->"
SHELL_LANGUAGES = {"sh", "bash", "shell", "console"}
# The demo library, as tests/support/demo_library.cpp builds it (and README's first command).
LIBRARY_FLAGS = ["--views", "40", "--distance", "0.9"]
BLOCK_TIMEOUT_S = 120
VERBOSE = False

# Shell operators after which a new command starts, and redirections (their next word is a file name).
COMMAND_SEPARATORS = {"|", "||", "&&", ";", ";;", "&", "|&", "(", ")", "{", "}", "!"}
COMMAND_PREFIXES = {"sudo", "time", "exec", "nice", "env", "command"}


class Block:
    def __init__(self, path, line, language, lines, runnable):
        self.path = path  # relative to the checkout
        self.line = line  # of the opening fence, from 1
        self.language = language
        self.lines = lines  # [(line number, text)]
        self.runnable = runnable

    def where(self):
        return f"{self.path}:{self.line}"


def parse_markdown(path, relative):
    """The fenced blocks, the inline code spans outside them [(line, text)] and misplaced markers."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    blocks, problems = [], []
    prose = []  # the file with the blocks blanked, for the inline spans
    i = 0
    while i < len(lines):
        # A fence: three or more backticks (and no backtick after them: that is an inline span) or tildes.
        opening = re.match(r"^ {0,3}(`{3,}(?=[^`]*$)|~{3,})\s*([\w+-]*)", lines[i])
        if not opening:
            if lines[i].strip() == MARKER and not re.match(r"^\s*```\s*(sh|bash)\s*$", lines[i + 1] if i + 1 < len(lines) else ""):
                problems.append(f"{relative}:{i + 1}: {MARKER} must be the line right before a ```sh or ```bash fence")
            prose.append(lines[i])
            i += 1
            continue
        fence, language = opening.group(1), opening.group(2).lower()
        start = i
        content = []
        i += 1
        while i < len(lines) and not lines[i].strip().startswith(fence):
            content.append((i + 1, lines[i]))
            i += 1
        if i == len(lines):
            problems.append(f"{relative}:{start + 1}: code block not closed")
        runnable = start > 0 and lines[start - 1].strip() == MARKER
        blocks.append(Block(relative, start + 1, language, content, runnable))
        prose.extend([""] * (i + 1 - start))
        i += 1
    spans = []
    text = "\n".join(prose)
    for m in re.finditer(r"(?<!`)`([^`]+)`(?!`)", text):
        spans.append((text.count("\n", 0, m.start()) + 1, " ".join(m.group(1).split())))
    return blocks, spans, problems


class Cli:
    """Subcommands and flags of the built ecvpose, read from its --help (CLI11's format)."""

    def __init__(self, program):
        self.program = program
        self.cache = {}

    def describe(self, path):
        path = tuple(path)
        if path not in self.cache:
            run = subprocess.run([self.program, *path, "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 text=True, timeout=60)
            if run.returncode != 0:
                raise RuntimeError(f"`ecvpose {' '.join(path)} --help` exited {run.returncode}:\n{run.stdout}")
            subcommands, flags, section = set(), set(), None
            for line in run.stdout.splitlines():
                if line and not line[0].isspace() and line.rstrip().endswith(":"):
                    section = line.strip()[:-1]
                    continue
                m = re.match(r"^  (\S+)", line)  # an entry: two spaces, then its name
                if not m:
                    continue
                name = m.group(1)
                if name.startswith("-"):
                    for part in name.split(","):
                        part = re.sub(r"\{.*?\}", "", part)
                        if part.startswith("--"):
                            flags.add(part)
                elif section == "Subcommands":
                    subcommands.add(name)
            self.cache[path] = (subcommands, flags)
        return self.cache[path]

    def check(self, words):
        """Problems of one `ecvpose ...` command (its words after the program); [] when it is right."""
        path = []
        subcommands, flags = self.describe(path)
        for word in words:
            if word.startswith("<") or word.startswith("..."):  # a placeholder: `ecvpose <subcommand> --help`
                return []
            if word.startswith("--") and len(word) > 2:
                flag = word.split("=", 1)[0]
                if flag not in flags:
                    command = " ".join(["ecvpose", *path])
                    return [f"`{command}` has no flag {flag} (`{command} --help`)"]
            elif not word.startswith("-") and subcommands:
                if word not in subcommands:
                    command = " ".join(["ecvpose", *path])
                    return [f"`{command}` has no subcommand `{word}` (it has: {', '.join(sorted(subcommands))})"]
                path.append(word)
                subcommands, flags = self.describe(path)
        return []


def logical_lines(lines, prompts_only):
    """[(line, text)]: continuation lines joined, heredoc bodies dropped; with prompts_only only `$ ` lines."""
    result = []
    i = 0
    while i < len(lines):
        number, text = lines[i]
        i += 1
        if prompts_only:
            if not text.startswith("$ "):
                continue
            text = text[2:]
        while text.rstrip().endswith("\\") and i < len(lines):
            text = text.rstrip()[:-1] + " " + lines[i][1].strip()
            i += 1
        heredoc = re.search(r"<<-?\s*['\"]?(\w+)['\"]?", text)
        if heredoc:
            while i < len(lines) and lines[i][1].strip() != heredoc.group(1):
                i += 1
            i += 1
        result.append((number, text))
    return result


def ecvpose_commands(text):
    """The word lists following each `ecvpose` program word of a shell line (or raises ValueError)."""
    lexer = shlex.shlex(text, posix=True, punctuation_chars=True)
    lexer.whitespace_split = True
    words = list(lexer)
    commands = []
    at_command = True
    i = 0
    while i < len(words):
        word = words[i]
        if word in COMMAND_SEPARATORS:
            at_command = True
        elif at_command and (re.match(r"^[A-Za-z_]\w*=", word) or word in COMMAND_PREFIXES):
            pass
        elif at_command:
            at_command = False
            if os.path.basename(word) == "ecvpose":
                arguments = []
                i += 1
                while i < len(words) and words[i] not in COMMAND_SEPARATORS and not re.match(r"^[<>&]+$", words[i]):
                    arguments.append(words[i])
                    i += 1
                commands.append(arguments)
                continue
        i += 1
    return commands


def check_statically(blocks, spans_by_file, cli):
    failures, checked = [], 0
    for block in blocks:
        if block.language not in SHELL_LANGUAGES and block.language != "":
            continue
        prompts_only = block.language in ("", "console") or any(t.startswith("$ ") for _, t in block.lines)
        for number, text in logical_lines(block.lines, prompts_only):
            try:
                commands = ecvpose_commands(text)
            except ValueError as error:
                failures.append(f"{block.path}:{number}: cannot read the shell line ({error}): {text}")
                continue
            for words in commands:
                checked += 1
                if VERBOSE:
                    print(f"  {block.path}:{number}: ecvpose {' '.join(words)}")
                failures += [f"{block.path}:{number}: {p}: {text.strip()}" for p in cli.check(words)]
    for path, spans in spans_by_file.items():
        for number, text in spans:
            if not re.match(r"^ecvpose\s+\S", text):
                continue
            try:
                commands = ecvpose_commands(text)
            except ValueError:
                continue  # prose such as `ecvpose recognize`'s flags
            for words in commands:
                checked += 1
                if VERBOSE:
                    print(f"  {path}:{number}: ecvpose {' '.join(words)}")
                failures += [f"{path}:{number}: {p}: `{text}`" for p in cli.check(words)]
    return failures, checked


def check_python_names(blocks, python_dir):
    """Each ecvpose.name of the python blocks exists in the built module; (failures, note)."""
    names = {}
    for block in blocks:
        if block.language != "python":
            continue
        for number, text in block.lines:
            code = re.sub(r"#.*", "", re.sub(r"'[^']*'|\"[^\"]*\"", "''", text))  # without strings and comments
            for m in re.finditer(r"(?<![\w.])ecvpose((?:\.[A-Za-z_]\w*)+)", code):
                names.setdefault(m.group(1)[1:], f"{block.path}:{number}")
    if not names:
        return [], "no ecvpose.name in python blocks"
    if not python_dir or not os.path.exists(os.path.join(python_dir, "ecvpose", "__init__.py")):
        return [], f"python names not checked: no module in {python_dir}"
    probe = ("import json, sys, ecvpose\n"
             "missing = []\n"
             "for name in json.loads(sys.argv[1]):\n"
             "    thing = ecvpose\n"
             "    for part in name.split('.'):\n"
             "        if not hasattr(thing, part):\n"
             "            missing.append(name); break\n"
             "        thing = getattr(thing, part)\n"
             "print(json.dumps(missing))\n")
    environment = dict(os.environ, PYTHONPATH=python_dir)
    run = subprocess.run([sys.executable, "-c", probe, json.dumps(sorted(names))], env=environment,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=120)
    if run.returncode != 0:
        return [], f"python names not checked: the module in {python_dir} did not import ({run.stderr.strip()[-300:]})"
    missing = json.loads(run.stdout)
    return [f"{names[n]}: the Python module has no ecvpose.{n}" for n in missing], f"{len(names)} python names checked"


def build_library(program, source, folder):
    library = os.path.join(folder, "lib.sqlite")
    if "ECV_DEMO_LIBRARY" in os.environ:  # the one ctest's demo_library fixture built with the same flags
        shutil.copy(os.environ["ECV_DEMO_LIBRARY"], library)
        return library
    started = time.monotonic()
    run = subprocess.run([program, "modeldb", "build", os.path.join(source, "models", "meshes"), "--db", library,
                          *LIBRARY_FLAGS], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         timeout=600)
    if run.returncode != 0:
        raise RuntimeError(f"building the demo library failed ({run.returncode}):\n{run.stdout[-3000:]}")
    print(f"docs_commands: demo library built in {time.monotonic() - started:.1f} s")
    return library


def run_block(block, folder, environment):
    """Runs one runnable block in folder; a failure message or None."""
    # Line numbers in bash's messages are those of the Markdown file: the block's lines sit at their own numbers.
    script = ["trap 'echo \"docs_commands: failed at line $LINENO\" >&2' ERR; set -eo pipefail"]
    for number, text in block.lines:
        script += [""] * (number - 1 - len(script))
        script.append(text)
    path = os.path.join(folder, f"block_{block.line}.sh")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(script) + "\n")
    started = time.monotonic()
    try:
        run = subprocess.run(["bash", path], cwd=folder, env=environment, stdin=subprocess.DEVNULL,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=BLOCK_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return f"{block.where()}: runnable block did not end within {BLOCK_TIMEOUT_S} s"
    seconds = time.monotonic() - started
    body = "\n".join(f"  {number}: {text}" for number, text in block.lines)
    output = (run.stdout[-2000:] + run.stderr[-3000:]).rstrip()
    if run.returncode != 0:
        return f"{block.where()}: runnable block exited {run.returncode}:\n{body}\n--- its output:\n{output}"
    for line in run.stdout.splitlines():
        if line.startswith("{"):
            try:
                answer = json.loads(line)
            except ValueError:
                continue
            if isinstance(answer, dict) and "error" in answer:
                return f"{block.where()}: runnable block answered an error:\n{body}\n--- its output:\n{output}"
    print(f"docs_commands: {block.where()} ran ({seconds:.1f} s)")
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--ecvpose", required=True, help="the built program")
    parser.add_argument("--source", required=True, help="the checkout")
    parser.add_argument("--python-dir", help="folder of the built Python package (build/python)")
    parser.add_argument("--keep", action="store_true", help="keep the temporary folder")
    parser.add_argument("--verbose", action="store_true", help="list the commands checked")
    args = parser.parse_args()
    global VERBOSE
    VERBOSE = args.verbose
    program = os.path.realpath(args.ecvpose)
    source = os.path.realpath(args.source)

    files = [os.path.join(source, "README.md")]
    docs = os.path.join(source, "docs")
    files += sorted(os.path.join(docs, name) for name in os.listdir(docs) if name.endswith(".md"))
    all_blocks, spans_by_file, failures = [], {}, []
    for path in files:
        relative = os.path.relpath(path, source)
        blocks, spans, problems = parse_markdown(path, relative)
        all_blocks += blocks
        spans_by_file[relative] = spans
        failures += problems
        for block in blocks:
            if block.runnable and block.language not in ("sh", "bash"):
                failures.append(f"{block.where()}: a runnable block must be ```sh or ```bash")

    cli = Cli(program)
    static_failures, checked = check_statically(all_blocks, spans_by_file, cli)
    failures += static_failures
    print(f"docs_commands: {checked} ecvpose commands checked against --help")
    python_failures, note = check_python_names(all_blocks, args.python_dir)
    failures += python_failures
    print(f"docs_commands: {note}")

    runnable = [b for b in all_blocks if b.runnable and b.language in ("sh", "bash")]
    if not runnable:
        failures.append(f"no block of README.md or docs/*.md is marked {MARKER}")
    work = tempfile.mkdtemp(prefix="docs_commands.")
    try:
        if runnable:
            library = build_library(program, source, work)
            environment = dict(os.environ)
            environment["PATH"] = os.path.dirname(program) + os.pathsep + environment.get("PATH", "")
            environment.pop("PYTHONPATH", None)
            for relative in dict.fromkeys(b.path for b in runnable):
                folder = os.path.join(work, relative.replace("/", "_"))
                os.mkdir(folder)
                shutil.copy(library, os.path.join(folder, "lib.sqlite"))
                os.symlink(os.path.join(source, "models"), os.path.join(folder, "models"))
                for block in (b for b in runnable if b.path == relative):
                    failure = run_block(block, folder, environment)
                    if failure:
                        failures.append(failure)
    finally:
        if args.keep:
            print(f"docs_commands: kept {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)

    print(f"docs_commands: {len(runnable)} runnable blocks, {len(failures)} failures")
    for failure in failures:
        print(f"FAILED {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
