# SPDX-License-Identifier: MIT
"""The Dask batch (python -m trivcon.batch) on a local cluster of two worker processes."""

import json
import os
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest

import trivcon

distributed = pytest.importorskip("distributed", reason="python3-distributed (Dask) is not installed")
import trivcon.batch as batch  # noqa: E402

BAD_OBJ = "v 0 0 0\nv 1 0 0\nf 1 2 3\n"


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        with distributed.Client(c) as client:
            assert len(client.scheduler_info()["workers"]) == 2
        yield c


@pytest.fixture
def meshes(tmp_path):
    """Three good meshes (sphere-like cube, torus, genus 2), one broken file, and singularity files."""
    folder = tmp_path / "meshes"
    folder.mkdir()
    cube = trivcon.make_cube_sphere(6, spherical=False)
    trivcon.write_mesh(str(folder / "cube.obj"), *cube)
    trivcon.write_mesh(str(folder / "torus.ply"), *trivcon.make_torus(20, 10))
    trivcon.write_mesh(str(folder / "eight.obj"), *trivcon.make_genus_surface(2, 1))
    (folder / "broken.obj").write_text(BAD_OBJ)
    sings = tmp_path / "sings"
    sings.mkdir()
    corners = [v for v in range(len(cube[0])) if (abs(abs(cube[0][v]) - 1) < 1e-12).all()]
    trivcon.write_singularities(str(sings / "cube.sing"), {v: "1/4" for v in corners}, N=4)
    trivcon.write_singularities(str(sings / "torus.sing"), {0: 1}, N=4)  # violates Gauss-Bonnet (chi = 0)
    trivcon.write_singularities(str(sings / "eight.sing"), {}, N=4)  # so does this one (chi = -2)
    return folder, sings


def library_message(call, *args):
    with pytest.raises(trivcon.Error) as e:
        call(*args)
    return str(e.value)


def check_outputs(row, N):
    """The field written reads back with the singularities written (judged by field_indices)."""
    field, sing = row["outputs"][0], row["outputs"][1]
    V, F = trivcon.read_mesh(row["path"])
    directions, file_N = trivcon.read_field(field, len(F))
    assert file_N == N
    assert trivcon.field_indices(V, F, directions, N=N) == trivcon.read_singularities(sing, N=N)
    assert len(trivcon.read_singularities(sing, N=N)) == row["singularities"]


def test_auto_batch_on_a_cluster(cluster, meshes, tmp_path):
    folder, _ = meshes
    out = tmp_path / "out"
    rows = batch.run([str(folder)], str(out), N=4, scheduler=cluster.scheduler_address, png=True, connection=True, progress=False)
    assert [r["mesh"] for r in rows] == ["broken", "cube", "eight", "torus"]  # folder order, sorted
    status = {r["mesh"]: r["status"] for r in rows}
    assert status == {"broken": "failed", "cube": "ok", "eight": "ok", "torus": "ok"}
    broken = rows[0]
    assert broken["message"] == library_message(trivcon.read_mesh, str(folder / "broken.obj"))
    assert broken["message"].endswith("face index 3 out of range (file has 2 vertices)")
    by_name = {r["mesh"]: r for r in rows}
    assert by_name["cube"]["singularities"] == 8 and by_name["eight"]["chi"] == -2
    for name in ("cube", "eight", "torus"):
        row = by_name[name]
        assert row["residual"] < 1e-9 and row["source"] == "auto"
        assert [os.path.basename(p) for p in row["outputs"]] == [f"{name}.field.txt", f"{name}.sing", f"{name}.connection.txt", f"{name}.png"]
        check_outputs(row, 4)
        assert row["worker"].startswith("tcp://")
    # The summary files.
    assert (out / "summary.txt").read_text() == batch.format_table(rows) + "\n"
    assert json.loads((out / "summary.json").read_text()) == json.loads(json.dumps(rows))
    table = batch.format_table(rows).splitlines()
    assert table[0].split() == list(batch.COLUMNS)
    assert table[-1] == f"4 meshes: 3 ok, 1 failed, 0 unverified, 0 inexact (field not exact); {sum(r['seconds'] for r in rows):.1f} s of work"
    assert any(line.startswith("broken") and "failed" in line and "face index 3 out of range" in line for line in table)


