#!/usr/bin/env python3
"""extend_field against scikit-fem solving the same vector Laplace problem on the same mesh.

    PYTHONPATH=build/dev/pkg python3 bench/bench_extend.py [speed|speed3d|inversions]

speed: the bundled kidney pair, diffusion mapping, then the harmonic extension on CGAL meshes of
Omega_1 at four sizes (the third about 10^5 nodes). morphomap: ``extend_field(field, mesh=(points,
cells))`` (boundary nodes, field.at, P1 assembly, one multifrontal Cholesky factorisation for both
components, inversion count). Peer: scikit-fem assembling the P1 Laplacian on the same mesh and
solving the Dirichlet problem for both components with scipy's spsolve (SuperLU) and with pyamg
(smoothed aggregation, CG, relative residual 1e-10), the boundary values taken from morphomap's
answer so that both solve the same problem; the answers are compared. Best of 3, one process.

speed3d: the lung-like pair (morphomap.synthetic.lung), auto mapping, the harmonic extension on
morphomap's Mesh_3 meshes of S1's inside at three sizes; the peer: scikit-fem on the same
tetrahedra, each component solved with pyamg (smoothed aggregation, CG, relative residual 1e-10)
and with spsolve. speed3d_large: the same at about 10^5 nodes (mesh_size=0.02), the peers timed
once (not run by default).

inversions: cells turned over by the motion, for one solve and for substeps, harmonic and
elastic, and with untangle=True, on the kidney pair (diffusion and normal fields) and the
lung-like pair.
"""

from __future__ import annotations

import sys
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


def peer(points, cells, fixed, values, solver="spsolve"):
    import scipy.sparse.linalg as sparse
    from skfem import Basis, ElementTetP1, ElementTriP1, MeshTet, MeshTri, condense
    from skfem.models.poisson import laplace

    dim = points.shape[1]
    kind, element = (MeshTri, ElementTriP1) if dim == 2 else (MeshTet, ElementTetP1)
    mesh = kind(np.ascontiguousarray(points.T), np.ascontiguousarray(cells.T), sort_t=False)
    basis = Basis(mesh, element())
    K = laplace.assemble(basis)
    out = np.zeros_like(values)
    for k in range(dim):
        x = np.zeros(len(points))
        x[fixed] = values[fixed, k]
        A, b, x_full, interior = condense(K, x=x, D=fixed)
        if solver == "pyamg":
            import pyamg

            x_full[interior] = pyamg.smoothed_aggregation_solver(A.tocsr()).solve(b, tol=1e-10, accel="cg")
        else:
            x_full[interior] = sparse.spsolve(A, b)
        out[:, k] = x_full
    return out


def boundary_nodes(cells):
    """Nodes on a side (edge, triangle) of one cell only."""
    corners = cells.shape[1]
    sides = np.sort(np.vstack([np.delete(cells, skip, axis=1) for skip in range(corners)]), axis=1)
    unique, counts = np.unique(sides, axis=0, return_counts=True)
    return np.unique(unique[counts == 1])


def speed():
    c1, c2 = mm.load_example("kidney")
    field = mm.map_curves(c1, c2, "diffusion")
    print("| nodes | triangles | morphomap s | spsolve s | spsolve / morphomap | pyamg s | pyamg / morphomap | "
          "max difference |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for size in (0.05, 0.015, 0.0065, 0.005):
        mesh = mm.extend_field(field, mesh_size=size)
        points, cells = np.array(mesh.points), np.array(mesh.cells)
        ours_s, ours = best(lambda: mm.extend_field(field, mesh=(points, cells)))
        fixed = boundary_nodes(cells)
        lu_s, lu = best(lambda: peer(points, cells, fixed, ours.displacement))
        amg_s, amg = best(lambda: peer(points, cells, fixed, ours.displacement, "pyamg"))
        difference = max(np.abs(lu - ours.displacement).max(), np.abs(amg - ours.displacement).max())
        print(f"| {len(points)} | {len(cells)} | {ours_s:.3f} | {lu_s:.3f} | {lu_s / ours_s:.2f} | {amg_s:.3f} | "
              f"{amg_s / ours_s:.2f} | {difference:.1e} |", flush=True)


def speed3d(sizes=(None, 0.05, 0.03), peer_repeat=3):
    from morphomap.synthetic.lung import lung_pair

    field = mm.map_surfaces(*lung_pair(), "auto")
    print("| nodes | tetrahedra | mesh s | morphomap s | pyamg s | ratio | spsolve s | ratio | max difference |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for size in sizes:
        mesh_s, mesh = best(lambda: mm.extend_field(field, mesh_size=size), repeat=1)
        points, cells = np.array(mesh.points), np.array(mesh.cells)
        ours_s, ours = best(lambda: mm.extend_field(field, mesh=(points, cells)))
        fixed = boundary_nodes(cells)
        amg_s, amg = best(lambda: peer(points, cells, fixed, ours.displacement, "pyamg"), peer_repeat)
        lu_s, lu = best(lambda: peer(points, cells, fixed, ours.displacement), peer_repeat)
        difference = max(np.abs(amg - ours.displacement).max(), np.abs(lu - ours.displacement).max())
        print(f"| {len(points)} | {len(cells)} | {mesh_s:.2f} | {ours_s:.3f} | {amg_s:.3f} | {amg_s / ours_s:.2f} | "
              f"{lu_s:.3f} | {lu_s / ours_s:.2f} | {difference:.1e} |", flush=True)


def inversion_row(label, field, mesh, variants):
    cells = [label, str(len(mesh[1]))]
    for options in variants:
        if options is None:
            cells.append("")
            continue
        start = time.perf_counter()
        out = mm.extend_field(field, mesh=mesh, **options)
        cells.append(f"{out.inverted} ({out.min_jacobian:.3g}, {time.perf_counter() - start:.1f} s)")
    print("| " + " | ".join(cells) + " |", flush=True)


def inversions():
    from morphomap.synthetic.lung import lung_pair

    variants = [{}, {"substeps": 4}, {"substeps": 16}, {"method": "elastic"}, {"method": "elastic", "substeps": 16},
                {"untangle": True}, {"substeps": 4, "untangle": True}]
    print("| pair, field, mesh size | cells | harmonic | 4 substeps | 16 substeps | elastic | elastic, 16 substeps | "
          "untangle | 4 substeps, untangle |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    c1, c2 = mm.load_example("kidney")
    for method in ("diffusion", "normal"):
        field = mm.map_curves(c1, c2, method)
        for size in (0.05, 0.02, 0.005):
            mesh = mm.extend_field(field, mesh_size=size)
            slow = size < 0.01  # elastic substeps take minutes there
            inversion_row(f"kidney, {method}, {size}", field, (mesh.points, mesh.cells),
                          variants[:4] + [None] + variants[5:] if slow else variants)
    s1, s2 = lung_pair()
    for method in ("auto", "diffusion"):
        field = mm.map_surfaces(s1, s2, method)
        for size in (None, 0.05):
            mesh = mm.extend_field(field, mesh_size=size)
            inversion_row(f"lung, {method}, {size or 'default'}", field, (mesh.points, mesh.cells), variants)


def speed3d_large():
    """The speed3d row at 10^5 nodes (mesh_size=0.02); the peers once each (spsolve takes ~50 s)."""
    speed3d(sizes=(0.02,), peer_repeat=1)


if __name__ == "__main__":
    tables = {"speed": speed, "speed3d": speed3d, "speed3d_large": speed3d_large, "inversions": inversions}
    for name in sys.argv[1:] or [name for name in tables if name != "speed3d_large"]:
        tables[name]()
