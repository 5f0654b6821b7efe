# SPDX-License-Identifier: MIT
"""Solve many meshes on a Dask cluster: python3 -m trivcon.batch MESH... --out DIR.

    python3 -m trivcon.batch meshes/*.obj --out results -N 4                  # automatic singularities
    python3 -m trivcon.batch meshes/ --out results -N 4 --sing-dir sings/     # sings/NAME.sing per mesh
    python3 -m trivcon.batch meshes/ --out results --scheduler tcp://host:8786   # an existing cluster

Each mesh (a file, or every .obj/.off/.ply[.gz] file of a folder) is one task: read, FieldDesigner, solve
(its singularities from --sing-dir, else those of the smoothest field as with `trivcon solve --auto`), write
DIR/NAME.field.txt (--field-format), DIR/NAME.sing (the singularities used) and, when asked, the connection
and a picture. NAME is the file name without its extensions. With --split-large-turns each mesh is refined
where the connection turns by pi/N or more and solved again (as `trivcon solve --split-large-turns`), so that
the field read on its own shows exactly the singularities; the field then belongs to the refined mesh, which
is written beside it (DIR/NAME.mesh.obj, input vertices and faces keeping their ids) with DIR/NAME.parent_face.txt
(the input face of each of its faces, one per line). By default the tasks run on a local cluster of
worker processes (--workers, default one per core, each on one thread); --scheduler sends them to a running
Dask scheduler instead (`dask scheduler` on one machine, `dask worker tcp://host:8786` on each of the
others, trivcon installed on every worker), which then must see the meshes and DIR at the same paths (a
shared file system): paths are made absolute before they are sent.

A failing mesh (an unreadable file, a non-manifold mesh, a prescription that violates Gauss-Bonnet, a worker
that died) is reported and never stops the others. While it runs, a progress bar goes to stderr; at the end a
summary table goes to stdout and to DIR/summary.txt, and every row (with the full error messages) to
DIR/summary.json. A mesh's status is "ok" when it solved, verified and its field is exact (field_exact: the
per-face field read on its own shows exactly the prescribed singularities), "inexact" when it verified but
its field reads other indices at some vertices (large turns, large_turn_edges > 0: use --split-large-turns),
"unverified" when the verification failed, "failed" when it did not solve. Exit status: 0 when every mesh is
ok, 1 otherwise, 2 for a usage error.

From Python: trivcon.batch.run(meshes, out, ...) returns the rows (a list of dicts, in the order of the
meshes); trivcon.batch.solve_mesh(job) is the task itself.
"""

import argparse
import json
import os
import sys
import time
import warnings

__all__ = ["run", "solve_mesh", "find_meshes", "format_table", "main"]

MESH_SUFFIXES = (".obj", ".off", ".ply", ".stl", ".gltf", ".glb")
FIELD_FORMATS = ("txt", "rawfield", "ply")
COLUMNS = ("mesh", "status", "vertices", "faces", "chi", "N", "singularities", "field_exact", "large_turn_edges", "energy", "residual",
           "seconds", "message")
STATUSES = ("ok", "inexact", "unverified", "failed")


class UsageError(Exception):
    """A problem with the arguments (exit status 2)."""


def _is_mesh(path):
    p = path.lower()
    if p.endswith(".gz"):
        p = p[:-3]
    return p.endswith(MESH_SUFFIXES)


def mesh_name(path):
    """The file name without .gz and the mesh extension: meshes/bunny.obj.gz -> bunny."""
    name = os.path.basename(path)
    if name.lower().endswith(".gz"):
        name = name[:-3]
    root, ext = os.path.splitext(name)
    return root if ext.lower() in MESH_SUFFIXES else name


def find_meshes(paths):
    """Absolute paths of the meshes named: files as given, folders by their mesh files (sorted)."""
    meshes = []
    for p in paths:
        if os.path.isdir(p):
            found = sorted(os.path.join(p, f) for f in os.listdir(p) if _is_mesh(f) and os.path.isfile(os.path.join(p, f)))
            if not found:
                raise UsageError(f"the folder {p} holds no .obj, .off or .ply files")
            meshes += found
        else:
            meshes.append(p)  # a missing or unreadable file fails as its own task, with the reader's message
    return [os.path.abspath(m) for m in meshes]


