"""Time series and batches: `map_series` against the same pairs mapped one by one, and `map_batch`
on a local Dask cluster against a sequential loop.

    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_series.py            (plain tables)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_series.py --quick    (fewer batch pairs)

1. A 10-frame 2D series, 1,000 points per curve (a circle growing three buds, `method="auto"`):
   per step, `map_series`' own seconds (mapping + quality, from its table) and a plain
   `map_curves` call on the same pair, and `quality` on its field; the totals, and `map_series`'
   whole time (carrying the points, the growth maps and re-seeding included).
2. A 5-frame 3D series, 5,120 faces per surface (an icosphere growing a bud), the same with
   `map_surfaces`. Both with `--method` (default "auto"); series times are the best of `--rounds`.
3. `map_batch` on a local cluster of 2 worker processes (its start included) against a loop that
   runs the same 16 jobs in this process one after the other: 3D pairs (a sphere inside an
   ellipsoid with semi-axes 1.8, 1.6, 1.5, 1,280 faces each, a little larger pair by pair) mapped
   with "diffusion" (CGAL Mesh_3 and the trace), read from PLY and written to CSV. Target: at
   least 1.7x on 2 cores.

Prints what else was running (compilers) so that a loaded machine shows in the numbers.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import tempfile
import time

import numpy as np
import trimesh

import morphomap as mm


def budding_curve(t: float, n: int = 1000) -> np.ndarray:
    """A circle at t = 0 that grows three buds (the shape of tests/test_series.py)."""
    theta = 2 * np.pi * np.arange(n) / n
    bumps = sum(np.exp(-(np.angle(np.exp(1j * (theta - c))) / 0.3) ** 2) for c in (0.3, 2.4, 4.5))
    r = 1 + 0.1 * t + 0.12 * t**2 * bumps
    return np.column_stack([r * np.cos(theta), r * np.sin(theta)])


def budding_surface(t: float, subdivisions: int = 4) -> trimesh.Trimesh:
    """An icosphere (5,120 faces at 4 subdivisions) growing a bud at its north pole."""
    sphere = trimesh.creation.icosphere(subdivisions)
    tip = np.array([0.0, 0.0, 1.0])
    bump = np.exp(-np.sum((sphere.vertices - tip) ** 2, axis=1) / 0.3)
    return trimesh.Trimesh(sphere.vertices * (1 + 0.05 * t + 0.15 * t * bump)[:, None], sphere.faces, process=False)


def busy() -> str:
    """What else is compiling or testing on the machine now."""
    found = subprocess.run(["pgrep", "-c", "cc1plus"], capture_output=True, text=True).stdout.strip() or "0"
    load = os.getloadavg()[0]
    return f"{found} compiler processes, load {load:.1f}"


def best(run, rounds):
    """The smallest wall time of ``rounds`` runs, and the last result."""
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - start)
    return min(times), result


def series_table(frames, map_pair, method, label, rounds):
    whole, series = best(lambda: mm.map_series(frames, method, progress=False), rounds)
    steps = [min(q.seconds for q in column) for column in zip(*(mm.map_series(frames, method, progress=False).quality
                                                               for _ in range(rounds)))]
    plain, judged = [], []
    for a, b in zip(frames[:-1], frames[1:]):
        seconds, field = best(lambda: map_pair(a, b, method), rounds)
        plain.append(seconds)
        judged.append(best(lambda: mm.quality(field, a, b), rounds)[0])
    print(f"\n**{label}**, best of {rounds} ({busy()} at the end)\n")
    print("| step | map_series step (map + quality) s | independent map s | + quality s | step / (map + quality) |")
    print("|---:|---:|---:|---:|---:|")
    for k, (step, p, q) in enumerate(zip(steps, plain, judged)):
        print(f"| {k} | {step:.4f} | {p:.4f} | {q:.4f} | {step / (p + q):.2f} |")
    total, maps, checks = sum(steps), sum(plain), sum(judged)
    print(f"| total | {total:.4f} | {maps:.4f} | {checks:.4f} | {total / (maps + checks):.2f} |")
    print(f"\nmap_series whole call {whole:.4f} s = {whole / maps:.2f}x the independent maps, "
          f"{whole / (maps + checks):.2f}x maps + quality; carrying the points, growth maps and re-seeding "
          f"{whole - total:.4f} s; {series!r}")
    return series


def batch_table(pairs: int, workers: int, method: str, subdivisions: int = 3):
    from morphomap.batch import Job, map_batch, run_job

    folder = tempfile.mkdtemp(prefix="bench_series_")
    try:
        sphere = trimesh.creation.icosphere(subdivisions)  # 1,280 faces at 3, 5,120 at 4, 20,480 at 5
        paths = []
        for k in range(pairs):  # a sphere inside an ellipsoid, a little larger pair by pair
            for name, axes in (("inner", [1.0, 1.0, 1.0]), ("outer", [1.8, 1.6, 1.5])):
                path = os.path.join(folder, f"{name}{k:02d}.ply")
                mm.write_surface(path, trimesh.Trimesh(sphere.vertices * axes * (1 + 0.02 * k), sphere.faces))
                paths.append(path)
        jobs = {kind: [Job(paths[2 * k], paths[2 * k + 1], os.path.join(folder, f"{kind}_{k:02d}.csv"), method)
                       for k in range(pairs)] for kind in ("loop", "batch")}
        before = busy()
        start, cpu = time.perf_counter(), os.times()
        for job in jobs["loop"]:
            run_job(job)
        loop = time.perf_counter() - start
        # Cores the loop kept busy on average (this process and its meshing children).
        used = sum(after - before for after, before in zip(os.times()[:4], cpu[:4])) / loop
        start = time.perf_counter()
        results = map_batch(jobs["batch"], workers=workers, progress=False)
        batch = time.perf_counter() - start
        failed = [r for r in results if r.status != "done"]
        difference = max((np.abs(mm.read_field(a.output).ends - mm.read_field(b.output).ends).max()
                          for a, b in zip(jobs["loop"], jobs["batch"]) if os.path.exists(b.output)), default=np.nan)
        print(f"\n**map_batch: {pairs} 3D pairs ({method}, {len(sphere.faces):,} faces each)**; before: {before}; "
              f"after: {busy()}\n")
        print("| sequential loop s | cores it used | map_batch, 2 workers s (cluster start included) | speed-up "
              "| failed | largest end difference |")
        print("|---:|---:|---:|---:|---:|---:|")
        print(f"| {loop:.2f} | {used:.2f} | {batch:.2f} | {loop / batch:.2f}x | {len(failed)} | {difference:.2g} |")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="4 batch pairs instead of 16")
    parser.add_argument("--method", default="auto", help="the series' method, 2D and 3D (default auto)")
    parser.add_argument("--rounds", type=int, default=5, help="series timings: best of this many runs (default 5)")
    parser.add_argument("--batch-subdivisions", type=int, default=3,
                        help="icosphere subdivisions of the batch pairs: 3 (1,280 faces, default), 4 (5,120) "
                             "or 5 (20,480: organ-sized jobs, ~4 min)")
    parser.add_argument("--skip", default="", help="comma-separated parts to skip: 2d, 3d, batch")
    args = parser.parse_args()
    skip = set(filter(None, args.skip.split(",")))
    print(f"morphomap {mm.__version__}, {os.cpu_count()} cores; {busy()} at the start")
    if "2d" not in skip:
        series_table([budding_curve(0.4 * t) for t in range(10)], mm.map_curves, args.method,
                     f"2D: 10 frames, 1,000 points per curve, {args.method}", args.rounds)
    if "3d" not in skip:
        series_table([budding_surface(t) for t in range(5)], mm.map_surfaces, args.method,
                     f"3D: 5 frames, 5,120 faces per surface, {args.method}", args.rounds)
    if "batch" not in skip:
        batch_table(4 if args.quick else 16, 2, "diffusion", args.batch_subdivisions)


if __name__ == "__main__":
    main()
