# SPDX-License-Identifier: MIT
"""A complete trivcon session in Python: read a mesh, solve a cross field, edit the singularities and
re-solve, check the result, write the field in the CLI's formats, and render pictures.

    python3 examples/cross_field.py                        # data/cube_sphere.obj with data/cube_sphere.sing
    python3 examples/cross_field.py mesh.obj --out DIR     # your mesh, singularities found automatically
    python3 examples/cross_field.py mesh.obj -s mesh.sing  # your mesh and singularities

Install the module first (docs/tutorials/python.md): pip install --no-build-isolation . in a venv.
"""

import argparse
import os
import numpy as np

import trivcon

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", default=os.path.join(HERE, "..", "data", "cube_sphere.obj"))
    parser.add_argument("-s", "--singularities", help="singularity file (default: data/cube_sphere.sing for the default mesh, "
                        "else automatic)")
    parser.add_argument("--out", default="examples-output", help="output folder (default examples-output)")
    a = parser.parse_args()
    if a.singularities is None and a.mesh == parser.get_default("mesh"):
        a.singularities = os.path.join(HERE, "..", "data", "cube_sphere.sing")
    os.makedirs(a.out, exist_ok=True)

    # Read and prepare: validation, geometry, cycles and the factorization happen once, here.
    V, F = trivcon.read_mesh(a.mesh)
    designer = trivcon.FieldDesigner(V, F)
    print(designer)

    # Solve: a cross field (N = 4) with the given singularities, or those of the smoothest cross field.
    if a.singularities:
        sings = trivcon.read_singularities(a.singularities, N=4)
    else:
        sings = designer.auto_singularities(N=4, cancel=2).singularities
    r = designer.solve(N=4, singularities=sings)
    print("solved:", r)
    print("  singularities", {v: str(i) for v, i in r.singularities.items()})
    print(f"  energy {r.energy:.6g}, residual {r.residual:.2e} rad, {len(r.edges)} interior edges")

    # Edit: move the first singularity halfway towards the second (to the nearest free interior vertex) and
    # re-solve: milliseconds, only the right-hand side changes. Indices may be Fractions, floats, ints or "p/q".
    a_vertex, b_vertex = sorted(sings)[:2]
    taken = set(sings) | set(designer.boundary_vertices.tolist()) | set(designer.unreferenced_vertices.tolist())
    distance = np.linalg.norm(V - (V[a_vertex] + V[b_vertex]) / 2, axis=1)
    target = next(int(v) for v in np.argsort(distance) if int(v) not in taken)
    edited = dict(sings)
    edited[target] = edited.pop(a_vertex)
    print(f"moving the singularity at vertex {a_vertex} to vertex {target}")
    r2 = designer.solve(N=4, singularities=edited)
    print("edited:", r2)

    # Check: the indices read back from the field itself are the prescription (as `trivcon check` does).
    for result in (r, r2):
        found = trivcon.field_indices(V, F, result.directions, N=4)
        assert result.large_turn_edges > 0 or found == result.singularities, (found, result.singularities)
        assert result.verified

    # The arrays: unit directions per face, angles in the face frames, the connection per interior edge.
    X, Y, normal = designer.face_frames()
    assert np.allclose(r.directions, np.cos(r.angles)[:, None] * X + np.sin(r.angles)[:, None] * Y)
    assert np.all(r.edges[:, 0] < r.edges[:, 1])

    # Write: the CLI's files (exactly what `trivcon solve --field-out/--connection-out/--sing-out` writes).
    r.write_field(os.path.join(a.out, "field.txt"))
    r.write_connection(os.path.join(a.out, "connection.txt"))
    r.write_singularities(os.path.join(a.out, "field.sing"))
    trivcon.write_field(os.path.join(a.out, "edited.rawfield"), V, F, r2.directions, N=4)  # any (m, 3) directions

    # Render: (h, w, 3) uint8 images, saved as PNG.
    trivcon.write_png(os.path.join(a.out, "field.png"), r.render(size=(800, 600)))
    trivcon.write_png(os.path.join(a.out, "edited.png"),
                      trivcon.render(V, F, r2.directions, N=4, size=(800, 600), style="streamlines", singularities=edited))
    print("wrote", ", ".join(sorted(os.listdir(a.out))), "to", a.out)


if __name__ == "__main__":
    main()