def _jobs(meshes, out, N, sing_dir, auto_cancel, align_boundary, weights, field_format, connection, png, split_large_turns=False,
          threads=None, repair=True):
    jobs, names = [], {}
    for mesh in meshes:
        name = mesh_name(mesh)
        if name in names:
            raise UsageError(f"two meshes have the name '{name}' ({names[name]} and {mesh}): their outputs would collide")
        names[name] = mesh
        sing = None
        if sing_dir is not None:
            sing = os.path.join(sing_dir, name + ".sing")
            if not os.path.exists(sing) and os.path.exists(os.path.join(sing_dir, name + ".sings")):
                sing = os.path.join(sing_dir, name + ".sings")
        jobs.append({
            "mesh": mesh,
            "name": name,
            "out": out,
            "N": N,
            "sing_file": sing,
            "auto_cancel": auto_cancel,
            "align_boundary": align_boundary,
            "weights": weights,
            "field_format": field_format,
            "connection": connection,
            "png": png,
            "split_large_turns": split_large_turns,
            "threads": threads,
            "repair": repair,
        })
    return jobs


def _worker_name():
    try:
        from distributed import get_worker

        return get_worker().address
    except Exception:  # not on a Dask worker (e.g. called directly)
        return f"pid {os.getpid()}"


def solve_mesh(job):
    """One task: solve job["mesh"] and write its outputs into job["out"]; returns its summary row.

    Never raises for a problem of the mesh or its singularities: the row's status is then "failed" and
    its message the library's error message. Keys of job: mesh, name, out, N, sing_file (None: automatic),
    auto_cancel, align_boundary, weights, field_format, connection, png, and optionally split_large_turns
    (refine where the connection turns by pi/N or more; writes the refined mesh and its parent faces too)
    threads (the designer's, None: trivcon's default) and repair (default True: a mesh that is not manifold is
    repaired, FieldDesigner(repair=...), and the row's "repair" says what was done).
    """
    import trivcon

    t0 = time.perf_counter()
    row = {"mesh": job["name"], "path": job["mesh"], "status": "failed", "N": job["N"], "message": "", "worker": _worker_name()}
    try:
        V, F = trivcon.read_mesh(job["mesh"])
        row["vertices"], row["faces"] = int(V.shape[0]), int(F.shape[0])
        with warnings.catch_warnings():  # what repair did goes into the row
            warnings.simplefilter("ignore", UserWarning)
            d = trivcon.FieldDesigner(V, F, weights=job["weights"], threads=job.get("threads"), repair=job.get("repair", True))
        if d.repair is not None:
            row["repair"] = d.repair["summary"]
        row["chi"] = d.euler_characteristic
        split = bool(job.get("split_large_turns"))
        if job["sing_file"] is not None:
            if not os.path.exists(job["sing_file"]):
                raise trivcon.Error(f"no singularity file {job['sing_file']}")
            sings = trivcon.read_singularities(job["sing_file"], job["N"])
            r = d.solve(N=job["N"], singularities=sings, align_boundary=job["align_boundary"], split_large_turns=split)
            row["source"] = job["sing_file"]
        else:
            r = d.solve(N=job["N"], singularities="auto", auto_cancel=job["auto_cancel"], align_boundary=job["align_boundary"],
                        split_large_turns=split)
            row["source"] = "auto"
            row["auto_found"], row["auto_cancelled_pairs"] = len(r.auto.found), len(r.auto.pairs)
        base = os.path.join(job["out"], job["name"])
        outputs = [f"{base}.field.{job['field_format']}", base + ".sing"]
        r.write_field(outputs[0])
        r.write_singularities(outputs[1])
        if split:
            # The field is per face of the refined mesh: that mesh, and the input face of each of its faces.
            outputs += [base + ".mesh.obj", base + ".parent_face.txt"]
            r.write_mesh(outputs[-2])
            _write_parent_faces(outputs[-1], r.parent_face, job["mesh"])
            row["split_large_turns"] = {"rounds": len(r.split_rounds), "converged": bool(r.split_converged),
                                        "vertices": r.designer.num_vertices, "faces": r.designer.num_faces}
        if job["connection"]:
            outputs.append(base + ".connection.txt")
            r.write_connection(outputs[-1])
            if d.repair is not None and not split:  # its edges are the repaired mesh's vertex pairs: that mesh beside it
                outputs.append(base + ".mesh.obj")
                r.write_mesh(outputs[-1])
        if job["png"]:
            outputs.append(base + ".png")
            trivcon.write_png(outputs[-1], r.render(size=(800, 600)))
        row.update({
            "status": "ok" if r.verified and r.field_exact else "inexact" if r.verified else "unverified",
            "singularities": len(r.singularities),
            "field_exact": bool(r.field_exact),
            "large_turn_edges": int(r.large_turn_edges),
            "index_mismatches": int(len(r.index_mismatches)),
            "energy": r.energy,
            "residual": r.residual,
            "transport_mismatch": r.transport_mismatch,
            "outputs": outputs,
        })
        if not r.verified:
            row["message"] = (f"verification failed: residual {r.residual:.3g}, transport mismatch {r.transport_mismatch:.3g}, "
                              f"{len(r.unexplained_mismatches)} unexplained index mismatches")
        elif not r.field_exact:
            k = len(r.index_mismatches)
            row["message"] = (f"field not exact: {k} {'vertex reads another index' if k == 1 else 'vertices read other indices'} "
                              f"({r.large_turn_edges} edges turn by pi/N or more); "
                              + ("--split-large-turns left large turns" if split else "use --split-large-turns"))
    except trivcon.Error as e:
        row["message"] = str(e)
    except MemoryError:
        row["message"] = "out of memory"
    except Exception as e:  # a bug: reported like the CLI's exit status 70, and the batch goes on
        row["message"] = f"internal error: {type(e).__name__}: {e}"
    row["seconds"] = time.perf_counter() - t0
    return row


