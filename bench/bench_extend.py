#!/usr/bin/env python3
"""extend_field against scikit-fem solving the same vector Laplace problem on the same mesh.

    PYTHONPATH=build/dev/pkg python3 bench/bench_extend.py

The bundled kidney pair, diffusion mapping, then the harmonic extension on CGAL meshes of
Omega_1 at three sizes. morphomap: ``extend_field(field, mesh=(points, cells))`` (boundary nodes,
field.at, P1 assembly, one LDL^T for both components, inversion count). Peer: scikit-fem
assembling the P1 Laplacian on the same mesh and solving the Dirichlet problem for both
components with scipy's spsolve (SuperLU), the boundary values taken from morphomap's answer so
that both solve the same problem; the answers are compared. Best of 3, one process.
"""

from __future__ import annotations

import time

import numpy as np

import morphomap as mm


def best(function, repeat=3):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def peer(points, cells, fixed, values):
    import scipy.sparse.linalg as sparse
    from skfem import Basis, ElementTriP1, MeshTri, condense
    from skfem.models.poisson import laplace

    mesh = MeshTri(np.ascontiguousarray(points.T), np.ascontiguousarray(cells.T), sort_t=False)
    basis = Basis(mesh, ElementTriP1())
    K = laplace.assemble(basis)
    out = np.zeros_like(values)
    for k in range(2):
        x = np.zeros(len(points))
        x[fixed] = values[fixed, k]
        A, b, x_full, interior = condense(K, x=x, D=fixed)
        x_full[interior] = sparse.spsolve(A, b)
        out[:, k] = x_full
    return out


def main():
    c1, c2 = mm.load_example("kidney")
    field = mm.map_curves(c1, c2, "diffusion")
    print("| nodes | triangles | morphomap s | scikit-fem s | scikit-fem / morphomap | max difference |")
    print("|---:|---:|---:|---:|---:|---:|")
    for size in (0.05, 0.015, 0.005):
        mesh = mm.extend_field(field, mesh_size=size)
        points, cells = np.array(mesh.points), np.array(mesh.cells)
        ours_s, ours = best(lambda: mm.extend_field(field, mesh=(points, cells)))
        edges = np.sort(np.vstack([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
        unique, counts = np.unique(edges, axis=0, return_counts=True)
        fixed = np.unique(unique[counts == 1])
        peer_s, theirs = best(lambda: peer(points, cells, fixed, ours.displacement))
        difference = np.abs(theirs - ours.displacement).max()
        print(f"| {len(points)} | {len(cells)} | {ours_s:.3f} | {peer_s:.3f} | {peer_s / ours_s:.2f} | {difference:.1e} |")


if __name__ == "__main__":
    main()
