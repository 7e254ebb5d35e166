"""3D diffusion mapping: accuracy under refinement, and the time of its three stages.

    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_diffusion3d.py          (plain tables)
    PYTHONPATH=build/dev-NAME/pkg python3 -m pytest bench -k diffusion3d      (pytest-benchmark)

1. Concentric spheres, radius 1 inside radius 4 (icospheres of 642, 2562 and 10242 vertices): the
   streamlines are radial, so the end error of each is 4 x the angle between its start and end
   directions. RMS and max of that error by surface resolution and mesh_size (None: the default).
2. The paper's Figure 12 pair: the unit sphere (2562 vertices) onto the ellipsoid with semi-axes
   2, 1.5, 1.2 (10242 vertices): mesh, solve and trace seconds at three mesh sizes, with the
   number of tetrahedra, lost streamlines and folds.
3. Crossing surfaces: the unit sphere and the ellipsoid with semi-axes 1.3, 1, 1 centred at
   (0.6, 0.05, 0.03); no closed form, so the map back (S2 -> S1, interpolated at the images) is
   compared with the starts.
4. Organ scale (--organ): lumpy nested pairs of 10k to 200k faces per surface, end to end, with
   peak memory, beside the pipeline a user would assemble: TetGen (PyPI `tetgen`, AGPL: measured
   only, never a dependency) meshing the shell with quality switches, then scikit-fem's P1
   assembly. Each case runs in its own process; peak memory is the process's plus its children's
   (the mesher's) largest resident sets, an upper bound. --rounds N alternates N runs of each
   and reports medians (the times of both move by tens of percent with the machine's load).
5. A new bud (--bud): map_surfaces(..., "auto") on lumpy pairs of 20k and 100k faces where S2 grows
   one bud over a narrow pit of S1, so that normal mapping folds around the pit only: the share of
   the surface that folds and that auto redoes with diffusion, the time of normal mapping and of
   auto end to end, beside reverse and forward diffusion over the whole surface, and how far the
   redone ends lie from forward diffusion's.

--all-cores runs every table with repeatable=False (Mesh_3's parallel mode on all cores).
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

import numpy as np
import pytest
from scipy.spatial import cKDTree

import morphomap as mm

trimesh = pytest.importorskip("trimesh")

FIGURE12_AXES = np.array([2.0, 1.5, 1.2])
CROSSING_AXES, CROSSING_CENTRE = np.array([1.3, 1.0, 1.0]), np.array([0.6, 0.05, 0.03])
REPEATABLE = True  # False with --all-cores


def icosphere(subdivisions, axes=(1.0, 1.0, 1.0), centre=(0.0, 0.0, 0.0)):
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions)
    return np.array(mesh.vertices) * np.asarray(axes, float) + np.asarray(centre, float), np.array(mesh.faces)


def radial_errors(starts, ends, radius):
    a = starts / np.linalg.norm(starts, axis=1, keepdims=True)
    b = ends / np.linalg.norm(ends, axis=1, keepdims=True)
    return radius * np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))


def round_trip_errors(s1, s2, forward_ends, backward_ends):
    """|starts - (map S2 -> S1 interpolated on S2's triangles at the images of S1's vertices)|."""
    hits = mm.SurfaceIndex(*s2).closest_points(forward_ends)
    corners = s2[0][s2[1][hits.faces]]
    images = backward_ends[s2[1][hits.faces]]
    e1, e2, d = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0], hits.points - corners[:, 0]
    g11, g12, g22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    r1, r2 = (d * e1).sum(1), (d * e2).sum(1)
    det = g11 * g22 - g12**2
    w1, w2 = (g22 * r1 - g12 * r2) / det, (g11 * r2 - g12 * r1) / det
    back = (1 - w1 - w2)[:, None] * images[:, 0] + w1[:, None] * images[:, 1] + w2[:, None] * images[:, 2]
    return np.linalg.norm(back - s1[0], axis=1)


def timed(s1, s2, mesh_size):
    start = time.perf_counter()
    solution = mm.solve_diffusion_3d(s1, s2, mesh_size=mesh_size, repeatable=REPEATABLE)
    return solution, time.perf_counter() - start


def stages(solution):
    s = solution.seconds
    return f"{s['mesh']:6.2f} {s['solve']:6.2f} {s['trace']:6.2f}"


def concentric_table(cases):
    print("1. Concentric spheres r = 1 -> 4: end error (4 x angle) by surface vertices and mesh_size")
    print(f"{'vertices':>8} {'mesh_size':>9} {'tets':>8} {'RMS':>9} {'max':>9} {'lost':>5} {'mesh':>6} {'solve':>6} "
          f"{'trace':>6} {'total':>6}")
    for subdivisions, size in cases:
        inner, outer = icosphere(subdivisions), icosphere(subdivisions, (4.0, 4.0, 4.0))
        solution, total = timed(inner, outer, size)
        ok = np.isfinite(solution.ends).all(axis=1)
        error = radial_errors(inner[0][ok], solution.ends[ok], 4.0)
        print(f"{len(inner[0]):>8} {str(size):>9} {len(solution.tetrahedra):>8} {np.sqrt(np.mean(error**2)):>9.2e} "
              f"{error.max():>9.2e} {(~ok).sum():>5} {stages(solution)} {total:6.2f}")


def figure12_table(sizes):
    print("\n2. Unit sphere (2562 vertices) onto the ellipsoid 2, 1.5, 1.2 (10242 vertices): stage seconds")
    print(f"{'mesh_size':>9} {'tets':>8} {'lost':>5} {'folds':>5} {'|r-1| max':>9} "
          f"{'mesh':>6} {'solve':>6} {'trace':>6} {'total':>6}")
    s1, s2 = icosphere(4), icosphere(5, FIGURE12_AXES)
    for size in sizes:
        solution, total = timed(s1, s2, size)
        ok = np.isfinite(solution.ends).all(axis=1)
        off = np.abs(np.linalg.norm(solution.ends[ok] / FIGURE12_AXES, axis=1) - 1).max()
        field = mm.DisplacementField(s1[0], solution.ends, np.full(len(s1[0]), "diffusion"), faces=s1[1])
        folds = mm.quality(field, s1, s2).folds
        print(f"{str(size):>9} {len(solution.tetrahedra):>8} {(~ok).sum():>5} {folds:>5} {off:>9.2e} "
              f"{stages(solution)} {total:6.2f}")


def crossing_table(sizes):
    print("\n3. Crossing: unit sphere and ellipsoid 1.3, 1, 1 through it (2562 vertices each): round trip")
    print(f"{'mesh_size':>9} {'tets':>8} {'lost':>5} {'RMS':>9} {'max':>9} "
          f"{'mesh':>6} {'solve':>6} {'trace':>6} {'total':>6}")
    s1 = icosphere(4)
    s2 = icosphere(4, CROSSING_AXES, CROSSING_CENTRE)
    for size in sizes:
        forward, total = timed(s1, s2, size)
        backward = mm.solve_diffusion_3d(s2, s1, mesh_size=size, repeatable=REPEATABLE)
        ok = np.isfinite(forward.ends).all(axis=1)
        error = round_trip_errors(s1, s2, forward.ends, backward.ends)[ok]
        print(f"{str(size):>9} {len(forward.tetrahedra):>8} {(~ok).sum():>5} {np.sqrt(np.mean(error**2)):>9.2e} "
              f"{error.max():>9.2e} {stages(forward)} {total:6.2f}")


def geodesic_sphere(frequency):
    """The unit sphere with each icosahedron face cut into frequency**2 triangles (20 f**2 faces)."""
    ico = trimesh.creation.icosahedron()
    n = frequency
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    i, j = i[keep], j[keep]
    index = -np.ones((n + 1, n + 1), int)
    index[i, j] = np.arange(len(i))
    a, b = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    up, down = a + b < n, a + b < n - 1
    local = np.vstack([np.stack([index[a[up], b[up]], index[a[up] + 1, b[up]], index[a[up], b[up] + 1]], 1),
                       np.stack([index[a[down] + 1, b[down]], index[a[down] + 1, b[down] + 1],
                                 index[a[down], b[down] + 1]], 1)])
    corners = ico.vertices[ico.faces]
    points = np.vstack([p + np.outer(i / n, q - p) + np.outer(j / n, r - p) for p, q, r in corners])
    faces = np.vstack([local + k * len(i) for k in range(len(corners))])
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    _, first, inverse = np.unique(np.round(points, 9), axis=0, return_index=True, return_inverse=True)
    return points[first], inverse.reshape(-1)[faces]


def lumpy_radius(directions, seed, amplitude):
    """1 plus eight Gaussian bumps and dents of random axes and widths."""
    rng = np.random.default_rng(seed)
    r = np.ones(len(directions))
    for _ in range(8):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        width, height = rng.uniform(0.3, 0.7), amplitude * rng.uniform(-1, 1)
        r += height * np.exp(-0.5 * (np.arccos(np.clip(directions @ axis, -1, 1)) / width) ** 2)
    return r


def lumpy_nested_pair(faces):
    """A lumpy ball of radius about 1 inside one of radius about 2, each with about `faces` faces."""
    u, triangles = geodesic_sphere(int(np.sqrt(faces / 20) + 0.5))
    return (u * lumpy_radius(u, 1, 0.15)[:, None], triangles), (2.0 * u * lumpy_radius(u, 2, 0.15)[:, None], triangles)


def bud_pair(faces):
    """The lumpy inner surface of lumpy_nested_pair with a narrow pit; S2 = 1.15 x it, plus a bud over the pit."""
    u, triangles = geodesic_sphere(int(np.sqrt(faces / 20) + 0.5))
    lumpy = lumpy_radius(u, 1, 0.15)
    axis = np.array([0.3, -0.5, 0.81])
    angle = np.arccos(np.clip(u @ (axis / np.linalg.norm(axis)), -1, 1))
    pit = 0.25 * np.exp(-0.5 * (angle / 0.06) ** 2)
    bud = 0.6 * np.exp(-0.5 * (angle / 0.3) ** 2)
    return (u * (lumpy - pit)[:, None], triangles), (u * (1.15 * lumpy + bud)[:, None], triangles)


def bud_table(sizes):
    """Normal mapping on the bud pair (its folds); auto, which keeps it and diffuses near the folds
    only; and the whole-surface diffusions auto used before (reverse) and that the local part is
    measured against (forward): time, and the distance of the inner redone ends (a gap or more from
    the normal part, not blended) from the forward ones."""
    print("\n5. A new bud: auto (normal, diffusion near its folds) beside diffusion over the whole surface")
    print("   faces  folded  normal s  auto s  redone  | reverse s  forward s  forward tets  "
          "| inner local - forward RMS  max  (mean gap)  | auto folds lost")
    for faces in sizes:
        (v1, f1), (v2, f2) = bud_pair(faces)
        s1, s2 = trimesh.Trimesh(v1, f1, process=False), trimesh.Trimesh(v2, f2, process=False)
        gap = (s2.volume - s1.volume) / (0.5 * (s1.area + s2.area))
        start = time.perf_counter()
        normal = mm.map_surfaces(s1, s2, "normal")
        normal_seconds = time.perf_counter() - start
        folded = mm.quality(normal, s1, s2).folds
        start = time.perf_counter()
        auto = mm.map_surfaces(s1, s2, "auto", repeatable=REPEATABLE)
        auto_seconds = time.perf_counter() - start
        q = mm.quality(auto, s1, s2)
        redone = np.asarray(auto.method) != "normal"
        start = time.perf_counter()
        mm.map_surfaces(s1, s2, "diffusion", reverse=True, repeatable=REPEATABLE)
        reverse_seconds = time.perf_counter() - start
        start = time.perf_counter()
        forward = mm.solve_diffusion_3d(s1, s2, repeatable=REPEATABLE)
        forward_seconds = time.perf_counter() - start
        # The vertices a gap or more inside the redone part have diffusion's ends, not a blend.
        inner = redone.copy()
        if (~redone).any():
            inner[redone] = cKDTree(v1[~redone]).query(v1[redone])[0] >= gap
        gone = np.linalg.norm(np.asarray(auto.ends)[inner] - forward.ends[inner], axis=1)
        print(f"  {len(f1):>6,}  {folded:>6,}  {normal_seconds:>8.1f}  {auto_seconds:>6.1f}  {redone.mean():>6.1%}  "
              f"| {reverse_seconds:>9.1f}  {forward_seconds:>9.1f}  {len(forward.tetrahedra):>12,}  "
              f"| {inner.sum():>5} {np.sqrt(np.mean(gone ** 2)) if len(gone) else 0:>19.2e}  "
              f"{gone.max(initial=0):.2e}  ({gap:.3f})  "
              f"| {q.folds} {int((~auto.valid).sum())}  methods {', '.join(sorted(map(str, set(auto.method))))}")


def peak_memory_gb():
    """Largest resident sets of this process and of its children (the mesher), summed: GB."""
    kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss + resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return kb / 2**20


def cpu_seconds():
    """User and system time of this process and its children (the mesher)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def organ_morphomap(faces):
    s1, s2 = lumpy_nested_pair(faces)
    cpu = cpu_seconds()
    solution, total = timed(s1, s2, None)
    cpu = cpu_seconds() - cpu
    lost = int((~np.isfinite(solution.ends).all(axis=1)).sum())
    field = mm.DisplacementField(s1[0], np.nan_to_num(solution.ends), np.full(len(s1[0]), "diffusion"), faces=s1[1])
    return {"faces": len(s1[1]), "tetrahedra": len(solution.tetrahedra), **solution.seconds, "total": total, "cpu": cpu,
            "lost": lost, "folds": int(mm.quality(field, s1, s2).folds), "memory": peak_memory_gb()}


