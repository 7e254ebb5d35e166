"""A reaction-diffusion model solved on a growing domain: the paper's Figure 1 d -> e -> f.

    python -m morphomap.examples.growing_kidney      (needs scikit-fem: pip install scikit-fem)

The bundled kidney pair gives the boundary at t = 0 and t = 1; morphomap maps C1 onto C2
(diffusion: bijective), extends the boundary displacement U into the domain Omega_1 (harmonic)
and the mesh of Omega_1 moves along x(t) = X + t U(X) in substeps, so that its nodes move with
the velocity u = U. There c obeys

    dc/dt + div(u c) = D lap(c)   in Omega(t),   D grad(c) . n = 0 on the boundary (no flux),

which, with test functions that move with the mesh, is d/dt (M(t) c) = -D K(t) c (M, K the P1 mass
and stiffness matrices on the moved mesh; the advection is carried by the mesh motion). Backward
Euler, M(t + dt) c' = M(t) c - dt D K(t + dt) c', keeps the total mass 1^T M c exactly: K has
zero row sums. scikit-fem assembles the matrices.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as sparse

import morphomap as mm


def run(steps: int = 20, diffusivity: float = 0.01, mesh_size: float = 0.05):
    """Solve the growing-domain problem; returns a dict with the masses, the nodes and cells,
    the final concentration and the smallest cell area seen (negative: an inverted cell)."""
    from skfem import Basis, BilinearForm, ElementTriP1, MeshTri
    from skfem.helpers import dot, grad

    c1, c2 = mm.load_example("kidney")
    field = mm.map_curves(c1, c2, "diffusion")
    interior = mm.extend_field(field, mesh_size=mesh_size)
    X, U, cells = interior.points, interior.displacement, interior.cells

    @BilinearForm
    def mass(u, v, _):
        return u * v

    @BilinearForm
    def stiffness(u, v, _):
        return dot(grad(u), grad(v))

    def matrices(t):
        mesh = MeshTri(np.ascontiguousarray((X + t * U).T), np.ascontiguousarray(cells.T), sort_t=False)
        basis = Basis(mesh, ElementTriP1())
        return mass.assemble(basis), stiffness.assemble(basis)

    def areas(t):
        # Signed, in the cells' own (counter-clockwise) order: negative once a cell is turned over.
        p = (X + t * U)[cells]
        return 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                      - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))

    # A blob of morphogen near the trunk of the kidney.
    c = np.exp(-np.sum((X - np.array([0.0, -0.6])) ** 2, axis=1) / 0.05)
    M, _ = matrices(0.0)
    masses, smallest = [float(np.sum(M @ c))], float(np.min(areas(0.0)))
    dt = 1.0 / steps
    for k in range(1, steps + 1):
        M_next, K_next = matrices(k * dt)
        smallest = min(smallest, float(np.min(areas(k * dt))))
        c = sparse.spsolve((M_next + dt * diffusivity * K_next).tocsc(), M @ c)
        M = M_next
        masses.append(float(np.sum(M @ c)))
    return {"masses": np.array(masses), "points": X + U, "cells": cells, "concentration": c,
            "smallest_area": smallest, "inverted": interior.inverted}


def main():
    result = run()
    drift = np.abs(result["masses"] / result["masses"][0] - 1).max()
    print(f"kidney pair, {len(result['points'])} nodes, {len(result['cells'])} triangles, 20 substeps: "
          f"largest relative change of the total mass {drift:.2e}, smallest triangle area "
          f"{result['smallest_area']:.3g} (inverted after the motion: {result['inverted']})")


if __name__ == "__main__":
    main()
