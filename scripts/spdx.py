#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The SPDX licence line of every source file we wrote (LICENSE: MIT).

    spdx.py [--root DIR] --check   list the source files without the line; exit 1 when there is any
    spdx.py [--root DIR] --fix     add it where it is missing

The line is the first of the file, in the file's comment syntax; after a shebang (#!) or an HTML doctype it is
the second. Which files: C++ (.cpp .h .hpp), JavaScript (.js .mjs), Python (.py .pyi), shell (.sh), CMake
(CMakeLists.txt .cmake .cmake.in), .toml, .cfg, .html, and scripts without an extension (a #! line naming sh,
bash or python) of the checkout (git's list of tracked and new files
when it is a git checkout), without dependencies (node_modules), build folders and data (meshes, fuzz corpora).
Python 3 standard library only; run by the test Package.Spdx (tests/CMakeLists.txt)."""

import argparse
import os
import subprocess
import sys

LICENSE = "MIT"
SLASHES = (".cpp", ".h", ".hpp", ".js", ".mjs")
HASH = (".py", ".pyi", ".sh", ".cmake", ".cmake.in", ".toml", ".cfg")
HTML = (".html",)
SKIP_DIRS = {".git", "node_modules", "data", "corpus", "fuzz_regressions", "images", "__pycache__"}


def shebang_script(path):
    """Whether a file without a known extension is a shell or Python script (#! line)."""
    try:
        with open(path, "rb") as f:
            first = f.readline(200)
    except OSError:
        return False
    return first.startswith(b"#!") and any(k in first for k in (b"sh", b"python"))


def comment(path):
    """The SPDX line for a file, or None for a file that is not a source file of ours."""
    name = os.path.basename(path)
    if "." not in name and name != "CMakeLists" and shebang_script(path):
        return f"# SPDX-License-Identifier: {LICENSE}"
    tag = f"SPDX-License-Identifier: {LICENSE}"
    if name.endswith(SLASHES):
        return f"// {tag}"
    if name == "CMakeLists.txt" or name.endswith(HASH):
        return f"# {tag}"
    if name.endswith(HTML):
        return f"<!-- {tag} -->"
    return None


def skipped(relpath):
    parts = relpath.split("/")
    return any(p in SKIP_DIRS or p.startswith("build") or p.endswith(".egg-info") for p in parts[:-1])


def source_files(root):
    """{path relative to root: its SPDX line} of the source files."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "--cached", "--others", "--exclude-standard", "-z"],
                             stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, check=True)
        files = [f for f in out.stdout.decode().split("\0") if f]
    except (OSError, subprocess.CalledProcessError):  # not a git checkout (e.g. a source archive)
        files = []
        for folder, dirs, names in os.walk(root):
            rel = os.path.relpath(folder, root)
            dirs[:] = [d for d in dirs if d not in SKIP_DIRS and not d.startswith("build") and not d.endswith(".egg-info")]
            files += [os.path.normpath(os.path.join(rel, n)) for n in names]
    files = [f for f in files if not skipped(f) and os.path.isfile(os.path.join(root, f))]
    return {f: comment(os.path.join(root, f)) for f in sorted(files) if comment(os.path.join(root, f))}


def header_lines(lines):
    """How many lines stay above the SPDX line: a shebang or a doctype."""
    return 1 if lines and (lines[0].startswith("#!") or lines[0].lower().startswith("<!doctype")) else 0


def has_line(path, line):
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.read().split("\n")[:2]
    return len(lines) > header_lines(lines) and lines[header_lines(lines)].rstrip() == line


def add_line(path, line):
    with open(path, encoding="utf-8", newline="") as f:
        text = f.read()
    lines = text.split("\n")
    at = header_lines(lines)
    lines.insert(at, line)
    with open(path, "w", encoding="utf-8", newline="") as f:
        f.write("\n".join(lines))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--check", action="store_true")
    mode.add_argument("--fix", action="store_true")
    args = parser.parse_args(argv)
    root = os.path.abspath(args.root)
    files = source_files(root)
    if not files:
        print(f"spdx.py: no source files found under {root}", file=sys.stderr)
        return 1
    missing = [f for f, line in files.items() if not has_line(os.path.join(root, f), line)]
    if args.fix:
        for f in missing:
            add_line(os.path.join(root, f), files[f])
        print(f"spdx.py: added the SPDX line to {len(missing)} of {len(files)} source files")
        return 0
    if missing:
        print(f"spdx.py: {len(missing)} of {len(files)} source files lack the line '{files[missing[0]]}' (or its "
              f"equivalent in their comment syntax) as their first line (second after a shebang); "
              f"`python3 scripts/spdx.py --fix` adds it:", file=sys.stderr)
        for f in missing:
            print(f"  {f}", file=sys.stderr)
        return 1
    print(f"spdx.py: all {len(files)} source files carry the SPDX line")
    return 0


if __name__ == "__main__":
    sys.exit(main())