def organ_peer(faces):
    """TetGen on both surfaces (the shell: a hole inside S1), then scikit-fem's P1 stiffness matrix."""
    import skfem
    import tetgen
    from skfem.models.poisson import laplace

    (v1, f1), (v2, f2) = lumpy_nested_pair(faces)
    cpu = cpu_seconds()
    start = time.perf_counter()
    generator = tetgen.TetGen(np.vstack([v1, v2]), np.vstack([f1, f2 + len(v1)]).astype(np.int32))
    generator.add_hole([0.0, 0.0, 0.0])
    nodes, elements = generator.tetrahedralize(quality=True, minratio=1.5, mindihedral=10.0)[:2]
    meshed = time.perf_counter()
    basis = skfem.Basis(skfem.MeshTet(nodes.T, elements.T.astype(np.int64)), skfem.ElementTetP1())
    skfem.asm(laplace, basis)
    assembled = time.perf_counter()
    return {"faces": len(f1), "tetrahedra": len(elements), "mesh": meshed - start, "assembly": assembled - meshed,
            "cpu": cpu_seconds() - cpu, "memory": peak_memory_gb()}


def median_run(runs):
    """Each figure's median over the rounds (the first error, if a round failed)."""
    failed = [run for run in runs if "error" in run]
    if failed:
        return failed[0]
    return {key: float(np.median([run[key] for run in runs])) for key in runs[0]}