def _write_parent_faces(path, parent_face, mesh):
    """The input face of each face of the refined mesh, one per line after a comment, atomically."""
    temporary = os.path.join(os.path.dirname(path), ".trivcon-partial." + os.path.basename(path))
    with open(temporary, "w") as f:
        f.write(f"# trivcon parent faces: the face of {os.path.basename(mesh)} each face of the refined mesh comes from\n")
        f.write(f"# {len(parent_face)} faces\n")
        f.write("\n".join(str(int(p)) for p in parent_face))
        f.write("\n")
    os.replace(temporary, path)


class Progress:
    """A progress bar on a stream: redrawn in place on a terminal, one line per finished mesh otherwise."""

    def __init__(self, total, stream=None, width=30):
        self.total, self.done, self.failed, self.not_ok = total, 0, 0, 0
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.start = time.perf_counter()

    def line(self, last=""):
        filled = self.width * self.done // max(self.total, 1)
        bar = "#" * filled + "-" * (self.width - filled)
        other = f", {self.not_ok - self.failed} not ok" if self.not_ok > self.failed else ""
        text = f"[{bar}] {self.done}/{self.total} meshes, {self.failed} failed{other}, {time.perf_counter() - self.start:.1f} s"
        return text + (f"  {last}" if last else "")

    def update(self, row):
        self.done += 1
        self.failed += row["status"] == "failed"
        self.not_ok += row["status"] != "ok"
        last = f"{row['mesh']}: {row['status']}"
        if self.tty:
            self.stream.write("\r\033[K" + self.line(last))
            if self.done == self.total:
                self.stream.write("\n")
        else:
            self.stream.write(self.line(last) + "\n")
        self.stream.flush()


def _cell(row, key):
    v = row.get(key)
    if v is None:
        return ""
    if key == "field_exact":
        return "yes" if v else "NO"
    if key in ("energy",):
        return f"{v:.6g}"
    if key == "residual":
        return f"{v:.2e}"
    if key == "seconds":
        return f"{v:.2f}"
    if key == "message":
        return str(v).replace("\n", " ")
    return str(v)


def format_table(rows):
    """The summary table: one line per mesh (mesh, status, sizes, chi, N, singularities, field_exact,
    large_turn_edges, energy, residual, seconds, message), then a total line."""
    cells = [list(COLUMNS)] + [[_cell(r, k) for k in COLUMNS] for r in rows]
    widths = [max(len(c[i]) for c in cells) for i in range(len(COLUMNS))]
    numeric = {"vertices", "faces", "chi", "N", "singularities", "large_turn_edges", "energy", "residual", "seconds"}
    lines = []
    for n, c in enumerate(cells):
        parts = [(s.rjust(w) if COLUMNS[i] in numeric else s.ljust(w)) for i, (s, w) in enumerate(zip(c, widths))]
        lines.append("  ".join(parts).rstrip())
        if n == 0:
            lines.append("  ".join("-" * w for w in widths))
    count = {s: sum(r["status"] == s for r in rows) for s in STATUSES}
    total = sum(r.get("seconds") or 0 for r in rows)
    lines.append(f"{len(rows)} meshes: {count['ok']} ok, {count['failed']} failed, {count['unverified']} unverified, "
                 f"{count['inexact']} inexact (field not exact); {total:.1f} s of work")
    return "\n".join(lines)


