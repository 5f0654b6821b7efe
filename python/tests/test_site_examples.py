# SPDX-License-Identifier: MIT
"""Every code example of the documentation site runs (docs/development/testing.md, "The examples of this site").

The fenced blocks of README.md and of every page under docs/ (and of the files the pages include) are read in order. Per page, in a
scratch folder with the repository's data/ at data/ and the built program on the PATH:
- sh / bash blocks run with bash -e -o pipefail;
- python blocks run in one namespace per page, with the installed module;
- cpp blocks are complete programs: built with the page's cmake block (its find_package(trivcon)) against an install
  of the build, then run;
- a text block right after <!-- output --> is what the block before it prints: its lines must appear in that output
  in order ("..." alone: any lines; "..." within a line: any text).
A code block with <!-- norun: REASON --> right before it is not run; any other block of another language fails.
"""

import contextlib
import glob
import io
import os
import re
import subprocess
import sys

import pytest

from conftest import REPO, cli_path

DOCS = os.path.join(REPO, "docs")
RUN = {"sh", "bash", "python", "cpp", "cmake"}
DATA = {"", "text", "json"}  # file contents, outputs and API bodies shown as they are
NORUN_LIMIT = 8  # a few, each with its reason
FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([^\s`]*)(.*)$")
COMMENT = re.compile(r"^\s*<!--\s*(norun|output)\s*(?::\s*(.*?))?\s*-->\s*$")


class Block:
    def __init__(self, path, line, lang, text, marker, reason):
        self.path, self.line, self.lang, self.text, self.marker, self.reason = path, line, lang, text, marker, reason
        self.expected = None  # the output block that follows, if any

    def where(self):
        return f"{os.path.relpath(self.path, REPO)}:{self.line}"


def read_blocks(path):
    """The fenced blocks of a Markdown file, with the <!-- norun/output --> comment right before each."""
    lines = open(path, encoding="utf-8").read().split("\n")
    blocks, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, lang = m.group(1), m.group(2), m.group(3)
        body, j = [], i + 1
        while j < len(lines):
            close = FENCE.match(lines[j])
            if close and close.group(2)[0] == fence[0] and len(close.group(2)) >= len(fence) \
                    and not (close.group(3) + close.group(4)).strip():
                break
            body.append(lines[j][len(indent):] if lines[j].startswith(indent) else lines[j])
            j += 1
        assert j < len(lines), f"{path}:{i + 1}: unclosed fence"
        c = COMMENT.match(lines[i - 1]) if i > 0 else None
        blocks.append(Block(path, i + 1, lang, "\n".join(body) + "\n", c.group(1) if c else None, (c.group(2) or "") if c else ""))
        i = j + 1
    return blocks


def site_files():
    """The pages (docs/**/*.md but the generated reference) and the repository files they include, once each."""
    pages = sorted(p for p in glob.glob(os.path.join(DOCS, "**", "*.md"), recursive=True)
                   if os.sep + "generated" + os.sep not in p)
    files = [os.path.join(REPO, "README.md")] + pages  # the front page's tour too
    for page in pages:
        text = open(page, encoding="utf-8").read()
        for rel in re.findall(r"^```\{include\}\s+(\S+)", text, flags=re.M):
            target = os.path.normpath(os.path.join(os.path.dirname(page), rel))
            if target not in files:
                files.append(target)
    return pages, files


def classify(path):
    """The page's blocks to run, in order, each with its expected output; (runs, noruns). Fails on a stray block."""
    runs, noruns, last = [], [], None
    for b in read_blocks(path):
        if b.lang.startswith("{"):
            continue  # a MyST directive (toctree, include, doxygenfile, eval-rst), not an example
        if b.marker == "output":
            assert b.lang == "text", f"{b.where()}: an output block is a text block"
            assert last is not None and last.expected is None, f"{b.where()}: an output block follows no block that runs"
            last.expected = b.text
            continue
        if b.marker == "norun":
            assert b.reason.strip(), f"{b.where()}: <!-- norun: REASON --> needs its reason"
            noruns.append(b)
            last = None
            continue
        if b.lang in RUN:
            runs.append(b)
            last = b
            continue
        assert b.lang in DATA, f"{b.where()}: a ```{b.lang} block neither runs nor says why (<!-- norun: REASON -->)"
        last = None
    return runs, noruns


PAGES, FILES = site_files()


def test_every_block_runs_or_says_why():
    total_runs, total_noruns = 0, []
    for path in FILES:
        runs, noruns = classify(path)
        total_runs += len(runs)
        total_noruns += noruns
    print(f"site examples: {total_runs} blocks run, {len(total_noruns)} not run:")
    for b in total_noruns:
        print(f"  {b.where()}: {b.reason}")
    assert total_runs >= 40
    assert len(total_noruns) <= NORUN_LIMIT, [b.where() for b in total_noruns]
    # The pages the site must have, each with examples that run.
    for page in ("getting-started.md", "tutorials/cli.md", "tutorials/python.md", "tutorials/cpp.md", "tutorials/quads.md",
                 "tutorials/batch.md", "howto/features.md", "howto/repair.md"):
        assert classify(os.path.join(DOCS, page))[0], page


def expect(output, expected, where):
    """Every line of `expected` appears in `output` in order; '...' alone skips any lines, within a line any text."""
    lines = output.split("\n")
    pos = 0
    for want in expected.rstrip("\n").split("\n"):
        if want.strip() == "...":
            continue
        pattern = re.compile("^" + ".*".join(re.escape(part) for part in want.split("...")) + r"\s*$")
        while pos < len(lines) and not pattern.match(lines[pos]):
            pos += 1
        assert pos < len(lines), f"{where}: the output lacks (in order) the line {want!r}; it was:\n{output}"
        pos += 1


@pytest.fixture(scope="session")
def installed(tmp_path_factory):
    """An install of the build (cmake --install), as a user of the library has it."""
    build = os.path.dirname(cli_path())
    if not os.path.isfile(os.path.join(build, "CMakeCache.txt")):
        pytest.skip(f"no C++ build at {build} (set TRIVCON_CLI)")
    prefix = tmp_path_factory.mktemp("prefix")
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True, capture_output=True)
    return str(prefix)


def build_cpp(page_runs, scratch, prefix):
    """The page's C++ programs, built with its cmake block: the first is main.cpp (app), the others example_K."""
    cmake = [b for b in page_runs if b.lang == "cmake"]
    cpps = [b for b in page_runs if b.lang == "cpp"]
    assert len(cmake) == 1 and "find_package(trivcon" in cmake[0].text and "add_executable(app main.cpp)" in cmake[0].text, \
        "a page with C++ programs has one cmake block building app from main.cpp"
    project = os.path.join(scratch, "cpp_project")
    os.makedirs(project)
    lists = cmake[0].text
    programs = {}
    for k, b in enumerate(cpps):
        name = "main.cpp" if k == 0 else f"example_{k}.cpp"
        target = "app" if k == 0 else f"example_{k}"
        assert "int main(" in b.text, f"{b.where()}: a C++ block is a complete program"
        open(os.path.join(project, name), "w").write(b.text)
        if k:
            lists += f"add_executable({target} {name})\ntarget_link_libraries({target} PRIVATE trivcon::trivcon)\n"
        programs[id(b)] = os.path.join(project, "build", target)
    open(os.path.join(project, "CMakeLists.txt"), "w").write(lists)
    for args in (["-S", project, "-B", os.path.join(project, "build"), "-DCMAKE_BUILD_TYPE=Release", f"-DCMAKE_PREFIX_PATH={prefix}"],
                 ["--build", os.path.join(project, "build"), "-j2"]):
        p = subprocess.run(["cmake", *args], capture_output=True, text=True)
        assert p.returncode == 0, f"cmake {' '.join(args)}:\n{p.stdout}\n{p.stderr}"
    return programs


@pytest.mark.parametrize("page", [p for p in FILES if classify(p)[0]], ids=lambda p: os.path.relpath(p, DOCS))
def test_page_examples(page, tmp_path, monkeypatch, request):
    program = cli_path()
    if not os.access(program, os.X_OK):
        pytest.skip(f"the trivcon program is not built at {program} (set TRIVCON_CLI)")
    runs, _ = classify(page)
    scratch = str(tmp_path)
    os.symlink(os.path.join(REPO, "data"), os.path.join(scratch, "data"))
    env = dict(os.environ)
    # trivcon, then this Python (python3 in a block is the one with the module), then the rest.
    env["PATH"] = os.pathsep.join([os.path.dirname(program), os.path.dirname(sys.executable), env.get("PATH", "")])
    monkeypatch.chdir(scratch)
    namespace = {"__name__": "__site_example__"}
    programs = None
    for b in runs:
        if b.lang in ("sh", "bash"):
            p = subprocess.run(["stdbuf", "-oL", "-eL", "bash", "-e", "-o", "pipefail", "-c", b.text], cwd=scratch, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=900)
            assert p.returncode == 0, f"{b.where()}: exit status {p.returncode}:\n{p.stdout}"
            output = p.stdout
        elif b.lang == "python":
            out = io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
                exec(compile(b.text, b.where(), "exec"), namespace)
            output = out.getvalue()
        elif b.lang == "cmake":
            continue  # built with the page's C++ programs
        else:  # cpp
            if programs is None:
                programs = build_cpp(runs, scratch, request.getfixturevalue("installed"))
            p = subprocess.run([programs[id(b)]], cwd=scratch, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               timeout=600)
            assert p.returncode == 0, f"{b.where()}: exit status {p.returncode}:\n{p.stdout}"
            output = p.stdout
        if b.expected is not None:
            expect(output, b.expected, b.where())