def organ_table(sizes, peer_sizes, rounds=1):
    """Each case in a fresh process (peak memory of its own), the peer beside it; with rounds > 1,
    morphomap and the peer alternate, each figure is the median of the rounds, and the last column
    gives the ratio's range over the rounds (both sides' times move with the machine's load)."""
    def run(kind, faces):
        command = [sys.executable, __file__, "--case", kind, str(faces)] + ([] if REPEATABLE else ["--all-cores"])
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            return {"error": done.stderr.strip().splitlines()[-1:]}
        return json.loads(done.stdout.strip().splitlines()[-1])

    print("\n4. Lumpy nested pairs (radius ~1 in ~2): end to end, and TetGen + scikit-fem assembly"
          + ("" if REPEATABLE else " (morphomap: repeatable=False)")
          + (f"; medians of {rounds} alternated rounds" if rounds > 1 else ""))
    print("| faces per surface | tetrahedra | mesh s | solve s | trace s | total s | CPU s | lost | folds "
          "| peak memory GB | TetGen tetrahedra | TetGen s | assembly s | peer CPU s | peer memory GB "
          "| peer / morphomap (wall, CPU) |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    totals = []
    for faces in sizes:
        ours_runs, peer_runs = [], []
        for _ in range(rounds):
            ours_runs.append(run("morphomap", faces))
            if faces in peer_sizes:
                peer_runs.append(run("peer", faces))
        ours, peer = median_run(ours_runs), median_run(peer_runs) if peer_runs else None
        if "error" in ours:
            print(f"| {faces:,} | {ours['error']} |", flush=True)
            continue
        totals.append((ours["faces"], ours["cpu"]))
        row = (f"| {ours['faces']:,.0f} | {ours['tetrahedra']:,.0f} | {ours['mesh']:.1f} | {ours['solve']:.2f} | "
               f"{ours['trace']:.2f} | {ours['total']:.1f} | {ours['cpu']:.1f} | {ours['lost']:.0f} | "
               f"{ours['folds']:.0f} | {ours['memory']:.2f} |")
        if peer and "error" not in peer:
            ratio = (peer["mesh"] + peer["assembly"]) / ours["total"]
            row += (f" {peer['tetrahedra']:,.0f} | {peer['mesh']:.1f} | {peer['assembly']:.1f} | {peer['cpu']:.1f} | "
                    f"{peer['memory']:.2f} | {ratio:.1f}x, {peer['cpu'] / ours['cpu']:.1f}x")
            if rounds > 1:
                each = [(p["mesh"] + p["assembly"]) / o["total"] for o, p in zip(ours_runs, peer_runs)]
                row += f" (wall {min(each):.1f}-{max(each):.1f}x)"
            row += " |"
        else:
            row += f" {peer['error'] if peer else 'not run'} | | | | | |"
        print(row, flush=True)
    if len(totals) >= 2:
        (n0, t0), (n1, t1) = totals[0], totals[-1]
        print(f"growth exponent of the total CPU time from {n0:,.0f} to {n1:,.0f} faces: "
              f"{np.log(t1 / t0) / np.log(n1 / n0):.2f}")


@pytest.mark.parametrize("case", ("concentric", "figure12", "crossing"))
def test_diffusion3d_default(benchmark, case):
    if case == "concentric":
        s1, s2 = icosphere(4), icosphere(4, (4.0, 4.0, 4.0))
    elif case == "figure12":
        s1, s2 = icosphere(4), icosphere(5, FIGURE12_AXES)
    else:
        s1, s2 = icosphere(4), icosphere(4, CROSSING_AXES, CROSSING_CENTRE)
    benchmark.group = "diffusion3d default mesh"
    solution = benchmark.pedantic(mm.solve_diffusion_3d, args=(s1, s2), rounds=1, iterations=1)
    benchmark.extra_info.update(solution.seconds)
    benchmark.extra_info["tetrahedra"] = len(solution.tetrahedra)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="default mesh sizes only")
    parser.add_argument("--organ", action="store_true", help="only the organ-scale table (4), ~10 min")
    parser.add_argument("--bud", nargs="*", type=int, metavar="FACES",
                        help="only the new-bud table (5); faces per surface (default 20000 100000)")
    parser.add_argument("--all-cores", action="store_true", help="repeatable=False: Mesh_3 on all cores")
    parser.add_argument("--rounds", type=int, default=1, metavar="N",
                        help="--organ: N alternated rounds of morphomap and the peer, medians (default 1)")
    parser.add_argument("--case", nargs=2, metavar=("KIND", "FACES"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    global REPEATABLE
    REPEATABLE = not args.all_cores
    if args.case:
        kind, faces = args.case[0], int(args.case[1])
        print(json.dumps(organ_morphomap(faces) if kind == "morphomap" else organ_peer(faces)))
        return
    if args.bud is not None:
        bud_table(args.bud or [20_000, 100_000])
        return
    if args.organ:
        organ_table([10_000, 20_000, 100_000, 200_000], {20_000, 100_000, 200_000}, max(1, args.rounds))
        return
    # mesh_size only caps the size: near the surfaces the mesh follows their spacing (inner sphere
    # 0.077, outer 0.31, ellipsoid 0.05), so the caps below are what refines it.
    concentric_table([(4, None)] if args.quick else [(3, None), (4, None), (5, None), (4, 0.3), (4, 0.2), (4, 0.15)])
    figure12_table([None] if args.quick else [None, 0.08, 0.05])
    crossing_table([None] if args.quick else [0.1, None, 0.04])


if __name__ == "__main__":
    main()