def _failed_row(job, message):
    return {"mesh": job["name"], "path": job["mesh"], "status": "failed", "N": job["N"], "message": message, "seconds": None}


def run(meshes, out, N=4, sing_dir=None, auto_cancel=0.0, align_boundary=False, weights="cotan", field_format="txt",
        connection=False, png=False, scheduler=None, workers=None, threads_per_worker=1, progress=True, stream=None, timeout=30,
        split_large_turns=False, threads=None, repair=True):
    """Solve every mesh on a Dask cluster and write the outputs into `out`; returns the rows, in mesh order.

    meshes: mesh files and folders (all their mesh files). sing_dir: a folder with NAME.sing (or NAME.sings)
    per mesh; None: automatic singularities (auto_cancel: their cancel distance in mean edge lengths).
    split_large_turns: refine each mesh where the connection turns by pi/N or more (FieldDesigner.solve's
    split_large_turns) and write NAME.mesh.obj and NAME.parent_face.txt beside the field.
    repair: repair meshes that are not manifold (FieldDesigner's repair; default True); the row says what was done.
    threads: threads per mesh (None: with a local cluster the cores shared out among its workers, one at
    least; with a scheduler each worker's trivcon default).
    Rows have the keys of COLUMNS (field_exact, large_turn_edges, ...), status one of STATUSES.
    scheduler: the address of a running Dask scheduler (e.g. "tcp://host:8786"); None: a local cluster of
    `workers` processes (default: one per core, at most one per mesh) with `threads_per_worker` threads.
    timeout: seconds to wait for the scheduler. progress: draw a progress bar on `stream` (default stderr).
    Also writes out/summary.json and
    out/summary.txt. Raises UsageError for bad arguments (nothing is solved then).
    """
    from distributed import Client, LocalCluster, as_completed

    if field_format not in FIELD_FORMATS:
        raise UsageError(f"--field-format must be one of {', '.join(FIELD_FORMATS)}, not {field_format!r}")
    if weights not in ("cotan", "unit"):
        raise UsageError(f"--weights must be cotan or unit, not {weights!r}")
    if isinstance(N, bool) or not isinstance(N, int) or N < 1:
        raise UsageError(f"-N must be an integer >= 1, not {N!r}")
    if sing_dir is not None and not os.path.isdir(sing_dir):
        raise UsageError(f"--sing-dir {sing_dir} is not a folder")
    out = os.path.abspath(out)
    os.makedirs(out, exist_ok=True)
    if threads is not None and (isinstance(threads, bool) or not isinstance(threads, int) or threads < 1):
        raise UsageError(f"--threads must be an integer >= 1, not {threads!r}")
    jobs = _jobs(find_meshes(meshes), out, N, None if sing_dir is None else os.path.abspath(sing_dir), float(auto_cancel),
                 bool(align_boundary), weights, field_format, bool(connection), bool(png), bool(split_large_turns), threads,
                 bool(repair))
    if not jobs:
        raise UsageError("no meshes given")

    cluster = None
    if scheduler:
        try:
            client = Client(scheduler, timeout=f"{float(timeout)}s")
        except (OSError, TimeoutError) as e:
            raise UsageError(f"cannot reach the Dask scheduler at {scheduler}: {e}") from None
    else:
        n = workers or min(len(jobs), os.cpu_count() or 1)
        if threads is None:  # the cores shared out: workers on all cores each would fight over them
            for job in jobs:
                job["threads"] = max(1, (os.cpu_count() or 1) // (n * max(1, threads_per_worker)))
        cluster = LocalCluster(n_workers=n, threads_per_worker=threads_per_worker, processes=True, dashboard_address=None)
        client = Client(cluster)
    rows = [None] * len(jobs)
    bar = Progress(len(jobs), stream) if progress else None
    try:
        # By its module's name, so that workers can import it also when this file runs as __main__ (-m).
        from trivcon.batch import solve_mesh as task

        futures = {client.submit(task, job, pure=False): i for i, job in enumerate(jobs)}
        for future in as_completed(futures):
            i = futures[future]
            try:
                row = future.result()
            except Exception as e:  # the task itself died (e.g. its worker was killed): that mesh fails
                row = _failed_row(jobs[i], f"task failed: {type(e).__name__}: {e}")
            rows[i] = row
            if bar:
                bar.update(row)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

    table = format_table(rows)
    with open(os.path.join(out, "summary.txt"), "w") as f:
        f.write(table + "\n")
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(rows, f, indent=2)
        f.write("\n")
    return rows


def main(argv=None):
    """The command line (python3 -m trivcon.batch --help)."""
    parser = argparse.ArgumentParser(
        prog="python3 -m trivcon.batch",
        description="Solve many meshes with trivcon on a Dask cluster (a local one by default): automatic singularities, "
        "or one singularity file per mesh. Prints a summary table; exit status 0 when every mesh solved, verified and "
        "its field is exact (status ok).")
    parser.add_argument("meshes", nargs="+", help="mesh files (.obj .off .ply .stl .gltf .glb, optionally .gz) or folders of them")
    parser.add_argument("--out", required=True, help="output folder: NAME.field.txt, NAME.sing, summary.txt, summary.json "
                        "(and NAME.mesh.obj, NAME.parent_face.txt with --split-large-turns)")
    parser.add_argument("-N", "--symmetry", type=int, default=4, help="symmetry N (default 4: cross fields)")
    parser.add_argument("--sing-dir", help="folder with NAME.sing (or Directional's NAME.sings) per mesh; default: automatic")
    parser.add_argument("--auto-cancel", type=float, default=0.0,
                        help="automatic: cancel opposite pairs at most D mean edge lengths apart")
    parser.add_argument("--align-boundary", action="store_true", help="fix every boundary face to its boundary edge")
    parser.add_argument("--weights", choices=("cotan", "unit"), default="cotan")
    parser.add_argument("--field-format", choices=FIELD_FORMATS, default="txt", help="field file format (default txt)")
    parser.add_argument("--connection", action="store_true", help="also write NAME.connection.txt")
    parser.add_argument("--png", action="store_true", help="also write NAME.png (800x600)")
    parser.add_argument("--split-large-turns", action="store_true",
                        help="refine each mesh where the connection turns by pi/N or more, so that the field read on its own shows "
                        "exactly the singularities; writes the refined mesh NAME.mesh.obj and NAME.parent_face.txt beside the field")
    parser.add_argument("--threads", type=int, help="threads per mesh (default: the cores shared out among local workers)")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786 (default: a local cluster)")
    parser.add_argument("--timeout", type=float, default=30, help="seconds to wait for the scheduler (default 30)")
    parser.add_argument("--workers", type=int, help="local cluster: worker processes (default: one per core)")
    parser.add_argument("--threads-per-worker", type=int, default=1, help="local cluster: threads per worker (default 1)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--no-repair", action="store_true",
                        help="refuse meshes that are not manifold instead of repairing them (the row says what repair did)")
    a = parser.parse_args(argv)
    if a.auto_cancel and a.sing_dir:
        parser.error("--auto-cancel applies to automatic singularities, not with --sing-dir")
    if a.workers is not None and a.workers < 1:
        parser.error("--workers must be at least 1")
    if a.scheduler and a.workers:
        parser.error("--workers is for the local cluster, not with --scheduler")
    if a.threads is not None and a.threads < 1:
        parser.error("--threads must be at least 1")
    try:
        rows = run(a.meshes, a.out, N=a.symmetry, sing_dir=a.sing_dir, auto_cancel=a.auto_cancel, align_boundary=a.align_boundary,
                   weights=a.weights, field_format=a.field_format, connection=a.connection, png=a.png, scheduler=a.scheduler,
                   workers=a.workers, threads_per_worker=a.threads_per_worker, progress=not a.no_progress, timeout=a.timeout,
                   split_large_turns=a.split_large_turns, threads=a.threads, repair=not a.no_repair)
    except UsageError as e:
        parser.error(str(e))
    print(format_table(rows))
    print(f"outputs and summary.json in {os.path.abspath(a.out)}")
    return 0 if all(r["status"] == "ok" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
