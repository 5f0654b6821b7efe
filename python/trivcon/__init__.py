# SPDX-License-Identifier: MIT
"""trivcon: direction fields on triangle meshes with exactly the singularities you ask for.

Vector fields (N = 1), line fields (N = 2), cross fields (N = 4), any N: the trivial connection closest
to Levi-Civita (Crane, Desbrun & Schroeder, "Trivial Connections on Discrete Surfaces", SGP 2010), the
same C++ library as the `trivcon` command line. Plain numpy arrays in, plain arrays out:

    import trivcon
    V, F = trivcon.read_mesh("mesh.obj")         # float64 (n, 3), int64 (m, 3): the file's own ids
    d = trivcon.FieldDesigner(V, F)              # validates and factors once
    r = d.solve(N=4, singularities={12: "1/4", 40: -0.25, ...})   # milliseconds per re-solve
    r.directions, r.angles, r.connection, r.edges, r.energy, r.residual, r.singularities
    r.verified, r.field_exact                    # the connection checks; the per-face field reads exactly
    r2 = d.solve(N=4, singularities="auto")      # the singularities of the smoothest cross field
    trivcon.field_indices(V, F, r.directions, N=4)          # {vertex: Fraction}, of any tool's field
    trivcon.write_field("f.rawfield", V, F, r.directions, N=4)
    image = trivcon.render(V, F, r.directions, N=4, size=(800, 600))   # (600, 800, 3) uint8

Conventions (the CLI's, see docs/explanation/conventions.md):
- Ids are the file's own, 0-based; nothing is renumbered. Polygons are fan-triangulated in order.
- Indices are exact multiples of 1/N. They are given as int, float (a multiple of 1/N),
  fractions.Fraction or "p/q" strings, and returned as fractions.Fraction; or as arrays: a tuple
  (vertex ids, numerators) of two 1-D integer numpy arrays, index = numerator / N, in and out
  (Result.singularity_arrays, field_indices(..., arrays=True)).
- Orientation: FieldDesigner re-orients a component whose faces disagree (flipping the smaller class);
  FieldDesigner.F is the oriented copy, and face frames, normals and angles refer to it.
- Face frames: face f's x axis runs along its first edge (corner 0 -> corner 1 of the oriented face), the
  y axis is normal x x_axis, angles increase counter-clockwise about the normal (p1 - p0) x (p2 - p0).
  A field's angle a at face f is the world direction cos(a) X[f] + sin(a) Y[f]; its N directions are
  a + 2 pi k / N (all of them: Result.all_directions()).
- Edges (i, j) have i < j, sorted by (i, j); face L holds the half-edge i -> j, R the half-edge j -> i.
  A direction at angle b in L is carried to b + rho - x in R (x: the connection, radians).
- Arrays: V accepts any real dtype, F any integer dtype (both any layout, (n, 3) and (m, 3));
  directions are (m, 3) world vectors. Outputs are float64 and int64 arrays. The arrays of a
  FieldDesigner, Result and AutoResult are computed once and read-only (copy one to change it); those
  that functions return (read_mesh, make_*, render, ...) are new and yours.

Every error -- a bad array, a bad index, and every error of the library (a bad file, a non-manifold mesh,
a prescription violating Gauss-Bonnet, ...) -- raises trivcon.Error, a ValueError whose message is the
one the CLI prints after "trivcon: error: ".

Long calls release the GIL and stop on Ctrl-C: KeyboardInterrupt is raised within about 20 ms (the
abandoned work stops at its next safe point, within a fraction of a second, and frees what it built).
Threads: FieldDesigner(threads=k), trivcon.set_threads(k) or the environment variable TRIVCON_THREADS
(see set_threads). FieldDesigner, Result and AutoResult pickle (a FieldDesigner is rebuilt from its mesh
and options when unpickled, and factored again on its first solve), so they come back from
multiprocessing and Dask workers.

Batches of meshes on a Dask cluster: python3 -m trivcon.batch --help (trivcon/batch.py).
"""

import atexit as _atexit
import math as _math
import numbers as _numbers
import os as _os
import re as _re
import warnings as _warnings
from collections.abc import Mapping as _Mapping
from fractions import Fraction as _Fraction

import numpy as _np

from . import _core

__version__ = _core.__version__
# Whether solver="qr" and factorization="cholmod" are in this build: they need SuiteSparseQR and CHOLMOD (GPL),
# which the default build does not link; asking for them otherwise raises trivcon.Error saying so.
with_suitesparse = bool(_core.with_suitesparse)

__all__ = [
    "Error",
    "FieldDesigner",
    "Result",
    "AutoResult",
    "RelaxResult",
    "Parametrization",
    "QuadMesh",
    "read_mesh",
    "write_mesh",
    "field_indices",
    "read_field",
    "write_field",
    "read_singularities",
    "write_singularities",
    "render",
    "write_png",
    "make_icosphere",
    "make_uv_sphere",
    "make_cube_sphere",
    "make_torus",
    "make_genus_surface",
    "make_disk",
    "make_annulus",
    "make_holed_grid",
    "blas_kernels",
    "set_threads",
    "get_threads",
    "batch",
    "with_suitesparse",
]

Error = _core.Error
Error.__module__ = "trivcon"
Error.__doc__ = """Every error trivcon reports: a ValueError whose message names the problem and where.

Library errors carry the message the CLI prints after "trivcon: error: " (e.g. "mesh.obj:12: face
index 40 out of range (file has 39 vertices)", "singular vertex 7 is on boundary loop 0: ...", "the
indices on component 0 sum to 3/2, but Gauss-Bonnet needs its Euler characteristic 2"); array
errors name the array and its shape or dtype (e.g. "V must have shape (n, 3), got shape (8, 2)")."""

_INT32_MAX = 2**31 - 1
_MAX_INDEX_PART = 10**9  # the library's bound on p and q of an index "p/q" (src/connection/indices.cpp)
_INDEX_TEXT = _re.compile(r"\s*([+-]?[0-9]+)(?:/([+-]?[0-9]+))?\s*\Z")


# ---------------------------------------------------------------------------------------------------------
# Arrays in and out


def _frozen(a):
    """`a` made read-only (the arrays an object hands out are views of what it keeps)."""
    a.flags.writeable = False
    return a


class _Cached:
    """The values an object hands out, computed once per key and kept in self._cache (arrays made read-only)."""

    def _get(self, key, compute):
        if key not in self._cache:
            value = compute()
            if isinstance(value, _np.ndarray):
                value = _frozen(value)
            elif isinstance(value, tuple):
                value = tuple(_frozen(a) if isinstance(a, _np.ndarray) else a for a in value)
            self._cache[key] = value
        return self._cache[key]


def _array(value, name):
    try:
        return _np.asarray(value)
    except (ValueError, TypeError) as e:
        raise Error(f"{name} must be an array: {e}") from None


def _shape_text(shape):
    return "(" + ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"


def _short(value):
    """The text of a number for a message: as written when short, else about 10 significant characters."""
    if isinstance(value, str):
        text = value.strip()
        return text if len(text) <= 24 else text[:20] + "..."
    text = repr(value) if isinstance(value, float) else str(value)
    if len(text) <= 24:
        return text
    try:
        return f"{float(value):.6g}"
    except OverflowError:  # beyond a float: the power of ten
        f = _Fraction(value)
        exponent = len(str(abs(f.numerator))) - len(str(f.denominator))
        return f"{'-' if f < 0 else ''}~1e+{exponent}"


def _vectors(value, name, rows=None, rows_text="n"):
    """float64 C-contiguous (rows, 3) copy or view of a real array; trivcon.Error naming `name` otherwise."""
    a = _array(value, name)
    if a.ndim != 2 or a.shape[1] != 3 or (rows is not None and a.shape[0] != rows):
        want = f"({rows_text}, 3)" if rows is None else f"({rows}, 3)"
        raise Error(f"{name} must have shape {want}, got shape {_shape_text(a.shape)}")
    if a.dtype.kind not in "fiu":
        raise Error(f"{name} must hold real numbers, got dtype {a.dtype}")
    return _np.ascontiguousarray(a, dtype=_np.float64)


def _vertices(V):
    return _vectors(V, "V")


def _faces(F, num_vertices):
    """int32 C-contiguous (m, 3) copy of an integer array (ids checked by the library)."""
    a = _array(F, "F")
    if a.ndim != 2 or a.shape[1] != 3:
        raise Error(f"F must have shape (m, 3), got shape {_shape_text(a.shape)}")
    if a.dtype.kind not in "iu":
        raise Error(f"F must hold integers, got dtype {a.dtype}")
    if a.size and (int(a.min()) < -_INT32_MAX or int(a.max()) > _INT32_MAX):
        # Beyond what the library's int ids hold: report the first bad face as the library would.
        for f in range(a.shape[0]):
            row = [int(i) for i in a[f]]
            for i in row:
                if i < 0 or i >= num_vertices:
                    raise Error(f"vertex index {i} out of range in face {f} (mesh has {num_vertices} vertices)")
            if len(set(row)) < 3:
                raise Error(f"face {f} has a repeated vertex ({row[0]}, {row[1]}, {row[2]})")
    return _np.ascontiguousarray(a, dtype=_np.int32)


def _mesh(V, F):
    V = _vertices(V)
    return V, _faces(F, V.shape[0])


def _directions(directions, num_faces):
    return _vectors(directions, "directions", rows=num_faces)


def _symmetry(N):
    if isinstance(N, bool) or not isinstance(N, _numbers.Integral):
        raise Error(f"N must be an integer, got {_short(N) if isinstance(N, _numbers.Number) else repr(N)}")
    N = int(N)
    if N < 1:
        raise Error(f"the symmetry N must be at least 1 (got {_short(N)})")
    if N > _INT32_MAX:
        raise Error(f"the symmetry N = {_short(N)} is too large (at most {_INT32_MAX})")
    return N


def _id(key, what):
    if isinstance(key, bool) or not isinstance(key, _numbers.Integral):
        raise Error(f"{what}: ids must be integers, got {_short(key) if isinstance(key, _numbers.Number) else repr(key)}")
    key = int(key)
    if abs(key) > _INT32_MAX:
        raise Error(f"{what}: id {_short(key)} out of range")
    return key