def test_given_singularities_and_failures_per_mesh(cluster, meshes, tmp_path):
    folder, sings = meshes
    out = tmp_path / "out"
    paths = [str(folder / n) for n in ("torus.ply", "cube.obj", "eight.obj", "broken.obj")] + [str(folder / "missing.off")]
    rows = batch.run(paths, str(out), N=4, sing_dir=str(sings), scheduler=cluster.scheduler_address, progress=False)
    by_name = {r["mesh"]: r for r in rows}
    assert [r["mesh"] for r in rows] == ["torus", "cube", "eight", "broken", "missing"]
    assert by_name["cube"]["status"] == "ok" and by_name["cube"]["singularities"] == 8
    check_outputs(by_name["cube"], 4)
    assert by_name["cube"]["source"] == str(sings / "cube.sing")
    # Each failure carries the library's message: Gauss-Bonnet, an unreadable file, a missing one.
    assert by_name["torus"]["status"] == "failed"
    assert by_name["torus"]["message"] == "the indices on component 0 sum to 1, but Gauss-Bonnet needs its Euler characteristic 0"
    assert by_name["eight"]["message"] == "the indices on component 0 sum to 0, but Gauss-Bonnet needs its Euler characteristic -2"
    assert by_name["missing"]["message"] == library_message(trivcon.read_mesh, str(folder / "missing.off"))
    assert by_name["broken"]["status"] == "failed"
    assert not (out / "torus.field.txt").exists()


