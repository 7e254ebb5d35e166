"""The paper's Eq. 2 on a growing domain, solved in dolfinx on a mesh that moves with morphomap's field.

    python -m morphomap.examples.growing_frames OUT             # morphomap: the motion, OUT/motion.xdmf
    python3 growing_domain_fenicsx.py OUT                        # dolfinx: this file, by its path

(or ``python -m morphomap.examples.growing_domain_fenicsx OUT`` where one Python has both; it
makes the motion first when ``OUT/motion.xdmf`` is missing). On the domain Omega(t) of the frames,

    dc/dt + div(u c) = D lap(c)   in Omega(t),   D grad(c) . n = 0 on the boundary (no flux),

with u the velocity of the mesh: within step k the nodes move along x(s) = X_k + s U_k (U_k the
interior displacement, s from 0 to 1 over the step's time). With test functions that move with
the mesh the advection is carried by the motion, d/dt (M(t) c) = -D K(t) c (M, K the P1 mass and
stiffness matrices on the moved mesh), and backward Euler, M(t + dt) c' = M(t) c - dt D K(t + dt)
c', keeps the total mass 1^T M c: K has zero row sums. Writes ``OUT/concentration.xdmf`` (dolfinx's
own writer, one function per step on the moved mesh) and ``OUT/concentration.png`` (the last
frame), and prints a JSON summary: the total mass per substep and its largest relative change.

This file imports only dolfinx, numpy, h5py and matplotlib, and loads morphomap's dolfinx helper
(:mod:`morphomap.io.fenicsx`) by its path, so it runs in a Python that has dolfinx (Debian's
``python3-dolfinx``) but not morphomap's other dependencies.
"""

from __future__ import annotations

import importlib.util
import json
import os
import sys

import numpy as np


def _helper():
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "io", "fenicsx.py")
    spec = importlib.util.spec_from_file_location("morphomap_fenicsx_helper", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def solve(folder, diffusivity: float = 0.01, substeps: int = 10, centre=(1.0, 0.5, 0.0), width: float = 0.3):
    """Solve Eq. 2 through the steps of ``folder/motion.xdmf`` (2D or 3D); returns a dict of the
    masses (one per substep and the start), the mesh and the final concentration."""
    import ufl
    from dolfinx import fem, io
    from dolfinx.fem.petsc import assemble_matrix
    from mpi4py import MPI
    from petsc4py import PETSc

    helper = _helper()
    motion = os.path.join(folder, "motion.xdmf")
    with io.XDMFFile(MPI.COMM_WORLD, motion, "r") as xdmf:
        mesh = xdmf.read_mesh()
    times = helper.read_times(motion)
    dt_step = times[1] - times[0] if len(times) > 1 else 1.0
    gdim = mesh.geometry.dim
    nodes = np.asarray(mesh.geometry.input_global_indices)
    space = fem.FunctionSpace(mesh, ("Lagrange", 1))
    c = fem.Function(space, name="c")
    c.interpolate(lambda x: np.exp(-sum((x[i] - centre[i]) ** 2 for i in range(len(centre))) / width ** 2))
    u, v = ufl.TrialFunction(space), ufl.TestFunction(space)
    dt = dt_step / substeps
    mass_form = fem.form(u * v * ufl.dx)
    system_form = fem.form((u * v + dt * diffusivity * ufl.inner(ufl.grad(u), ufl.grad(v))) * ufl.dx)
    total = fem.form(c * ufl.dx)
    solver = PETSc.KSP().create(mesh.comm)
    solver.setType("preonly")
    solver.getPC().setType("lu")
    masses = [mesh.comm.allreduce(fem.assemble_scalar(total), op=MPI.SUM)]
    out = io.XDMFFile(mesh.comm, os.path.join(folder, "concentration.xdmf"), "w")
    out.write_mesh(mesh)
    out.write_function(c, times[0])
    for k, time in enumerate(times):
        displacement = helper.read_point_data(motion, time=time)[nodes, :gdim]
        start = mesh.geometry.x[:, :gdim].copy()
        for j in range(1, substeps + 1):
            mass = assemble_matrix(mass_form)
            mass.assemble()
            rhs = mass.createVecLeft()
            mass.mult(c.vector, rhs)
            # The mesh moves: the forms are assembled on the nodes' new positions.
            mesh.geometry.x[:, :gdim] = start + (j / substeps) * displacement
            system = assemble_matrix(system_form)
            system.assemble()
            solver.setOperators(system)
            solver.solve(rhs, c.vector)
            c.x.scatter_forward()
            masses.append(mesh.comm.allreduce(fem.assemble_scalar(total), op=MPI.SUM))
        out.write_function(c, time + dt_step)
    out.close()
    masses = np.array(masses)
    return {"masses": masses, "drift": float(np.abs(masses / masses[0] - 1).max()), "mesh": mesh, "c": c,
            "steps": len(times), "substeps": substeps}


def plot(result, path):
    """The concentration on the last frame, on the moved mesh (3D: the tetrahedra's corners
    within a thin slab about z = 0)."""
    # This file runs in the Python that has dolfinx, by its path, where matplotlib is an extra;
    # the backend is chosen before pyplot is imported.
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mesh, c = result["mesh"], result["c"]
    width = mesh.topology.dim + 1
    corners = np.asarray(getattr(mesh.geometry.dofmap, "array", mesh.geometry.dofmap)).reshape(-1, width)
    dofs = np.asarray(getattr(c.function_space.dofmap.list, "array", c.function_space.dofmap.list)).reshape(-1, width)
    values = np.empty(mesh.geometry.x.shape[0])
    values[corners.ravel()] = c.x.array[dofs.ravel()]
    x = mesh.geometry.x
    figure, axes = plt.subplots(figsize=(6, 5), layout="constrained")
    if width == 3:
        shading = axes.tripcolor(x[:, 0], x[:, 1], corners, values, shading="gouraud", cmap="viridis")
        axes.triplot(x[:, 0], x[:, 1], corners, color="white", linewidth=0.1, alpha=0.4)
    else:
        slab = np.abs(x[:, 2]) < 0.1
        shading = axes.scatter(x[slab, 0], x[slab, 1], c=values[slab], s=12, cmap="viridis")
    axes.set_aspect("equal")
    axes.set_title(f"c on the last frame; total mass kept to {result['drift']:.1e}")
    figure.colorbar(shading, ax=axes, label="c")
    figure.savefig(path, dpi=120)
    plt.close(figure)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    folder = argv[0] if argv else "growing-frames"
    if not os.path.exists(os.path.join(folder, "motion.xdmf")):
        # Only where one Python has both: dolfinx's own Python need not have morphomap.
        from morphomap.examples.growing_frames import prepare

        prepare(folder)
    result = solve(folder)
    plot(result, os.path.join(folder, "concentration.png"))
    print(json.dumps({"steps": result["steps"], "substeps": result["substeps"],
                      "nodes": int(result["mesh"].geometry.x.shape[0]), "masses": result["masses"].tolist(),
                      "drift": result["drift"], "peak": float(result["c"].x.array.max())}))


if __name__ == "__main__":
    main()
