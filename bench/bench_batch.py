"""`map_batch` on a local Dask cluster of 2 worker processes against a sequential loop, side by side.

    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_batch.py               (16 pairs, 20,480 faces)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_batch.py --quick       (4 pairs, 1,280 faces)

16 3D pairs (a sphere inside an ellipsoid with semi-axes 1.8, 1.6, 1.5, a little larger pair by
pair), mapped with "diffusion" (CGAL Mesh_3 and the trace), read from PLY and written to CSV. Each
round runs the loop (`run_job` on each pair in this process, one after the other, the core's
threads on every core) and then `map_batch` on the same pairs into another folder (its cluster's
start and close, the workers' imports, the input hashes and the sidecars included). This process
has morphomap, trimesh and SciPy imported before the loop starts; the workers import them in the
batch's time. Then the machine's own ceiling for the same work: two bare Python processes started
together, each running every other pair with its core's threads on its share of the cores (no
Dask, no hashes, no sidecars). Prints each round and the median and range of the speed-up and
of that ceiling, with the machine's load (1-minute average) before and after each round: with
other work on the 2 cores the batch cannot show its speed-up, so run it on an idle machine.
Target: at least 1.7x on 2 cores.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import trimesh

import morphomap as mm
from morphomap import _core
from morphomap.batch import Job, map_batch, run_job


def load() -> float:
    return os.getloadavg()[0]


def make_pairs(folder: str, pairs: int, subdivisions: int) -> list:
    sphere = trimesh.creation.icosphere(subdivisions)  # 1,280 faces at 3, 5,120 at 4, 20,480 at 5
    paths = []
    for k in range(pairs):
        for name, axes in (("inner", [1.0, 1.0, 1.0]), ("outer", [1.8, 1.6, 1.5])):
            path = os.path.join(folder, f"{name}{k:02d}.ply")
            mm.write_surface(path, trimesh.Trimesh(sphere.vertices * axes * (1 + 0.02 * k), sphere.faces))
            paths.append(path)
    return [(paths[2 * k], paths[2 * k + 1]) for k in range(pairs)]


def bare_part(folder: str, part: int, parts: int, method: str, subdivisions: int, count: int) -> None:
    """One of the bare processes: every ``parts``-th pair from ``part`` on, threads on its share."""
    _core.limit_threads(max(1, (os.cpu_count() or 1) // parts))
    for k, (a, b) in enumerate(make_pairs(folder, count, subdivisions)):
        if k % parts == part:
            run_job(Job(a, b, os.path.join(folder, f"bare{part}_{k:02d}.csv"), method))


def bare_processes(folder: str, parts: int, method: str, subdivisions: int, count: int) -> float:
    start = time.perf_counter()
    children = [subprocess.Popen([sys.executable, __file__, "--bare-part", str(part), "--folder", folder,
                                  "--workers", str(parts), "--method", method, "--subdivisions",
                                  str(subdivisions), "--pairs", str(count)]) for part in range(parts)]
    if any(child.wait() != 0 for child in children):
        raise RuntimeError("a bare process failed")
    return time.perf_counter() - start


def one_round(folder: str, pairs: list, method: str, workers: int, number: int, subdivisions: int) -> dict:
    jobs = {kind: [Job(a, b, os.path.join(folder, f"{kind}{number}_{k:02d}.csv"), method)
                   for k, (a, b) in enumerate(pairs)] for kind in ("loop", "batch")}
    before = load()
    start = time.perf_counter()
    for job in jobs["loop"]:
        run_job(job)
    loop = time.perf_counter() - start
    start = time.perf_counter()
    results = map_batch(jobs["batch"], workers=workers, progress=False)
    batch = time.perf_counter() - start
    difference = max((np.abs(mm.read_field(a.output).ends - mm.read_field(b.output).ends).max()
                      for a, b in zip(jobs["loop"], jobs["batch"]) if os.path.exists(b.output)), default=np.nan)
    bare = bare_processes(folder, workers, method, subdivisions, len(pairs))
    return {"loop": loop, "batch": batch, "bare": bare, "failed": sum(r.status != "done" for r in results),
            "job": statistics.median(r.seconds for r in results if r.status == "done"),
            "difference": difference, "load": (before, load())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="4 pairs of 1,280 faces, 1 round")
    parser.add_argument("--pairs", type=int, default=16)
    parser.add_argument("--subdivisions", type=int, default=5,
                        help="icosphere subdivisions: 3 (1,280 faces), 4 (5,120) or 5 (20,480, default)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--method", default="diffusion")
    parser.add_argument("--bare-part", type=int, help=argparse.SUPPRESS)
    parser.add_argument("--folder", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.bare_part is not None:
        bare_part(args.folder, args.bare_part, args.workers, args.method, args.subdivisions, args.pairs)
        return
    if args.quick:
        args.pairs, args.subdivisions, args.rounds = 4, 3, 1
    folder = tempfile.mkdtemp(prefix="bench_batch_")
    try:
        pairs = make_pairs(folder, args.pairs, args.subdivisions)
        faces = len(trimesh.creation.icosphere(args.subdivisions).faces)
        print(f"morphomap {mm.__version__}, {os.cpu_count()} cores; {args.pairs} pairs of {faces:,} faces, "
              f"{args.method}, {args.workers} workers")
        print("\n| round | loop s | map_batch s | speed-up | bare processes s | ceiling | median job s in a "
              "worker | failed | largest end difference | load before, after |")
        print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
        rounds = []
        for number in range(args.rounds):
            r = one_round(folder, pairs, args.method, args.workers, number, args.subdivisions)
            rounds.append(r)
            print(f"| {number + 1} | {r['loop']:.2f} | {r['batch']:.2f} | {r['loop'] / r['batch']:.2f}x "
                  f"| {r['bare']:.2f} | {r['loop'] / r['bare']:.2f}x "
                  f"| {r['job']:.2f} | {r['failed']} | {r['difference']:.2g} "
                  f"| {r['load'][0]:.1f}, {r['load'][1]:.1f} |", flush=True)
        ups = [r["loop"] / r["batch"] for r in rounds]
        tops = [r["loop"] / r["bare"] for r in rounds]
        print(f"\nceiling (bare processes) median {statistics.median(tops):.2f}x, "
              f"range {min(tops):.2f}-{max(tops):.2f}x")
        print(f"speed-up median {statistics.median(ups):.2f}x, range {min(ups):.2f}-{max(ups):.2f}x; loop median "
              f"{statistics.median(r['loop'] for r in rounds):.2f} s, map_batch median "
              f"{statistics.median(r['batch'] for r in rounds):.2f} s")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
