# SPDX-License-Identifier: MIT
"""An independent reference for the tests: the paper's quantities recomputed in numpy from (V, F) alone.

Nothing here calls trivcon: frames, corner angles, angle defects, edges with their faces, the Levi-Civita
rotation rho, the holonomy of a connection around every vertex, the transport of a field across every edge,
and the indices of a per-face field are computed from the positions and the conventions of docs/explanation/conventions.md.
"""

import math
from fractions import Fraction

import numpy as np

TWO_PI = 2 * math.pi


def wrap(a):
    """Angles into (-pi, pi]."""
    a = np.mod(np.asarray(a, dtype=float) + math.pi, TWO_PI) - math.pi
    return np.where(a <= -math.pi, a + TWO_PI, a)


def reduce(a, N):
    """Angles into (-pi/N, pi/N] modulo 2 pi / N."""
    period = TWO_PI / N
    r = np.mod(np.asarray(a, dtype=float) + period / 2, period) - period / 2
    return np.where(r <= -period / 2, r + period, r)


class Mesh:
    """Geometry of an oriented triangle mesh (F as FieldDesigner.F)."""

    def __init__(self, V, F):
        self.V = np.asarray(V, dtype=float)
        self.F = np.asarray(F, dtype=np.int64)
        p = [self.V[self.F[:, k]] for k in range(3)]
        n = np.cross(p[1] - p[0], p[2] - p[0])
        self.normal = n / np.linalg.norm(n, axis=1, keepdims=True)
        e0 = p[1] - p[0]
        self.X = e0 / np.linalg.norm(e0, axis=1, keepdims=True)
        self.Y = np.cross(self.normal, self.X)
        # Corner angles and angle defects.
        self.corner = np.zeros(self.F.shape)
        for k in range(3):
            a, b = p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]
            self.corner[:, k] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
        nv = self.V.shape[0]
        angle_sum = np.zeros(nv)
        np.add.at(angle_sum, self.F.ravel(), self.corner.ravel())
        # Edges (i < j) with L (holds i -> j) and R (holds j -> i).
        faces = {}
        for f, tri in enumerate(self.F):
            for k in range(3):
                a, b = int(tri[k]), int(tri[(k + 1) % 3])
                key = (min(a, b), max(a, b))
                slot = 0 if a < b else 1
                faces.setdefault(key, [-1, -1])[slot] = f
        self.edges = np.array(sorted(faces), dtype=np.int64).reshape(-1, 2)
        self.edge_faces = np.array([faces[tuple(e)] for e in self.edges], dtype=np.int64).reshape(-1, 2)
        self.interior = (self.edge_faces >= 0).all(axis=1)
        boundary = np.zeros(nv, dtype=bool)
        boundary[self.edges[~self.interior].ravel()] = True
        used = np.zeros(nv, dtype=bool)
        used[self.F.ravel()] = True
        self.interior_vertex = used & ~boundary
        self.defect = np.where(self.interior_vertex, TWO_PI - angle_sum, 0.0)
        # rho per interior edge: the angle of p_j - p_i in R's frame minus its angle in L's frame.
        e = self.edges[self.interior]
        L, R = self.edge_faces[self.interior, 0], self.edge_faces[self.interior, 1]
        t = self.V[e[:, 1]] - self.V[e[:, 0]]
        self.interior_edges = e
        self.L, self.R = L, R
        self.rho = wrap(self.angle_in(R, t) - self.angle_in(L, t))

    def angle_in(self, faces, vectors):
        return np.arctan2(np.einsum("ij,ij->i", vectors, self.Y[faces]), np.einsum("ij,ij->i", vectors, self.X[faces]))

    def angles_of(self, directions):
        """Angles of world vectors (one per face) in the face frames."""
        return self.angle_in(np.arange(self.F.shape[0]), np.asarray(directions, dtype=float))

    def vertex_holonomy_residual(self, edges, x, singularities):
        """max over interior vertices of |sum_e s x_e - (K_v - 2 pi k_v)| (docs/explanation/conventions.md, "Connection")."""
        edges = np.asarray(edges)
        index = {tuple(e): k for k, e in enumerate(edges)}
        assert len(index) == len(self.interior_edges)
        xs = np.array([x[index[tuple(e)]] for e in self.interior_edges])
        total = np.zeros(self.V.shape[0])
        np.add.at(total, self.interior_edges[:, 1], xs)  # v the larger id: s = +1
        np.add.at(total, self.interior_edges[:, 0], -xs)
        k = np.zeros(self.V.shape[0])
        for v, idx in singularities.items():
            k[v] = float(idx)
        want = self.defect - TWO_PI * k
        return float(np.abs(total - want)[self.interior_vertex].max())

    def transport_mismatch(self, edges, x, angles, N):
        """max over interior edges of |beta_R - (beta_L + rho - x)| modulo 2 pi / N."""
        index = {tuple(e): k for k, e in enumerate(np.asarray(edges))}
        xs = np.array([x[index[tuple(e)]] for e in self.interior_edges])
        angles = np.asarray(angles)
        return float(np.abs(reduce(angles[self.R] - angles[self.L] - self.rho + xs, N)).max())

    def field_indices(self, directions, N):
        """{vertex: Fraction} of a per-face field: jumps reduced to (-pi/N, pi/N], index (K + sum s d) / 2 pi."""
        beta = self.angles_of(directions)
        return self.indices_from_jumps(reduce(beta[self.R] - beta[self.L] - self.rho, N), N)

    def indices_from_jumps(self, jump, N):
        """{vertex: Fraction}: (K + sum s d) / 2 pi from the jumps d per interior edge (a whole multiple of 1/N)."""
        total = np.zeros(self.V.shape[0])
        np.add.at(total, self.interior_edges[:, 1], jump)
        np.add.at(total, self.interior_edges[:, 0], -jump)
        raw = (self.defect + total) / TWO_PI * N
        n = np.rint(raw)
        assert np.abs(raw - n)[self.interior_vertex].max() < 1e-6
        return {int(v): Fraction(int(n[v]), N) for v in np.flatnonzero(self.interior_vertex & (n != 0))}


def indices_with_matching(mesh, directions, N, edges, matching):
    """{vertex: Fraction} of a per-face field read with a given matching (trivcon/matching.h): per interior
    edge (rows of `edges`), d = beta_R + 2 pi m / N - beta_L - rho in (-pi, pi]; index (K + sum s d) / 2 pi."""
    beta = mesh.angles_of(directions)
    index = {tuple(e): k for k, e in enumerate(np.asarray(edges))}
    m = np.array([matching[index[tuple(e)]] for e in mesh.interior_edges], dtype=float)
    return mesh.indices_from_jumps(wrap(beta[mesh.R] + TWO_PI * m / N - beta[mesh.L] - mesh.rho), N)


def valence(F, num_vertices):
    count = np.zeros(num_vertices, dtype=np.int64)
    np.add.at(count, np.asarray(F).ravel(), 1)
    return count