def test_command_line_local_cluster(meshes, tmp_path):
    """python -m trivcon.batch with its own local cluster of two workers: table, progress, exit status."""
    folder, _ = meshes
    out = tmp_path / "out"
    p = subprocess.run([sys.executable, "-m", "trivcon.batch", str(folder), "--out", str(out), "--workers", "2", "-N", "4",
                        "--field-format", "rawfield"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 1, p.stderr  # one mesh failed
    lines = p.stdout.splitlines()
    assert lines[0].split() == list(batch.COLUMNS)
    assert lines[-2].startswith("4 meshes: 3 ok, 1 failed, 0 unverified")
    assert lines[-1] == f"outputs and summary.json in {out}"
    assert "[" + "#" * 30 + "] 4/4 meshes, 1 failed" in p.stderr
    rows = json.loads((out / "summary.json").read_text())
    assert [r["status"] for r in rows] == ["failed", "ok", "ok", "ok"]
    assert len({r["worker"] for r in rows if r["status"] == "ok"}) >= 1
    assert (out / "cube.field.rawfield").exists()
    # All good: exit status 0.
    p = subprocess.run([sys.executable, "-m", "trivcon.batch", str(folder / "cube.obj"), "--out", str(tmp_path / "o2"), "--workers", "1",
                        "--no-progress"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert p.stderr.count("meshes,") == 0


def test_command_line_existing_scheduler(cluster, meshes, tmp_path):
    folder, sings = meshes
    p = subprocess.run([sys.executable, "-m", "trivcon.batch", str(folder / "cube.obj"), str(folder / "torus.ply"), "--out",
                        str(tmp_path / "out"), "--sing-dir", str(sings), "--scheduler", cluster.scheduler_address],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 1
    assert "2 meshes: 1 ok, 1 failed" in p.stdout
    assert "Gauss-Bonnet needs its Euler characteristic 0" in p.stdout


def test_usage_errors(meshes, tmp_path):
    folder, _ = meshes
    other = tmp_path / "other"
    other.mkdir()
    trivcon.write_mesh(str(other / "cube.obj"), *trivcon.make_icosphere(1))

    def run(*args):
        return subprocess.run([sys.executable, "-m", "trivcon.batch", *args], capture_output=True, text=True, timeout=120)

    p = run(str(folder / "cube.obj"), str(other / "cube.obj"), "--out", str(tmp_path / "o"))
    assert p.returncode == 2 and "two meshes have the name 'cube'" in p.stderr
    p = run(str(folder), "--out", str(tmp_path / "o"), "--sing-dir", str(tmp_path / "nowhere"))
    assert p.returncode == 2 and "is not a folder" in p.stderr
    p = run(str(tmp_path / "o"), "--out", str(tmp_path / "o2"))
    assert p.returncode == 2 and "holds no .obj, .off or .ply files" in p.stderr
    p = run(str(folder), "--out", str(tmp_path / "o"), "--scheduler", "tcp://127.0.0.1:9", "--timeout", "1")
    assert p.returncode == 2 and "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in p.stderr


@pytest.fixture
def coarse(tmp_path):
    """A coarse sphere with all of its index at one vertex (its connection turns by pi/4 or more there) and
    a cube whose corners read exactly: the first verifies but its field is not exact."""
    folder = tmp_path / "coarse"
    folder.mkdir()
    sings = tmp_path / "coarse_sings"
    sings.mkdir()
    trivcon.write_mesh(str(folder / "ball.obj"), *trivcon.make_icosphere(1))
    trivcon.write_singularities(str(sings / "ball.sing"), {0: 2}, N=4)
    cube = trivcon.make_cube_sphere(6, spherical=False)
    trivcon.write_mesh(str(folder / "cube.obj"), *cube)
    corners = [v for v in range(len(cube[0])) if (abs(abs(cube[0][v]) - 1) < 1e-12).all()]
    trivcon.write_singularities(str(sings / "cube.sing"), {v: "1/4" for v in corners}, N=4)
    return folder, sings


def test_a_field_that_is_not_exact_is_not_ok(cluster, coarse, tmp_path):
    folder, sings = coarse
    out = tmp_path / "out"
    rows = batch.run([str(folder)], str(out), N=4, sing_dir=str(sings), scheduler=cluster.scheduler_address, progress=False)
    ball, cube = rows
    # What a solve from Python says about the same prescription.
    V, F = trivcon.read_mesh(str(folder / "ball.obj"))
    r = trivcon.FieldDesigner(V, F).solve(N=4, singularities={0: 2})
    assert not r.field_exact and r.verified
    assert ball["status"] == "inexact" and ball["field_exact"] is False
    assert ball["large_turn_edges"] == r.large_turn_edges > 0 and ball["index_mismatches"] == len(r.index_mismatches)
    assert ball["message"].startswith(f"field not exact: {len(r.index_mismatches)} vertices read other indices")
    assert ball["message"].endswith("use --split-large-turns")
    # The field written reads other indices than the singularities written: exactly what field_exact says.
    directions, _ = trivcon.read_field(ball["outputs"][0], len(F))
    assert trivcon.field_indices(V, F, directions, N=4) != trivcon.read_singularities(ball["outputs"][1], N=4)
    assert cube["status"] == "ok" and cube["field_exact"] is True and cube["large_turn_edges"] == 0
    check_outputs(cube, 4)
    table = batch.format_table(rows).splitlines()
    assert table[0].split() == list(batch.COLUMNS) and "field_exact" in batch.COLUMNS and "large_turn_edges" in batch.COLUMNS
    ball_line = next(line for line in table if line.startswith("ball"))
    assert ball_line.split()[1:9] == ["inexact", str(len(V)), str(len(F)), "2", "4", "1", "NO", str(r.large_turn_edges)]
    assert next(line for line in table if line.startswith("cube")).split()[7:9] == ["yes", "0"]
    assert table[-1].startswith("2 meshes: 1 ok, 0 failed, 0 unverified, 1 inexact (field not exact); ")


def check_refined_outputs(row, mesh_path, N):
    """--split-large-turns: the field belongs to the refined mesh written beside it, reads exactly the
    singularities written, and parent_face.txt maps its faces to the input's."""
    field, sing, mesh, parents = row["outputs"]
    assert os.path.basename(mesh) == f"{row['mesh']}.mesh.obj" and os.path.basename(parents) == f"{row['mesh']}.parent_face.txt"
    V0, F0 = trivcon.read_mesh(mesh_path)
    V, F = trivcon.read_mesh(mesh)
    directions, file_N = trivcon.read_field(field, len(F))
    assert file_N == N
    assert trivcon.field_indices(V, F, directions, N=N) == trivcon.read_singularities(sing, N=N)
    parent = np.loadtxt(parents, dtype=np.int64, ndmin=1)
    assert parent.shape == (len(F),) and parent.min() >= 0 and parent.max() < len(F0)
    assert np.array_equal(V[: len(V0)], V0) and np.array_equal(parent[: len(F0)], np.arange(len(F0)))  # ids kept
    # Each refined face lies in the plane of its input face.
    n = np.cross(V0[F0[parent, 1]] - V0[F0[parent, 0]], V0[F0[parent, 2]] - V0[F0[parent, 0]])
    for c in range(3):
        assert np.abs(np.einsum("ij,ij->i", V[F[:, c]] - V0[F0[parent, 0]], n)).max() < 1e-12
    assert row["split_large_turns"]["faces"] == len(F) and row["split_large_turns"]["vertices"] == len(V)
    return parent


def test_split_large_turns(cluster, coarse, tmp_path):
    folder, sings = coarse
    out = tmp_path / "out"
    rows = batch.run([str(folder)], str(out), N=4, sing_dir=str(sings), scheduler=cluster.scheduler_address, progress=False,
                     split_large_turns=True)
    ball, cube = rows
    assert ball["status"] == "ok" and ball["field_exact"] is True and ball["large_turn_edges"] == 0 and ball["message"] == ""
    assert ball["split_large_turns"]["rounds"] >= 1 and ball["split_large_turns"]["converged"] is True
    parent = check_refined_outputs(ball, str(folder / "ball.obj"), 4)
    # The same as a split solve from Python.
    r = trivcon.FieldDesigner(*trivcon.read_mesh(str(folder / "ball.obj"))).solve(N=4, singularities={0: 2}, split_large_turns=True)
    assert np.array_equal(parent, r.parent_face)
    # A mesh that needed no refinement: its own mesh, every face its own parent.
    assert cube["status"] == "ok" and cube["split_large_turns"]["rounds"] == 0
    cube_parent = check_refined_outputs(cube, str(folder / "cube.obj"), 4)
    assert np.array_equal(cube_parent, np.arange(len(cube_parent)))
    assert batch.format_table(rows).splitlines()[-1].startswith("2 meshes: 2 ok, 0 failed, 0 unverified, 0 inexact")


def test_command_line_split_large_turns(coarse, tmp_path):
    folder, sings = coarse
    args = [sys.executable, "-m", "trivcon.batch", str(folder / "ball.obj"), "--sing-dir", str(sings), "--workers", "1", "--no-progress"]
    p = subprocess.run(args + ["--out", str(tmp_path / "plain")], capture_output=True, text=True, timeout=300)
    assert p.returncode == 1, p.stderr  # the field is not exact: not ok
    assert p.stdout.splitlines()[-2].startswith("1 meshes: 0 ok, 0 failed, 0 unverified, 1 inexact")
    p = subprocess.run(args + ["--out", str(tmp_path / "split"), "--split-large-turns"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert p.stdout.splitlines()[-2].startswith("1 meshes: 1 ok, 0 failed, 0 unverified, 0 inexact")
    row = json.loads((tmp_path / "split" / "summary.json").read_text())[0]
    assert row["field_exact"] is True and row["large_turn_edges"] == 0
    check_refined_outputs(row, str(folder / "ball.obj"), 4)
    assert "--split-large-turns" in subprocess.run([sys.executable, "-m", "trivcon.batch", "--help"], capture_output=True,
                                                   text=True).stdout
