# SPDX-License-Identifier: MIT
"""Docstrings everywhere, help(trivcon) reads well, and the examples/ script runs."""

import inspect
import os
import pydoc
import subprocess
import sys

import trivcon
import trivcon.batch
from conftest import REPO


def test_every_public_name_has_a_docstring():
    assert trivcon.__doc__ and "FieldDesigner" in trivcon.__doc__
    missing = []
    for name in trivcon.__all__:
        obj = getattr(trivcon, name)
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and obj is not trivcon.Error:
            for member_name, member in inspect.getmembers(obj):
                if member_name.startswith("_"):
                    continue  # __init__ is documented by the class
                raw = inspect.getattr_static(obj, member_name)
                if isinstance(raw, property) or inspect.isfunction(raw):
                    if not (raw.__doc__ or "").strip():
                        missing.append(f"{name}.{member_name}")
    for name in trivcon.batch.__all__:
        if not (getattr(trivcon.batch, name).__doc__ or "").strip():
            missing.append(f"batch.{name}")
    assert not missing, f"no docstring: {missing}"


def test_help_reads_well():
    text = pydoc.render_doc(trivcon, renderer=pydoc.plaintext)
    for needle in ("trivcon: direction fields", "class FieldDesigner", "solve(self, N=1, singularities=None", "field_indices(V, F, directions, N=1, arrays=False)",
                   "render(V, F, directions, N=1", "class Error", "Face frames", "batch"):
        assert needle in text, needle
    assert pydoc.render_doc(trivcon.FieldDesigner.solve, renderer=pydoc.plaintext).count("singularities") >= 3
    assert "Dask" in pydoc.render_doc(trivcon.batch, renderer=pydoc.plaintext)


def test_batch_help():
    p = subprocess.run([sys.executable, "-m", "trivcon.batch", "--help"], capture_output=True, text=True)
    assert p.returncode == 0 and "--scheduler" in p.stdout and "--sing-dir" in p.stdout


def test_example_script(tmp_path):
    p = subprocess.run([sys.executable, os.path.join(REPO, "examples", "cross_field.py"), "--out", str(tmp_path)], capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert sorted(os.listdir(tmp_path)) == ["connection.txt", "edited.png", "edited.rawfield", "field.png", "field.sing", "field.txt"]
    V, F = trivcon.read_mesh(os.path.join(REPO, "data", "cube_sphere.obj"))
    directions, N = trivcon.read_field(str(tmp_path / "field.txt"), len(F))
    assert trivcon.field_indices(V, F, directions, N=N) == trivcon.read_singularities(os.path.join(REPO, "data", "cube_sphere.sing"), N=4)


def test_python_tutorial_example_runs(tmp_path, monkeypatch):
    """The Python tutorial's complete example (docs/tutorials/python.md), as printed (run in a scratch folder, data/
    from the checkout); test_site_examples runs it too, this checks the files it writes."""
    text = open(os.path.join(REPO, "docs", "tutorials", "python.md")).read()
    section = text[text.index("## A complete example"):]
    code = section[section.index("```python\n") + len("```python\n"):]
    code = code[:code.index("```")]
    os.symlink(os.path.join(REPO, "data"), tmp_path / "data")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "docs/tutorials/python.md", "exec"), {})
    for name in ("field.txt", "connection.txt", "field.rawfield", "field.png", "lines.png"):
        assert (tmp_path / name).stat().st_size > 0