def _too_large(value, N, where):
    limit = min(_MAX_INDEX_PART, _INT32_MAX // N)
    return Error(f"{where}: index {_short(value)} is too large (|index| at most {limit} with N = {N})")


def _numerator(value, N, where):
    """n (the index is n/N) of an index given as int, float, Fraction or "p/q"; errors start with `where`.

    Strings go through the library's parser (the one behind --sing, with its messages) once their size is
    known to fit; every form of a number too large for the library's int indices gets the same message."""
    if isinstance(value, bool):
        raise Error(f"{where}: an index must be an int, a float, a fractions.Fraction or a 'p/q' string, not a bool")
    limit = _Fraction(min(_MAX_INDEX_PART, _INT32_MAX // N))
    if isinstance(value, str):
        m = _INDEX_TEXT.match(value)
        if m:
            p, q = int(m.group(1)), int(m.group(2) or 1)
            if q > 0 and (abs(p) > _MAX_INDEX_PART or q > _MAX_INDEX_PART or abs(_Fraction(p, q)) > limit):
                raise _too_large(value, N, where)
        elif len(value.strip()) > 24:  # the library would quote all of it
            raise Error(f"{where}: malformed index '{_short(value)}' (expected an integer or a fraction p/q, q > 0)")
        return _core.parse_index(value, N, where)
    if isinstance(value, _numbers.Rational):  # int, numpy integers, Fraction
        f = _Fraction(int(value.numerator), int(value.denominator))
        if abs(f) > limit:
            raise _too_large(value, N, where)
        n = f * N
        if n.denominator != 1:
            raise Error(f"{where}: index {_short(f)} is not a multiple of 1/{N} (use -N to change the symmetry)")
        return int(n)
    if isinstance(value, _numbers.Real):
        v = float(value)
        if not _math.isfinite(v):
            raise Error(f"{where}: index {v!r} is not finite")
        if abs(v) > limit:
            raise _too_large(v, N, where)
        n = round(v * N)
        if abs(v * N - n) > 1e-9 * max(1.0, abs(v * N)):
            raise Error(f"{where}: index {v!r} is not a multiple of 1/{N}")
        return n
    raise Error(f"{where}: an index must be an int, a float, a fractions.Fraction or a 'p/q' string, not {type(value).__name__}")


def _is_arrays(value):
    """Whether `value` is the arrays form of indices: a tuple (ids, numerators) of two numpy arrays."""
    return isinstance(value, tuple) and len(value) == 2 and all(isinstance(a, _np.ndarray) for a in value)


def _items(mapping, what):
    if mapping is None:
        return []
    if isinstance(mapping, _Mapping):
        return list(mapping.items())
    try:
        items = [tuple(item) for item in mapping]
    except TypeError:
        raise Error(f"{what} must be a dict {{id: index}}, a list of (id, index) pairs or a tuple (ids, numerators) of "
                    f"two integer arrays, not {type(mapping).__name__}") from None
    if any(len(item) != 2 for item in items):
        raise Error(f"{what} must be a dict {{id: index}} or a list of (id, index) pairs")
    return items


def _indices(mapping, N, what):
    """{id: n} (index n/N) of a user's {id: index}, (id, index) pairs or (ids, numerators) arrays."""
    out = {}
    if _is_arrays(mapping):
        ids, numerators = mapping
        if ids.ndim != 1 or numerators.shape != ids.shape or ids.dtype.kind not in "iu" or numerators.dtype.kind not in "iu":
            raise Error(f"{what}: (ids, numerators) must be two 1-D integer arrays of the same length, got shapes "
                        f"{_shape_text(ids.shape)} and {_shape_text(numerators.shape)}, dtypes {ids.dtype} and {numerators.dtype}")
        for key, n in zip(ids.tolist(), numerators.tolist()):
            key = _id(key, what)
            if key in out:
                raise Error(f"{what}[{key}]: given twice")
            if abs(n) > _INT32_MAX:
                raise Error(f"{what}[{key}]: numerator {_short(n)} is too large (|numerator| at most {_INT32_MAX})")
            out[key] = int(n)
        return out
    for key, value in _items(mapping, what):
        key = _id(key, what)
        where = f"{what}[{key}]"
        if key in out:
            raise Error(f"{where}: given twice")
        out[key] = _numerator(value, N, where)
    return out


def _fractions(ns, N):
    """{id: Fraction} of {id: n} or of a per-id sequence (zeros left out for vertices)."""
    if isinstance(ns, _Mapping):
        return {int(k): _Fraction(int(n), N) for k, n in sorted(ns.items())}
    return {i: _Fraction(int(n), N) for i, n in enumerate(ns)}


def _nonzero_fractions(per_vertex, N):
    per_vertex = _np.asarray(per_vertex)
    return {int(v): _Fraction(int(per_vertex[v]), N) for v in _np.flatnonzero(per_vertex)}


def _pair_arrays(ns):
    """(ids, numerators), two int64 arrays sorted by id, of {id: n} (zeros kept out)."""
    items = sorted((int(k), int(n)) for k, n in ns.items() if n != 0)
    ids = _np.array([k for k, _ in items], dtype=_np.int64)
    return ids, _np.array([n for _, n in items], dtype=_np.int64)


def _nonzero_arrays(per_vertex):
    per_vertex = _np.asarray(per_vertex, dtype=_np.int64)
    ids = _np.flatnonzero(per_vertex).astype(_np.int64)
    return ids, per_vertex[ids].copy()


def _render_args(size, view, up, style, spacing, flat, legend, supersampling):
    a = _core.RenderArgs()
    try:
        a.width, a.height = (int(s) for s in size)
    except (TypeError, ValueError):
        raise Error(f"render: size must be (width, height), got {size!r}") from None
    try:
        a.azimuth, a.elevation = (float(s) for s in view)
    except (TypeError, ValueError):
        raise Error(f"render: view must be (azimuth, elevation) in degrees, got {view!r}") from None
    a.up, a.style = str(up), str(style)
    a.spacing, a.flat, a.legend, a.supersampling = float(spacing), bool(flat), bool(legend), int(supersampling)
    return a


def _singular_pairs(singularities, N):
    if singularities is None:
        return None
    return sorted(_indices(singularities, N, "singularities").items())


# ---------------------------------------------------------------------------------------------------------
# Threads


def _threads(threads, what="threads"):
    """0 (the default) for None, else a whole number >= 1."""
    if threads is None:
        return 0
    if isinstance(threads, bool) or not isinstance(threads, _numbers.Integral) or threads < 1 or threads > 4096:
        raise Error(f"{what} must be None or a whole number from 1 to 4096, not {_short(threads) if isinstance(threads, _numbers.Number) else repr(threads)}")
    return int(threads)


def set_threads(threads):
    """How many threads trivcon's calls use by default (None: OpenMP's default, OMP_NUM_THREADS or every core).

    Applies to every call made afterwards by designers created without threads= (their set-up and
    factorization, solves, automatic placement, refinement, reading indices) and by the module's
    functions (read_mesh, field_indices, render). trivcon's own parallel loops (OpenMP) take the count per
    call, on the thread that makes the call: calls in other Python threads with other counts do not
    interfere. The BLAS (OpenBLAS, used by the factorization's dense blocks) has one setting per process:
    set_threads also sets it to `threads` (to OpenMP's default for None), for every BLAS user in the
    process, numpy included when it uses the same OpenBLAS (Debian's does). While a call with one thread
    runs, OpenBLAS runs single-threaded in the whole process.

    The environment variable TRIVCON_THREADS, read at import, gives the initial value. Two designers
    used from two Python threads at once run fastest with threads=1 each (no oversubscription); one
    designer alone runs fastest with every core (the default).
    """
    n = _threads(threads)
    _core.set_default_threads(n)
    _core.set_blas_threads(n if n > 0 else _core.omp_default_threads())


def get_threads():
    """The default thread count of trivcon's calls (set_threads; OpenMP's default when none was set)."""
    return _core.default_threads() or _core.omp_default_threads()


def _threads_from_environment():
    value = _os.environ.get("TRIVCON_THREADS", "").strip()
    if not value:
        return
    try:
        set_threads(int(value))
    except (ValueError, Error):
        _warnings.warn(f"TRIVCON_THREADS={value!r} is not a whole number from 1 to 4096: ignored", RuntimeWarning, stacklevel=3)


_threads_from_environment()


def _wait_for_abandoned_work():
    # Work abandoned by KeyboardInterrupt (and calls of daemon threads, the only Python threads left at exit,
    # cancelled here) stops at its next safe point; the process must not unload the libraries under it.
    try:
        _core.wait_for_background(-1.0, True)
    except KeyboardInterrupt:
        pass


_atexit.register(_wait_for_abandoned_work)


# ---------------------------------------------------------------------------------------------------------
# Files


def read_mesh(path, info=False, weld=0.0):
    """Read a triangle mesh: OBJ, OFF, PLY (ascii or binary), STL (ascii or binary, corners welded by exact
    position) or glTF 2.0 (.gltf, .glb: the default scene's triangle primitives, transforms applied), each
    optionally gzipped (.obj.gz, ...).

    Returns (V, F): V float64 (n, 3), F int64 (m, 3), in the file's order with the file's ids (0-based);
    polygons are fan-triangulated in order, (a,b,c), (a,c,d), ...; unreferenced vertices are kept.
    With info=True returns (V, F, info), info a dict with "format" ("obj", "off", "ply-ascii",
    "ply-binary-le", "ply-binary-be", "stl-ascii", "stl-binary", "gltf", "glb"), "polygon_count" and
    "polygon_of_triangle" (int64 (m,): the file polygon each triangle comes from) and "repeated_vertex" (the first
    polygon with a repeated corner, as a message with the file and line, or ""; such faces are read, and
    FieldDesigner's repair drops them). weld: for STL, join corners closer than this distance into one vertex
    (0, the default: exact position), as the CLI's --weld. Errors (trivcon.Error) name the file and line or
    byte offset.
    """
    V, F, polygon_of_triangle, polygon_count, fmt, repeated = _core.read_mesh(str(path), float(weld))
    if info:
        return V, F, {"format": fmt, "polygon_count": polygon_count, "polygon_of_triangle": polygon_of_triangle,
                      "repeated_vertex": repeated}
    return V, F


def write_mesh(path, V, F):
    """Write a mesh as OBJ (17 significant digits) or binary PLY (doubles), by the path's extension.

    Written atomically (a temporary file renamed into place); read_mesh reads it back identically.
    """
    V, F = _mesh(V, F)
    _core.write_mesh(str(path), V, F)


def read_field(path, num_faces):
    """Read a per-face field file: trivcon's .txt or .ply, or Directional's .rawfield.

    Returns (directions, N): directions float64 (num_faces, 3), the first direction of each face in world
    coordinates, and the N the file states (None when it states none). The file must have num_faces faces.
    """
    directions, N = _core.read_field(str(path), int(num_faces))
    return directions, (N if N > 0 else None)


def write_field(path, V, F, directions, N=1):
    """Write a per-face field in the CLI's formats, chosen by extension.

    .rawfield: Directional's (first line "N F", then 3N numbers per face); .ply: binary PLY of the mesh
    with face properties fx fy fz; anything else: trivcon's text format ("# N <N>", then "x y z" per
    face). directions (m, 3) are projected onto the faces (the first of the N directions per face).
    To write a solve's own field exactly, use Result.write_field.
    """
    V, F = _mesh(V, F)
    N = _symmetry(N)
    _core.write_field(str(path), V, F, _directions(directions, F.shape[0]), N)


def read_singularities(path, N=1, arrays=False):
    """Read a singularity file ("VERTEX INDEX" lines, INDEX an integer or p/q; or Directional's .sings).

    Returns {vertex: Fraction}; with arrays=True (vertices, numerators), two int64 arrays sorted by vertex
    (index = numerator / N, zeros left out). Every index must be a multiple of 1/N.
    """
    N = _symmetry(N)
    ns = _core.read_singularities(str(path), N)
    return _pair_arrays(ns) if arrays else _fractions(ns, N)


def write_singularities(path, singularities, N=1):
    """Write {vertex: index} (or (vertices, numerators) arrays) in the plain format `trivcon solve -s` reads
    (indices as reduced fractions)."""
    N = _symmetry(N)
    _core.write_singularities(str(path), _indices(singularities, N, "singularities"), N)


def write_png(path, image):
    """Write an (h, w, 3) uint8 image (e.g. from render) as an 8-bit RGB PNG, atomically."""
    a = _array(image, "image")
    if a.ndim != 3 or a.shape[2] != 3:
        raise Error(f"image must have shape (h, w, 3), got shape {_shape_text(a.shape)}")
    if a.dtype != _np.uint8:
        raise Error(f"image must hold uint8 values, got dtype {a.dtype}")
    _core.write_png(str(path), _np.ascontiguousarray(a))


# ---------------------------------------------------------------------------------------------------------
# Fields on plain arrays


def field_indices(V, F, directions, N=1, arrays=False):
    """The singularities of any per-face field (trivcon's, Directional's, your own): {vertex: Fraction}.

    directions (m, 3): one world vector per face (the first of its N directions; projected onto the
    face). Across each interior edge the field's jump relative to parallel transport is reduced to
    (-pi/N, pi/N]; a vertex's index is (angle defect + the sum of the jumps around it) / 2 pi, exactly as
    `trivcon check` reads it. Only vertices of nonzero index are listed. With arrays=True: (vertices,
    numerators), two int64 arrays sorted by vertex, index = numerator / N.
    """
    V, F = _mesh(V, F)
    N = _symmetry(N)
    vertex, _, _ = _core.field_indices(V, F, _directions(directions, F.shape[0]), N)
    return _nonzero_arrays(vertex) if arrays else _nonzero_fractions(vertex, N)


def render(V, F, directions, N=1, size=(1200, 900), view=(30, 20), up="y", style="hedgehog", spacing=11, flat=False,
           legend=True, singularities=None, supersampling=3):
    """A picture of a per-face field on its surface, rendered in software: an (h, w, 3) uint8 array.

    size (width, height) in pixels; view (azimuth, elevation) in degrees; up "x", "y" or "z"; style
    "hedgehog" (N segments per face, or an even subset) or "streamlines"; spacing: pixels between glyphs
    or streamlines (at 900 pixels); flat: flat shading; legend: list N and the indices in a corner.
    singularities {vertex: index} (or (vertices, numerators) arrays) are drawn as discs (red positive, blue negative); None (default):
    those of the field itself, as `trivcon render` does. Save with write_png. Deterministic.
    """
    V, F = _mesh(V, F)
    N = _symmetry(N)
    args = _render_args(size, view, up, style, spacing, flat, legend, supersampling)
    return _core.render(V, F, _directions(directions, F.shape[0]), N, _singular_pairs(singularities, N), args)


# ---------------------------------------------------------------------------------------------------------
# Meshes built in code (trivcon/generate.h): each returns (V, F) like read_mesh.


def make_icosphere(level):
    """Unit sphere: an icosahedron subdivided `level` times; 10*4**level + 2 vertices, 20*4**level faces."""
    return _core.make_icosphere(int(level))


def make_uv_sphere(rings, segments):
    """Unit sphere as a latitude/longitude grid; vertex 0 the north pole (0, 0, 1), the last the south pole."""
    return _core.make_uv_sphere(int(rings), int(segments))


def make_cube_sphere(n, spherical=True):
    """Cube [-1, 1]^3 with n x n grids on its faces, projected to the unit sphere when spherical.

    6n^2 + 2 vertices, 12n^2 faces; for n >= 2 the 8 cube corners are its only vertices of valence 3.
    """
    return _core.make_cube_sphere(int(n), bool(spherical))


def make_torus(nu, nv, R=1.0, r=0.4):
    """Torus around the z axis (major radius R, minor r), nu x nv quads split into triangles; genus 1."""
    return _core.make_torus(int(nu), int(nv), float(R), float(r))


def make_genus_surface(g, resolution=1):
    """Closed surface of genus g: a voxel plate with g holes (chi = 2 - 2g), each voxel face a grid."""
    return _core.make_genus_surface(int(g), int(resolution))


def make_disk(rings, segments):
    """Flat unit disk in z = 0 (a centre vertex and `rings` rings); chi = 1, one boundary loop."""
    return _core.make_disk(int(rings), int(segments))


def make_annulus(rings, segments, r_in=0.5, r_out=1.0):
    """Flat annulus in z = 0 with radii r_in < r_out; chi = 0, two boundary loops."""
    return _core.make_annulus(int(rings), int(segments), float(r_in), float(r_out))


def make_holed_grid(n, holes):
    """Flat n x n grid of the unit square with `holes` square holes in a row; chi = 1 - holes."""
    return _core.make_holed_grid(int(n), int(holes))


def blas_kernels():
    """The OpenBLAS kernels the factorization runs on ("SkylakeX", "Haswell", "Prescott", ...).

    Debian 12's OpenBLAS falls back to generic "Prescott" kernels on CPUs it does not recognise; start
    Python with OPENBLAS_CORETYPE set (e.g. to the value of _core.native_blas_kernels()) for faster
    factorizations. The `trivcon` program does this by itself.
    """
    return _core.blas_kernels()


# ---------------------------------------------------------------------------------------------------------
# The designer


class FieldDesigner(_Cached):
    """A mesh prepared for fields: validated, its geometry and cycles computed, the system factored once.

    FieldDesigner(V, F, weights="cotan", solver="cholesky", factorization="own", weight_floor=0.0, threads=None,
                  repair=True)

    V (n, 3) real, F (m, 3) integer, ids as in the file. A mesh that is not manifold is repaired first
    (repair=True, the default; as the CLI does, trivcon/repair.h): faces with a repeated vertex and exact
    duplicate faces dropped, edges with more than two faces cut into sheets, vertices where sheets touch
    split into one vertex per fan; a UserWarning says what was done. The designer is then the repaired
    mesh's: V, F, every id it takes and gives are the repaired mesh's (vertices: the input's ids, then the
    copies appended; faces: the input's in order without the dropped ones), and `repair` maps them to the
    input's; Result.input_directions and Result's files (write_field, write_singularities, the param OBJ) are
    the input's, as the CLI writes them. With repair=False such a mesh is refused. Validation errors
    (non-finite coordinate, vertex id out of range, non-manifold edge or vertex with repair=False,
    non-orientable component) raise trivcon.Error with the library's message. weights: "cotan" (clamped cotangent weights,
    default) or "unit"; solver: "cholesky" (default) or "qr" (the paper's SuiteSparseQR route);
    factorization: "own" (trivcon's, on several threads) or "cholmod" ("qr" and "cholmod" only when
    trivcon.with_suitesparse). weight_floor: with cotan
    weights, every interior edge gets at least this fraction of the median weight (0 to 1; default 0,
    none): fewer large turns on meshes with many obtuse angles, at some cost in smoothness (docs/explanation/weights.md,
    "Weights and energy"). threads: how many threads its calls use (None: trivcon.set_threads's default;
    see set_threads for what is per call and what is per process); also the attribute `threads`.

    solve() then costs milliseconds per new set of singularities. Fixed faces change the matrix: a
    solve with a different set of fixed faces than the previous one refactors once; changing only
    their directions or the singularities does not. Safe to share between threads (solves on one
    designer run one at a time); the GIL is released while it works, and Ctrl-C stops it
    (KeyboardInterrupt; the designer stays as it was).

    Pickling stores the mesh as given and the options, not the factorization: an unpickled designer is
    validated and prepared again (topology, geometry, cycles) when it is loaded, and factored again on its
    first solve. Its arrays (V, F, edges, ...) are read-only and computed once.
    """

    def __init__(self, V, F, weights="cotan", solver="cholesky", factorization="own", weight_floor=0.0, threads=None, repair=True):
        V, F = _mesh(V, F)
        for name, value, allowed in (("weights", weights, ("cotan", "unit")), ("solver", solver, ("cholesky", "qr")),
                                     ("factorization", factorization, ("own", "cholmod"))):
            if value not in allowed:
                raise Error(f"{name} must be " + " or ".join(repr(a) for a in allowed) + f", not {value!r}")
        try:
            weight_floor = float(weight_floor)
        except (TypeError, ValueError):
            raise Error(f"weight_floor must be a number in [0, 1], not {weight_floor!r}") from None
        threads = _threads(threads)
        self._d = _core.Designer(V, F, weights, solver, factorization, weight_floor, threads, bool(repair))
        if self._d.repair is not None:
            _warnings.warn(f"trivcon: the mesh was {self._d.repair['summary']} (repair=False refuses it instead)", UserWarning,
                           stacklevel=2)
        self.weights = weights
        self.weight_floor = weight_floor
        self.solver = solver
        self.factorization = factorization
        self._cache = {}

    @classmethod
    def _of_core(cls, core, like):
        """A FieldDesigner around a core designer made by the library (a refined mesh), with the options of `like`."""
        self = cls.__new__(cls)
        self._d = core
        self.weights, self.weight_floor, self.solver, self.factorization = like.weights, like.weight_floor, like.solver, like.factorization
        self._cache = {}
        return self

    def __getstate__(self):
        # The mesh as given and the options (the library's, including a refined mesh's per-edge weight
        # scales), not the factorization: __setstate__ prepares the mesh again and factors on the first solve.
        return {"core": self._d.get_state(), "weights": self.weights, "weight_floor": self.weight_floor, "solver": self.solver,
                "factorization": self.factorization}

    def __setstate__(self, state):
        self._d = _core.Designer.restore(state["core"])
        self.weights, self.weight_floor = state["weights"], state["weight_floor"]
        self.solver, self.factorization = state["solver"], state["factorization"]
        self._cache = {}

    @property
    def threads(self):
        """How many threads this designer's calls use (None: the module's default, trivcon.set_threads).
        Settable."""
        return self._d.threads or None

    @threads.setter
    def threads(self, threads):
        self._d.threads = _threads(threads)

    def __repr__(self):
        return (f"<trivcon.FieldDesigner: {self.num_vertices} vertices, {self.num_faces} faces, chi {self.euler_characteristic}, "
                f"{self.num_generators} generators, {len(self.boundary_loops)} boundary loops>")

    # --- The mesh.

    @property
    def V(self):
        """Vertex positions, float64 (n, 3), as given (read-only)."""
        return self._get("V", lambda: self._d.V)

    @property
    def F(self):
        """The consistently oriented faces, int64 (m, 3): equal to the input except for flipped_faces,
        which are reversed (a, b, c) -> (a, c, b). Face frames and angles refer to these (read-only)."""
        return self._get("F", lambda: self._d.F)

    @property
    def F_input(self):
        """The faces as given, int64 (m, 3) (read-only): what write_mesh and the field files pair with V."""
        return self._get("F_input", lambda: self._d.F_input)

    @property
    def repair(self):
        """None when the mesh needed no repair (or repair=False); else a dict mapping the repaired mesh to the
        input: summary (one sentence), input_vertices, input_faces, face_of_input (int64 array: per input face
        its face here; a duplicate's the face it duplicates; a dropped face's a neighbour, or -1), input_face
        (int64 array: per face here its input face), vertex_origin (int64 array: per vertex here the input vertex
        it copies), and lists: degenerate_faces, duplicate_faces ((dropped, original) pairs), cut_edges, split_vertices
        ((vertex, fans) pairs), unpaired_faces, unseparated_faces (dropped where the sheets of a cut edge meet
        again), all in the input's ids."""
        return self._d.repair

    @property
    def num_vertices(self):
        """n, including unreferenced vertices."""
        return self._d.num_vertices

    @property
    def num_faces(self):
        """m."""
        return self._d.num_faces

    @property
    def num_edges(self):
        """The number of edges (interior and boundary)."""
        return self._d.num_edges

    @property
    def euler_characteristic(self):
        """chi = V - E + F over the referenced vertices (summed over components)."""
        return self._d.euler_characteristic

    @property
    def num_generators(self):
        """2g per component: the generator ids solve(generators=) takes (as `trivcon info --cycles`)."""
        return self._d.num_generators

    @property
    def flipped_faces(self):
        """int64 array of the faces whose orientation was reversed to make their component consistent."""
        return self._get("flipped_faces", lambda: self._d.flipped_faces)

    @property
    def unreferenced_vertices(self):
        """int64 array of the vertices no face uses (kept, never singular)."""
        return self._get("unreferenced_vertices", lambda: self._d.unreferenced_vertices)

    @property
    def boundary_loops(self):
        """List of int64 arrays: each boundary loop's vertices in order (surface on the left), loop ids
        (solve(boundary=)) by smallest vertex id, each loop starting at its smallest vertex."""
        return list(self._get("boundary_loops", lambda: tuple(self._d.boundary_loops)))

    @property
    def boundary_vertices(self):
        """int64 array of the vertices on a boundary loop (they cannot be singular)."""
        return self._get("boundary_vertices", lambda: self._d.boundary_vertices)

    @property
    def components(self):
        """Per connected component (numbered by smallest face id): a dict with faces, vertices, edges,
        euler_characteristic, genus, boundary_loops (ids), first_face."""
        return self._d.components

    @property
    def edges(self):
        """Every edge, int64 (E, 2), (i, j) with i < j, sorted by (i, j)."""
        return self._get("edges", lambda: self._d.edges)

    @property
    def edge_faces(self):
        """(L, R) per edge of `edges`, int64 (E, 2): L holds the half-edge i -> j, R the half-edge j -> i;
        -1 where there is none (boundary edges)."""
        return self._get("edge_faces", lambda: self._d.edge_faces)

    def face_frames(self):
        """(X, Y, normal), each float64 (m, 3) unit vectors per face: X along the oriented face's first
        edge (corner 0 -> 1), Y = normal x X, normal along (p1 - p0) x (p2 - p0). The angle a in face f
        is the direction cos(a) X[f] + sin(a) Y[f]."""
        return self._get("face_frames", lambda: tuple(self._d.face_frames()))

    @property
    def timings(self):
        """Seconds per set-up stage (topology, geometry, cycles, plan, analysis, setup, prepare)."""
        return self._d.timings

    # --- Fields.

    def _fixed(self, fixed, align_boundary):
        """{face: angle} of fixed= ({face: angle or (x, y, z)}) and align_boundary (explicit faces win)."""
        out = dict(self._d.boundary_alignment()) if align_boundary else {}
        explicit = {}
        for key, value in _items(fixed, "fixed"):
            face = _id(key, "fixed")
            if face in explicit:
                raise Error(f"fixed[{face}]: given twice")
            self._d.check_fixed_face(face)
            if isinstance(value, _numbers.Real) and not isinstance(value, bool):
                explicit[face] = float(value)
            else:
                v = _array(value, f"fixed[{face}]")
                if v.shape != (3,) or v.dtype.kind not in "fiu":
                    raise Error(f"fixed[{face}]: expected an angle (radians, in the face's frame) or a direction (x, y, z), "
                                f"got {value!r}")
                explicit[face] = self._d.fixed_angle(face, v.astype(_np.float64))
        out.update(explicit)
        return out

    def solve(self, N=1, singularities=None, generators=None, boundary=None, fixed=None, align_boundary=False,
              align_features=None, feature_edges=None, roots=None, auto_cancel=0.0, align_curvature=None,
              split_large_turns=False, max_rounds=8, relax=False, relax_pins=None, relax_cancel=0, relax_max_moves=10000,
              relax_reach=1, relax_periods=0.0, map_target_faces=None, map_edge_length=None, feature_min_length=None,
              map_search_maps=0, map_progress=None):
        """The smoothest N-direction field with exactly the given singularities: a Result.

        N: 1 vectors, 2 lines, 4 crosses, any N >= 1.
        singularities: {vertex: index} (or a list of (vertex, index) pairs, or a tuple (vertices,
          numerators) of two 1-D integer numpy arrays, index = numerator / N, as Result.singularity_arrays
          gives them); indices int, float (a
          multiple of 1/N), fractions.Fraction or "p/q" strings; vertices not listed have index 0. On
          every closed component the indices must sum to chi (Gauss-Bonnet). Boundary vertices cannot
          be singular. Or "auto": those of the globally smoothest field (auto_singularities, with
          auto_cancel as its cancel distance, align_curvature as its curvature guidance and the same fixed
          faces), then the exact solve; each component takes its rotation from that smoothest field.
        generators, boundary: {id: index} (or the same other forms) for generators and boundary loops (ids
          as num_generators and boundary_loops); those not given are chosen to make the field smoothest.
        fixed: {face: direction}, an angle in radians in the face's frame or a world vector (x, y, z)
          (projected onto the face): the field holds it exactly, modulo 2 pi / N.
        align_boundary: fix every face with a boundary edge to that edge's direction (fixed= wins).
        align_features: None, or an angle in degrees: fix the faces beside every interior edge whose
          dihedral angle exceeds it to that edge's direction (as solve --align-features DEG; over
          align_boundary, under fixed=); feature_edges: (n, 2) vertex pairs of more such edges (as a
          --features file). Result.sharp_edges lists the edges followed. feature_min_length: of the edges
          align_features finds, those in a chain with a loose end shorter than this (mesh units, along the
          chain), and pieces less than this across, are not followed (as --feature-min-length; a scan's dashed
          creases). None: all followed, except that with map_target_faces / map_edge_length those shorter than
          one unit of the map are left out.
        roots: {face: angle}: where the field's propagation starts per component (default: each
          component's smallest face, angle 0; a component with fixed faces starts at its smallest one).

        relax: first move the vertex singularities (given, or "auto"'s) one edge at a time downhill in the
          field's energy, each move a real solve, until no single move lowers it (as solve --relax;
          trivcon/relax.h): indices per component kept, boundary vertices never singular; relax_pins: vertices
          that keep their index (none moves away or onto them); relax_cancel: an index may also move onto an
          opposite one at most this many edges away, both vanishing (0: never); relax_max_moves: accepted
          moves at most; relax_reach: a singularity may move to a free vertex at most this many edges away in
          one move (1: steps; more passes rises that steps stop at, as --relax-reach); relax_periods: W > 0 lowers
          the energy plus W times the squared periods of the conformal scale around the fixed faces' components
          instead (as --relax-periods; docs/solver.md, "Periods"). Result.relax is then a RelaxResult (energies,
          moves); the field is the relaxed one.

        split_large_turns: refine the mesh where the connection turns by pi/N or more and solve again
          with the same vertex singularities, at most max_rounds times, until no edge does (trivcon
          solve --split-large-turns): then any tool's own (principal) matching reads exactly the
          prescription (Result.field_exact). The Result then belongs to the refined mesh: Result.designer is a FieldDesigner
          of it (input vertices keep their ids, new ones appended; a split face keeps its id for its
          first child), Result.parent_face the input face of each face, Result.split_rounds one dict per
          round (split_edges, vertices, faces), Result.split_converged whether no large turn is left. The
          boundary and the sharp edges are aligned again on every refined mesh; fixed faces pass their
          direction to their children. Not with generators or boundary indices (the refined mesh has cycles
          of its own), nor with roots or feature_edges.

        map_target_faces or map_edge_length (N = 4): with singularities="auto", choose the singularities for a map at
          that scale, as `trivcon param`/`quad --auto` do (docs/param.md): +- pairs closer than one unit
          cancelled (unless auto_cancel is given), those at the ends of sharp edges kept, a +-1/4 within 1.5 units
          of a sharp edge moved onto it, then close same-sign ones gathered or spread (and those spread moved onto
          a sharp edge in turn); when their map folds
          or its quad mesh fails a check (the scale too coarse for them), or it stretches (mean singular-value
          ratio above 1.5), placed again: relaxed, with pairs cancelled within 2, then 4 units, and those relaxed, the
          cleanest map's kept (this makes the map once or more). Then Result.parametrize/quad at the same scale
          (and the same aligned edges and sizing) give back the map the search kept, as `trivcon quad` gives it
          (not after pickling: then it is made again). Where that map folds beside edges whose two ends lie on aligned lines (a flat
          CAD face triangulated from its rim alone), those edges are split at their midpoints and the search runs
          again on the refined mesh (as quad does): the Result then belongs to the refined mesh, as with
          split_large_turns (Result.designer, Result.parent_face). With singularities given (N = 4), the field as
          `trivcon param -s` / `quad -s` make it and its map kept the same way: a singularity on a feature line whose
          sectors do not make its index gets a sector turned through for it (docs/howto/features.md), so that
          `quad --auto --sing-out`'s singularities make the same field, and parametrize/quad at that scale give
          back the map kept (the other scales when the first keeps problems).
        map_search_maps: with map_target_faces / map_edge_length, the search for a better map starts no step once
          this many maps are made (a step under way finishes) and keeps the best of them, as `quad --search-maps`
          (0: no bound). Result.search says how many it made and whether the bound stopped it.
        map_progress: with map_target_faces / map_edge_length, a callable given each line of the search's steps as
          `quad` prints them (`search: maps 4-6 (placement ...): 12 problems, ...`), on the calling thread while
          the search runs; none when the first map ends the search. What it raises stops the search and is raised.

        The request means the same as the CLI's and the editor's (the library's trivcon/request.h does it).
        Errors in the prescription raise trivcon.Error with the library's message. The result is
        verified (residuals, transport, indices read back): see Result.verified and Result.field_exact.
        """
        N = _symmetry(N)
        explicit = self._fixed(fixed, False)
        curvature_t = None
        if isinstance(singularities, str) and singularities == "auto":
            vertex = None
            cancel, curvature_t = _auto_arguments(auto_cancel, align_curvature)
        else:
            if auto_cancel:
                raise Error("auto_cancel needs singularities='auto'")
            if align_curvature is not None:
                raise Error("align_curvature needs singularities='auto'")
            vertex = _indices(singularities, N, "singularities")
            cancel = 0.0
        root_list = []
        for key, angle in _items(roots, "roots"):
            face = _id(key, "roots")
            if isinstance(angle, bool) or not isinstance(angle, _numbers.Real):
                raise Error(f"roots[{face}]: the angle must be a number, got {angle!r}")
            root_list.append((face, float(angle)))
        degrees = None
        if align_features is not None:
            if isinstance(align_features, bool) or not isinstance(align_features, _numbers.Real) or not (0 <= align_features <= 180):
                raise Error(f"align_features: expected None or an angle in degrees in [0, 180], got {align_features!r}")
            degrees = float(align_features)
        if feature_min_length is not None:
            if degrees is None:
                raise Error("feature_min_length needs align_features")
            if (isinstance(feature_min_length, bool) or not isinstance(feature_min_length, _numbers.Real)
                    or not _math.isfinite(feature_min_length) or feature_min_length < 0):
                raise Error(f"feature_min_length must be a number >= 0, not {feature_min_length!r}")
            feature_min_length = float(feature_min_length)
        edge_pairs = []
        if feature_edges is not None:
            e = _array(feature_edges, "feature_edges")
            if e.size and (e.ndim != 2 or e.shape[1] != 2 or e.dtype.kind not in "iu"):
                raise Error(f"feature_edges: expected (n, 2) vertex ids, got an array of shape {e.shape} and type {e.dtype}")
            edge_pairs = [(_id(int(a), "feature_edges"), _id(int(b), "feature_edges")) for a, b in e.reshape(-1, 2)]
        if split_large_turns:
            if generators or boundary:
                raise Error("split_large_turns makes new generators and boundary loops: leave their indices to be chosen")
            if root_list:
                raise Error("split_large_turns: roots are not supported (the refined mesh starts each component itself)")
            if edge_pairs:
                raise Error("split_large_turns splits edges, which feature_edges names: use align_features instead")
            if isinstance(max_rounds, bool) or not isinstance(max_rounds, _numbers.Integral) or max_rounds < 0:
                raise Error(f"max_rounds must be a whole number >= 0, not {max_rounds!r}")
        pins = []
        if relax_pins is not None:
            pin_array = _array(relax_pins, "relax_pins").reshape(-1)
            if pin_array.size and pin_array.dtype.kind not in "iu":
                raise Error(f"relax_pins: expected vertex ids (integers), got an array of type {pin_array.dtype}")
            pins = [_id(int(v), "relax_pins") for v in pin_array]
        for name, value in (("relax_cancel", relax_cancel), ("relax_max_moves", relax_max_moves)):
            if isinstance(value, bool) or not isinstance(value, _numbers.Integral) or value < 0:
                raise Error(f"{name} must be a whole number >= 0, not {value!r}")
        if isinstance(relax_reach, bool) or not isinstance(relax_reach, _numbers.Integral) or relax_reach < 1:
            raise Error(f"relax_reach must be a whole number >= 1, not {relax_reach!r}")
        if (isinstance(relax_periods, bool) or not isinstance(relax_periods, _numbers.Real) or not _math.isfinite(relax_periods)
                or relax_periods < 0):
            raise Error(f"relax_periods must be a number >= 0, not {relax_periods!r}")
        if not relax and (pins or relax_cancel or relax_max_moves != 10000 or relax_reach != 1 or relax_periods):
            raise Error("relax_pins, relax_cancel, relax_max_moves, relax_reach and relax_periods need relax=True")
        map_scale = [0.0, 0.0]  # edge length, target faces
        for k, (name, value) in enumerate((("map_edge_length", map_edge_length), ("map_target_faces", map_target_faces))):
            if value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, _numbers.Real) or not _math.isfinite(value) or value <= 0:
                raise Error(f"{name} must be a positive number, not {value!r}")
            map_scale[k] = float(value)
        if map_scale[0] and map_scale[1]:
            raise Error("give at most one of map_target_faces and map_edge_length")
        if isinstance(map_search_maps, bool) or not isinstance(map_search_maps, _numbers.Integral) or map_search_maps < 0:
            raise Error(f"map_search_maps must be a whole number >= 0, not {map_search_maps!r}")
        if map_progress is not None and not callable(map_progress):
            raise Error(f"map_progress must be callable or None, not {map_progress!r}")
        core, r, a, parent, rounds, converged, sharp, relaxed = self._d.solve_request(
            N, vertex, _indices(generators, N, "generators"), _indices(boundary, N, "boundary"), explicit, bool(align_boundary),
            degrees, edge_pairs, root_list, cancel, False, 8, curvature_t, bool(split_large_turns), int(max_rounds),
            bool(relax), pins, int(relax_cancel), int(relax_max_moves), int(relax_reach), float(relax_periods), map_scale[0],
            map_scale[1], feature_min_length, int(map_search_maps), map_progress)
        auto = AutoResult(a, self) if a is not None else None
        designer = self if core is self._d else FieldDesigner._of_core(core, self)
        result = Result(designer, r, auto)
        result._align_boundary = bool(align_boundary)
        if degrees is not None or edge_pairs:
            result.sharp_edges = _frozen(sharp)
        result.relax = RelaxResult(relaxed, N) if relaxed is not None else None
        if split_large_turns or len(parent):
            result.parent_face = _frozen(parent)
        if split_large_turns:
            result.split_rounds = rounds
            result.split_converged = converged
        return result

    def auto_singularities(self, N=1, cancel=0.0, cancel_absolute=False, iterations=8, fixed=None, align_boundary=False,
                           align_curvature=None):
        """Singularities found automatically: those of the globally smoothest N-field (Knoeppel et al. 2013).

        cancel: remove pairs of opposite singularities (+n, -n) at most this far apart along edges, closest
          first, in mean edge lengths (or in the mesh's units with cancel_absolute=True); 0: none.
        iterations: inverse-power iterations (default 8).
        fixed, align_boundary: faces held as in solve (Dirichlet values of the smoothest field).
        align_curvature: None (no guidance), or the strength t < 1 with which the field follows the principal
          curvature directions (N even; 0 as geometry-central, toward 1 smoother, negative closer to the
          curvature), as `solve --auto --align curvature:t`.
        Returns an AutoResult; AutoResult.singularities go straight into solve(singularities=...).
        """
        N = _symmetry(N)
        cancel, curvature_t = _auto_arguments(cancel, align_curvature)
        fixed_angles = self._fixed(fixed, align_boundary)
        return AutoResult(self._d.auto_singularities(N, int(iterations), cancel, bool(cancel_absolute), fixed_angles,
                                                     curvature_t is not None, curvature_t or 0.0), self)

    def relax(self, singularities, N=1, pins=None, max_moves=10000, cancel_distance=0, generators=None, boundary=None, fixed=None,
              align_boundary=False, align_features=None, feature_edges=None, auto_cancel=0.0, reach=1, period_weight=0.0):
        """Singularities moved downhill in the field's own energy (trivcon/relax.h): a RelaxResult.

        singularities: as in solve (or "auto", with auto_cancel); pins, max_moves, cancel_distance, reach,
        period_weight: see solve's relax_pins, relax_max_moves, relax_cancel, relax_reach, relax_periods; generators, boundary, fixed, align_boundary, align_features,
        feature_edges as in solve. RelaxResult.singularities go straight into solve; RelaxResult.result is the
        field of the relaxed placement, already solved.
        """
        result = self.solve(N, singularities, generators=generators, boundary=boundary, fixed=fixed, align_boundary=align_boundary,
                            align_features=align_features, feature_edges=feature_edges, auto_cancel=auto_cancel, relax=True,
                            relax_pins=pins, relax_cancel=cancel_distance, relax_max_moves=max_moves, relax_reach=reach,
                            relax_periods=period_weight)
        result.relax.result = result
        return result.relax

    def field_indices(self, directions, N=1, arrays=False):
        """{vertex: Fraction} of a per-face field (m, 3) on this mesh (as trivcon.field_indices); with
        arrays=True (vertices, numerators), two int64 arrays sorted by vertex, index = numerator / N."""
        N = _symmetry(N)
        vertex, _, _ = self._d.field_indices(_directions(directions, self.num_faces), N)
        return _nonzero_arrays(vertex) if arrays else _nonzero_fractions(vertex, N)

    def cycle_indices(self, directions, N=1):
        """(loops, generators) of a per-face field: {loop id: Fraction}, {generator id: Fraction}: the
        field's turns around each boundary loop and generator, relative to parallel transport."""
        N = _symmetry(N)
        _, loops, generators = self._d.field_indices(_directions(directions, self.num_faces), N)
        return _fractions(loops, N), _fractions(generators, N)



def _auto_arguments(cancel, align_curvature):
    """(cancel distance, curvature strength or None) of automatic placement, checked."""
    curvature_t = None
    if align_curvature is not None:
        if isinstance(align_curvature, bool) or not isinstance(align_curvature, _numbers.Real):
            raise Error(f"align_curvature must be None or a number t < 1, got {align_curvature!r}")
        curvature_t = float(align_curvature)
    try:
        cancel = float(cancel)
    except (TypeError, ValueError):
        raise Error(f"cancel must be a number, got {cancel!r}") from None
    if not (_math.isfinite(cancel) and cancel >= 0):
        raise Error(f"singularity cancellation: invalid distance {cancel!r} (need a finite number >= 0)")
    return cancel, curvature_t


def _all_directions(designer, angles, N):
    """(m, N, 3): the N unit directions per face of angles (m,) in the designer's face frames."""
    X, Y, _ = designer.face_frames()
    a = angles[:, None] + (2 * _math.pi / N) * _np.arange(N)[None, :]
    return _np.cos(a)[:, :, None] * X[:, None, :] + _np.sin(a)[:, :, None] * Y[:, None, :]


class Result(_Cached):
    """One solve of a FieldDesigner: the field, its connection, what was used and how well it holds.

    Arrays (computed once, read-only):
      directions  float64 (m, 3): the first of the N unit directions per face, in world coordinates
                  (the others are rotated by 2 pi k / N about the face normal: all_directions())
      angles      float64 (m,): the same as angles in the face frames (FieldDesigner.face_frames), in [0, 2 pi)
      edges       int64 (E, 2): the interior edges (i, j), i < j, sorted by (i, j), as --connection-out
      connection  float64 (E,): the adjustment angle x per edge of `edges` (radians): a direction at angle
                  b in the face holding half-edge i -> j is carried to b + rho - x in the other face
    Numbers: N, energy (sum of x^2 / w), residual (largest holonomy residual over all vertex, loop and
      generator cycles, radians), transport_mismatch, fixed_error, large_turn_edges.
    Indices (dicts of fractions.Fraction): singularities (the vertex indices used), generators and
      boundary (the indices used, given or chosen), generators_chosen / boundary_chosen (ids chosen by
      the solver), field_singularities (read back from the field itself); singularity_arrays and
      field_singularity_arrays give the same vertex indices as (vertices, numerators) arrays.
    verified: the check `trivcon solve` applies to the connection (residuals, transport and fixed faces
      within 1e-9 relative, indices read back equal to the prescription except where the connection turns
      by pi/N or more across an edge).
    field_exact: whether the per-face field read on its own (the principal matching, as field_indices and
      any other tool read it) shows exactly the prescribed singularities; where the connection turns by
      pi/N or more a field sampled once per face cannot show them, and then it is False even when
      verified: solve again with split_large_turns=True. repr() says both.
    auto: the AutoResult when solved with singularities="auto".
    Files: write_field, write_connection, write_lines, write_singularities (and write_mesh, the mesh the
      field belongs to) write what the CLI's --field-out, --connection-out, --lines-out, --sing-out
      (--mesh-out) write for the same solve; render draws it.
    Pickling stores the designer (see FieldDesigner), the prescription and every output, so an unpickled
    Result gives the same values without solving again.
    """

    def __init__(self, designer, result, auto=None):
        self._designer = designer
        self._r = result
        self.auto = auto
        self._cache = {}

    def __getstate__(self):
        state = {"designer": self._designer, "core": self._r.get_state(), "auto": self.auto}
        for key in ("parent_face", "split_rounds", "split_converged", "sharp_edges", "_align_boundary", "relax"):
            if key in self.__dict__:
                state[key] = self.__dict__[key]
        return state

    def __setstate__(self, state):
        self._designer = state["designer"]
        self._r = _core.DesignResult.restore(self._designer._d, state["core"])
        self.auto = state["auto"]
        self._cache = {}
        self.relax = state.get("relax")
        if "sharp_edges" in state:
            self.sharp_edges = state["sharp_edges"]
        if "_align_boundary" in state:
            self._align_boundary = state["_align_boundary"]
        if "parent_face" in state:  # after split_large_turns, or a map's refinement
            self.parent_face = _frozen(_np.array(state["parent_face"], dtype=_np.int64))
        if "split_rounds" in state:
            self.split_rounds, self.split_converged = state["split_rounds"], state["split_converged"]

    def _exactness(self):
        """'field exact', or what is not and what to do about it."""
        k = len(self.index_mismatches)
        if k == 0:
            return "field exact"
        text = f"field NOT exact: {k} {'vertex reads another index' if k == 1 else 'vertices read other indices'}"
        if len(self.unexplained_mismatches) == 0:
            text += " (large turns)"
        if "split_rounds" in self.__dict__:
            return text + "; split_large_turns left large turns"
        return text + "; use split_large_turns=True"

    def __repr__(self):
        return (f"<trivcon.Result: N {self.N}, {len(self.singularities)} singular vertices, energy {self.energy:.6g}, "
                f"residual {self.residual:.3g}, {'verified' if self.verified else 'NOT verified'}, {self._exactness()}>")

    @property
    def designer(self):
        """The FieldDesigner this came from (with split_large_turns, the refined mesh's)."""
        return self._designer

    @property
    def N(self):
        """The symmetry."""
        return self._r.N

    @property
    def directions(self):
        """float64 (m, 3) unit vectors: the first of the N directions per face, world coordinates (read-only)."""
        return self._get("directions", lambda: self._r.directions)

    @property
    def angles(self):
        """float64 (m,): the field's first direction per face as an angle in the face's frame, [0, 2 pi) (read-only)."""
        return self._get("angles", lambda: self._r.angles)

    def all_directions(self):
        """float64 (m, N, 3), read-only: all N unit directions per face, direction k at angle angles + 2 pi k / N
        in the face frame; [:, 0] is `directions`."""

        def compute():
            out = _all_directions(self._designer, self.angles, self.N)
            out[:, 0] = self.directions  # the library's own first direction, bit for bit
            return out

        return self._get("all_directions", compute)

    def _connection(self):
        return self._get("connection", self._r.connection)

    @property
    def edges(self):
        """int64 (E, 2): the interior edges (i, j), i < j, sorted by (i, j): the rows of --connection-out."""
        return self._connection()[0]

    @property
    def connection(self):
        """float64 (E,): the adjustment angle x (radians) per edge of `edges`."""
        return self._connection()[1]

    @property
    def energy(self):
        """sum over edges of x^2 / w (w the cotan or unit weights)."""
        return self._r.energy

    @property
    def residual(self):
        """Largest |holonomy - prescription| over all vertex, loop and generator cycles (radians)."""
        return max(self._r.max_vertex_residual, self._r.max_cycle_residual)

    @property
    def rhs_scale(self):
        """The scale of the constraints' right-hand sides (verification is relative to max(1, this))."""
        return self._r.rhs_scale

    @property
    def transport_mismatch(self):
        """Largest mismatch of the field with its connection across an edge, modulo 2 pi / N (radians)."""
        return self._r.transport_mismatch

    @property
    def fixed_error(self):
        """Largest deviation of the field from a fixed direction, modulo 2 pi / N (radians)."""
        return self._r.max_fixed_error

    @property
    def fixed(self):
        """{face: angle}: the fixed directions used (angles in the face frames)."""
        return dict(self._r.fixed)

    @property
    def conflicts(self):
        """[(face_a, face_b, turn)]: adjacent fixed faces the field must turn sharply between (> pi/(2N))."""
        return self._r.conflicts

    @property
    def singularities(self):
        """{vertex: Fraction}: the vertex indices prescribed (the ones found, with singularities="auto")."""
        return dict(self._get("singularities", lambda: _fractions(self._r.vertex, self.N)))

    @property
    def search(self):
        """{"maps": n, "stopped": bool}: with map_target_faces / map_edge_length, the maps the search made and whether
        map_search_maps stopped it (as `quad --report`'s "search"); 0 and False without."""
        return dict(self._r.search)

    @property
    def corners(self):
        """{boundary vertex: Fraction}: corners of the aligned boundary, made where a map's placement moved a
        singularity beside the boundary onto it, or given as a boundary vertex's index with align_boundary=True:
        the vertex's fan turned as that index would turn it, no singularity there (docs/param.md). Empty
        without."""
        return dict(self._get("corners", lambda: _fractions(self._r.corners, self.N)))

    @property
    def singularity_arrays(self):
        """(vertices, numerators): the prescribed vertex indices as two int64 arrays sorted by vertex,
        index = numerator / N (read-only); solve(singularities=...) takes them back."""
        return self._get("singularity_arrays", lambda: _pair_arrays(self._r.vertex))

    @property
    def generators(self):
        """{generator id: Fraction}: every generator's index as used (given, or chosen by the solver)."""
        return _fractions(self._r.generator_index, self.N)

    @property
    def generators_chosen(self):
        """Ids of the generators whose index the solver chose."""
        return [i for i, c in enumerate(self._r.generator_chosen) if c]

    @property
    def boundary(self):
        """{loop id: Fraction}: every boundary loop's index as used (given, or chosen by the solver)."""
        return _fractions(self._r.loop_index, self.N)

    @property
    def boundary_chosen(self):
        """Ids of the boundary loops whose index the solver chose."""
        return [i for i, c in enumerate(self._r.loop_chosen) if c]

    @property
    def field_singularities(self):
        """{vertex: Fraction}: the indices read back from the field itself (as field_indices)."""
        return dict(self._get("field_singularities", lambda: _nonzero_fractions(self._r.indices[0], self.N)))

    @property
    def field_singularity_arrays(self):
        """(vertices, numerators): field_singularities as two int64 arrays sorted by vertex (read-only)."""
        return self._get("field_singularity_arrays", lambda: _nonzero_arrays(self._r.indices[0]))

    @property
    def index_mismatches(self):
        """int64 array: interior vertices whose index read back differs from the prescription (read-only)."""
        return self._get("index_mismatches", lambda: self._r.index_mismatch_vertices)

    @property
    def unexplained_mismatches(self):
        """int64 array: those of index_mismatches next to no edge turning by pi/N or more (real errors; read-only)."""
        return self._get("unexplained_mismatches", lambda: self._r.unexplained_mismatch_vertices)

    @property
    def large_turn_edges(self):
        """How many edges have |x| >= pi/N (where a per-face field cannot show an index)."""
        return self._r.large_turn_edges

    @property
    def verified(self):
        """True when every check `trivcon solve` makes passed (its exit status 3 otherwise): the connection has
        the prescribed holonomy and the field follows it. About the field read on its own: field_exact."""
        return self._r.verified

    @property
    def field_exact(self):
        """True exactly when the per-face field, read on its own with the principal (closest) matching -- as
        field_indices, `trivcon check` and other tools read a field -- shows exactly the prescribed
        singularities: no index_mismatches. False where the connection turns by pi/N or more across edges
        (large_turn_edges) around a vertex that then reads another index, even when `verified`; solve with
        split_large_turns=True to refine those edges away (or hand other tools `matching`)."""
        return len(self.index_mismatches) == 0

    @property
    def seconds(self):
        """Seconds of the solve, the field propagation and the verification."""
        return self._r.seconds

    @property
    def input_directions(self):
        """float64 (input faces, 3): `directions` per face of the mesh as given before repair (FieldDesigner.repair:
        a duplicate face reads the face it duplicates, a dropped degenerate face a neighbour's, or zeros);
        `directions` itself when the mesh was not repaired (read-only). What write_field writes."""
        def compute():
            r = self._designer.repair
            if r is None or "parent_face" in self.__dict__:
                return self.directions
            rows = _np.asarray(r["face_of_input"], dtype=_np.int64)
            out = _np.zeros((rows.shape[0], 3))
            out[rows >= 0] = self.directions[rows[rows >= 0]]
            return _frozen(out)
        return self._get("input_directions", compute)

    def write_field(self, path):
        """Write the field exactly as --field-out does (.txt, .rawfield or .ply by extension): a row per face of
        the mesh as given (input_directions) when it was repaired."""
        self._r.write_field(str(path))

    def write_mesh(self, path):
        """Write the mesh the field belongs to, as --mesh-out does (.ply binary, else OBJ by extension): the
        refined mesh after split_large_turns, else the input (faces as given)."""
        write_mesh(path, self._designer.V, self._designer.F_input)

    def write_connection(self, path):
        """Write the connection as --connection-out does ("i j x" per interior edge, sorted)."""
        self._r.write_connection(str(path))

    @property
    def matching(self):
        """int64 (E,): per edge of `edges`, the whole number m in [0, N) of 2 pi / N turns our connection uses
        between the two faces' first directions (trivcon/matching.h; what --matching-out writes): a tool
        given this matching instead of computing the closest one reads exactly our singularities (read-only)."""
        return self._get("matching", self._r.matching)

    def write_matching(self, path):
        """Write the matching as --matching-out does (Directional's .matching format)."""
        self._r.write_matching(str(path))

    def write_lines(self, path):
        """Write an OBJ with a segment per face and direction, as --lines-out does."""
        self._r.write_lines(str(path))

    def write_singularities(self, path):
        """Write the singularities used, as --sing-out does (readable by `trivcon solve -s`)."""
        self._r.write_singularities(str(path))

    def parametrize(self, target_faces=None, edge_length=None, align_boundary=None, aligned_edges=None, uniform_size=False, sizing=None):
        """The seamless integer-grid map of this cross field (N = 4), as `trivcon param`: a Parametrization.

        target_faces: about this many unit squares; or edge_length: one unit of (u, v) in the mesh's units.
        With singularities="auto", solve with map_target_faces (or map_edge_length) at the same scale to get the
        program's singularities and map (`trivcon param --auto` chooses them for the map).
        align_boundary: put every boundary edge the field runs along on an integer iso-line (default: as
          this field was solved, solve(align_boundary=...)). aligned_edges: (n, 2) vertex pairs of more edges
          to put on iso-lines (default: the sharp edges the solve followed, Result.sharp_edges).
        uniform_size: one unit of (u, v) everywhere (a texture's even density), as `--uniform-size`; by default
          the unit follows the map's own scale where the field turns (docs/param.md, "Sizing").
        sizing: "map" (the default), "connection" (the conformal factor of the field's connection first) or
          "uniform" (as uniform_size=True), as `--sizing`.
        The mathematics and what is checked: docs/param.md. Raises trivcon.Error for N other than 4, a
        missing or non-positive scale, an aligned edge that is not an edge of the mesh, a sizing other than the
        three, or uniform_size=True with another sizing.
        When the map at the scale asked for keeps problems, it is made again at 0.95, 1.05, 0.9 and 1.1 times the
        edge length, as the program does, and the one with the fewest is kept (Parametrization.scale says which).
        """
        return self._map(*self._map_args(target_faces, edge_length, align_boundary, aligned_edges, uniform_size, sizing), False)[0]

    def _map_args(self, target_faces, edge_length, align_boundary, aligned_edges, uniform_size, sizing):
        # parametrize's arguments checked, as the core's: (edge_length, target_faces, align_boundary, pairs, sizing).
        if self.N != 4:
            raise Error(f"param: a seamless parametrization needs a cross field (N = 4), got N = {self.N}")
        if (target_faces is None) == (edge_length is None):
            raise Error("parametrize: give exactly one of target_faces and edge_length")
        scale = target_faces if edge_length is None else edge_length
        if isinstance(scale, bool) or not isinstance(scale, _numbers.Real) or not _math.isfinite(scale) or scale <= 0:
            raise Error(f"parametrize: {'target_faces' if edge_length is None else 'edge_length'} must be a positive number, not {scale!r}")
        if align_boundary is None:
            align_boundary = self.__dict__.get("_align_boundary", False)
        if aligned_edges is None:
            pairs = self.__dict__.get("sharp_edges", _np.zeros((0, 2), dtype=_np.int64))
        else:
            pairs = _array(aligned_edges, "aligned_edges")
            if pairs.size and (pairs.ndim != 2 or pairs.shape[1] != 2 or pairs.dtype.kind not in "iu"):
                raise Error(f"aligned_edges: expected (n, 2) vertex ids, got an array of shape {pairs.shape} and type {pairs.dtype}")
        edge_pairs = [(int(a), int(b)) for a, b in _np.asarray(pairs).reshape(-1, 2)]
        if sizing is None:
            sizing = "uniform" if uniform_size else "map"
        elif uniform_size and sizing != "uniform":
            raise Error(f"parametrize: uniform_size=True and sizing={sizing!r} disagree")
        return (float(edge_length or 0.0), float(target_faces or 0.0), bool(align_boundary), edge_pairs, sizing)

    def _map(self, *args):
        # The map as the program keeps it (trivcon/request.h map_field), and with args[-1] its quad mesh's tuple.
        param, scale, quads = self._r.parametrize(*args)
        return Parametrization(self, *param, scale=scale, args=args), quads

    def quad(self, target_faces=None, edge_length=None, align_boundary=None, aligned_edges=None, uniform_size=False, sizing=None):
        """The quad mesh of this cross field (N = 4), as `trivcon quad`: a QuadMesh (V, Q = result.quad(...) works too).

        The map is made as by parametrize (same arguments; its quad mesh's failed checks count among the problems
        that make it again at another scale), then its integer grid is extracted (trivcon/quad.h,
        docs/quad.md): the quads' irregular vertices are this field's singularities, valence 4 - n at index n/4.
        QuadMesh.quality has every guarantee checked on the result and QuadMesh.warning says what failed ("" when
        nothing did); nothing is raised for a failed guarantee, so that the mesh can be looked at. Quads end on a
        boundary only where it is aligned: on a mesh with boundary, solve with align_boundary=True (as
        `trivcon quad --auto` does unasked), or the quads along it are missing (reported).
        """
        args = self._map_args(target_faces, edge_length, align_boundary, aligned_edges, uniform_size, sizing)
        return QuadMesh(*self._map(*args, True)[1])

    def render(self, size=(1200, 900), view=(30, 20), up="y", style="hedgehog", spacing=11, flat=False, legend=True,
               singularities=None, supersampling=3):
        """An (h, w, 3) uint8 picture of this field, as trivcon.render; singularities default to the ones
        prescribed (as `trivcon solve --png`)."""
        args = _render_args(size, view, up, style, spacing, flat, legend, supersampling)
        return self._r.render(_singular_pairs(singularities, self.N), args)


class RelaxResult:
    """Singularities relaxed (FieldDesigner.relax, or solve(..., relax=True) as Result.relax).

      singularities  {vertex: Fraction}: the relaxed placement (goes straight into solve(singularities=...));
                     singularity_arrays the same as (vertices, numerators) int64 arrays
      energy_before, energy_after   the field's energy (sum of x^2 / w) at the start and at the end
      periods_before, periods_after  with relax_periods / period_weight W > 0: the sum of the squared periods
                     P at the start and at the end (None without)
      energies       float64 (k + 1,): the objective (the energy, plus W P with the periods) before, then
                     after each move, strictly decreasing
      moves          dict of arrays, one entry per accepted move in order: "from", "to" (int64 vertices),
                     "index" (int64 n of the index n / N moved), "energy" (float64, after it), "cancelled"
                     (bool: "to" held the opposite index and both vanished)
      candidates_evaluated  real solves of candidate moves; converged: stopped because no single move lowers
                     the energy (False: stopped at max_moves); seconds
      result         the Result of the relaxed field (set by FieldDesigner.relax; None inside a Result)
    """

    def __init__(self, d, N):
        self.N = N
        self._vertex = {int(k): int(v) for k, v in d["vertex"].items()}
        self.energy_before, self.energy_after = d["energy_before"], d["energy_after"]
        self.periods_before, self.periods_after = d.get("periods_before"), d.get("periods_after")
        self.energies = _frozen(_np.asarray(d["energies"], dtype=_np.float64))
        self.moves = {"from": _frozen(d["from"]), "to": _frozen(d["to"]), "index": _frozen(d["index"]),
                      "energy": _frozen(_np.asarray(d["energies"], dtype=_np.float64)[1:].copy()),
                      "cancelled": _frozen(_np.asarray(d["cancelled"], dtype=bool))}
        self.candidates_evaluated, self.converged, self.seconds = d["candidates_evaluated"], d["converged"], d["seconds"]
        self.result = None

    def __getstate__(self):
        state = dict(self.__dict__)
        state["result"] = None  # the Result pickles this one, not the other way round
        return state

    @property
    def singularities(self):
        """{vertex: Fraction}: the relaxed placement."""
        return _fractions(self._vertex, self.N)

    @property
    def singularity_arrays(self):
        """(vertices, numerators): `singularities` as two int64 arrays sorted by vertex, index = numerator / N."""
        return _pair_arrays(self._vertex)

    def __repr__(self):
        return (f"<trivcon.RelaxResult: energy {self.energy_before:.6g} -> {self.energy_after:.6g}, {len(self.moves['from'])} moves, "
                f"{int(self.moves['cancelled'].sum())} cancelling a pair, converged={self.converged}>")


class QuadMesh:
    """The quad mesh of a seamless map (Result.quad, Parametrization.quads; trivcon/quad.h, docs/quad.md).

      V            float64 (n, 3): the quad vertices, on the input surface
      Q            int64 (m, 4): the quads, counter-clockwise seen from outside (the input faces' orientation)
      vertex_face  int64 (n,): the face (of the designer's mesh) each vertex lies in
      vertex_cone  int64 (n,): the mesh vertex under each quad vertex (a singularity, or a vertex on an integer
                   point), else -1
      quality      dict: quads, vertices, euler_characteristic (and input_...), boundary_loops, manifold,
                   oriented, irregular_vertices, singular_mismatches, inverted_quads, nonconvex_quads (a flat or
                   reflex corner), min/mean_scaled_jacobian,
                   hausdorff_relative, target_quads, extraction counts, problems, seconds (the `quad` object of
                   `trivcon quad --report`)
      warning      "" when every guarantee holds, else what failed, in one sentence
    Unpacks as (V, Q); write(path) writes what `trivcon quad -o` writes (.ply binary, else OBJ).
    """

    def __init__(self, V, Q, vertex_face, vertex_cone, quality, warning):
        self.V, self.Q = _frozen(V), _frozen(Q)
        self.vertex_face, self.vertex_cone = _frozen(vertex_face), _frozen(vertex_cone)
        self.quality, self.warning = quality, warning

    def __iter__(self):
        return iter((self.V, self.Q))

    @property
    def ok(self):
        """Every guarantee holds (quality["problems"] is empty)."""
        return not self.quality["problems"]

    def write(self, path):
        """Write the quad mesh: binary PLY when path ends in .ply, else OBJ (quads as 'f a b c d')."""
        _core.write_quad_mesh(str(path), _np.ascontiguousarray(self.V, dtype=_np.float64), _np.ascontiguousarray(self.Q, dtype=_np.int64))

    def __repr__(self):
        q = self.quality
        return (f"QuadMesh({q['quads']} quads, {q['vertices']} vertices, {q['irregular_vertices']} irregular, chi {q['euler_characteristic']}, "
                f"scaled Jacobian min {q['min_scaled_jacobian']:.3g}, ok={self.ok})")


class Parametrization:
    """A seamless integer-grid map (Result.parametrize; the conventions of trivcon/param.h, docs/param.md).

      uv           float64 (F, 3, 2): (u, v) of each corner of each input face, in the input's corner order
      cut_edges    int64 (n, 2): the cut's edges as vertex pairs (i < j); rotations int64 (n,): r in [0, 4),
                   translations int64 (n, 2): across cut edge (i, j) from its L face to its R face, the sides
                   differ by the rotation by r quarter turns and then the translation
      cones        int64 (k,): the singular vertices; cone_index int64 (k,): n per cone (index n / 4)
      edge_length  the mesh length of one unit of (u, v)
      scale        edge_length over the one asked for: 1, or when the map at that length kept problems (folds,
                   wrong windings) one of 0.95, 1.05, 0.9, 1.1 whose map has fewer (as `trivcon param`'s `scale:`
                   line, the report's map_scale); the squares move by about 1/scale^2
      quality      dict: seamless, flipped_faces, degenerate_faces, max_transition_residual, max_cone_offset,
                   max_cone_angle_error, max_alignment_error, mean_distortion, unit_squares, target_squares,
                   seconds, ... (the `param` object of `trivcon param --report`)
      warning      "" or what is wrong with the map (folds, with what to change)
    write_obj(path) writes what `trivcon param -o` writes.
    """

    def __init__(self, result, uv, cut, rotations, translations, cones, cone_index, edge_length, quality, warning, core=None, args=None,
                 scale=1.0):
        self._result = result
        self.scale = scale
        self.uv, self.cut_edges, self.rotations, self.translations = (_frozen(a) for a in (uv, cut, rotations, translations))
        self.cones, self.cone_index = _frozen(cones), _frozen(cone_index)
        self.edge_length, self.quality, self.warning = edge_length, quality, warning
        self._core, self._args = core, args

    def __getstate__(self):
        state = dict(self.__dict__)
        state["_core"] = None  # made again from the result on the first quads() after unpickling
        return state

    def quads(self):
        """The quad mesh of this map (trivcon/quad.h): a QuadMesh. See Result.quad."""
        if self._core is None:
            self._core = self._result._r.parametrize(*self._args)[0][-1]
        return QuadMesh(*self._result._r.quads(self._core))

    @property
    def seamless(self):
        """Transitions whole, cones on integer points, aligned edges on iso-lines (to 1e-6)."""
        return self.quality["seamless"]

    def write_obj(self, path):
        """Write the OBJ of `trivcon param -o`: the mesh as given, one vt per corner."""
        self._result._r.write_uv_obj(str(path), _np.ascontiguousarray(self.uv.reshape(-1, 6)))

    def __repr__(self):
        q = self.quality
        return (f"Parametrization({self.uv.shape[0]} faces, edge length {self.edge_length:.4g}, {q['unit_squares']:.0f} unit squares, "
                f"seamless={q['seamless']}, {q['flipped_faces']} flipped, {q['degenerate_faces']} degenerate)")


class AutoResult(_Cached):
    """Singularities found automatically (FieldDesigner.auto_singularities).

      singularities  {vertex: Fraction} to prescribe (after cancellation; from solve(..., map_target_faces=K) with
                     sharp edges, before the moves onto them and the split after those: Result.singularities
                     holds what was designed); singularity_arrays the same as (vertices, numerators) arrays
      found          {vertex: Fraction} of the smoothest field, before cancellation
      pairs          [(vertex of +n, vertex of -n)] cancelled, in order
      coincident_removed  singularities removed by summing over coincident vertices (auto.h)
      directions     float64 (m, 3), angles float64 (m,): the smoothest field itself (not the exact solve;
                     read-only); all_directions() its N directions per face
      energy         its Rayleigh quotient E(u) / |u|^2_M; vanishing_faces: faces where it vanished
      seconds        per stage (assemble, factor, iterate, align, indices, cancel)
      ordering       the smoothest field's factor order: "AMD" or "coordinate dissection" (auto.h)
    Pickles with its designer.
    """

    def __init__(self, a, designer=None):
        self._a = a
        self._designer = designer
        self._cache = {}

    def __getstate__(self):
        return {"designer": self._designer, "core": self._a.get_state()}

    def __setstate__(self, state):
        self._designer = state["designer"]
        self._a = _core.AutoResult.restore(self._designer._d, state["core"])
        self._cache = {}

    def __repr__(self):
        return (f"<trivcon.AutoResult: N {self.N}, found {len(self.found)} singularities, cancelled {len(self.pairs)} pairs, "
                f"using {len(self.singularities)}>")

    @property
    def N(self):
        """The symmetry."""
        return self._a.N

    @property
    def singularities(self):
        """{vertex: Fraction}: the singularities to prescribe (after cancellation)."""
        return _fractions(self._a.vertex, self.N)

    @property
    def singularity_arrays(self):
        """(vertices, numerators): `singularities` as two int64 arrays sorted by vertex, index = numerator / N."""
        return self._get("singularity_arrays", lambda: _pair_arrays(self._a.vertex))

    @property
    def found(self):
        """{vertex: Fraction}: the singularities of the smoothest field, before cancellation."""
        return _fractions(self._a.found, self.N)

    @property
    def coincident_removed(self):
        """Singularities of `found` that summing the indices over coincident vertices removed."""
        return self._a.coincident_removed

    @property
    def ordering(self):
        """The smoothest field's factor order: "AMD", or "coordinate dissection" where that needs fewer flops."""
        return self._a.ordering

    @property
    def pairs(self):
        """[(positive vertex, negative vertex)]: the cancelled pairs, in the order they were cancelled."""
        return list(self._a.pairs)

    @property
    def directions(self):
        """float64 (m, 3): the smoothest field's first direction per face (world coordinates; read-only)."""
        return self._get("directions", lambda: self._a.directions)

    @property
    def angles(self):
        """float64 (m,): the smoothest field's angles in the face frames (read-only)."""
        return self._get("angles", lambda: self._a.angles)

    def all_directions(self):
        """float64 (m, N, 3), read-only: the smoothest field's N directions per face ([:, 0] is `directions`)."""

        def compute():
            out = _all_directions(self._designer, self.angles, self.N)
            out[:, 0] = self.directions
            return out

        return self._get("all_directions", compute)

    @property
    def energy(self):
        """E(u) / |u|^2_M of the smoothest field over the whole mesh."""
        return self._a.energy

    @property
    def vanishing_faces(self):
        """Faces where the smoothest field vanished (they take their neighbours' direction)."""
        return self._a.vanishing_faces

    @property
    def seconds(self):
        """Seconds per stage: assemble, factor, iterate, indices, cancel."""
        return self._a.seconds



def __getattr__(name):
    # trivcon.batch on first use (PEP 562): imported with the package, `python3 -m trivcon.batch` would find
    # it in sys.modules before running it as __main__ (runpy warns).
    if name == "batch":
        import importlib

        return importlib.import_module(".batch", __name__)
    raise AttributeError(f"module 'trivcon' has no attribute {name!r}")
