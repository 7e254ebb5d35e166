#!/usr/bin/env python3
"""Mask -> surface: morphomap.surface_from_mask against the pipeline a user would write.

    PYTHONPATH=build/dev/pkg python3 bench/bench_masks.py [--sizes 256 128x512x512] [--runs 3]

A lumpy blob (a ball with smooth random-free bumps) in a stack of 2 x 0.5 x 0.5 um voxels, and the
same blob grown (the next frame). Each pipeline runs in its own child process, so that its peak
memory (max RSS) is its own:

- morphomap: ``surface_from_mask(stack, spacing, smooth=0.5)`` (scikit-image marching cubes, then
  CGAL's isotropic remeshing in the core at the coarsest voxel size);
- peer: scikit-image marching cubes on the Gaussian-smoothed stack (the same smoothing), trimesh's
  Taubin smoothing (10 rounds) and quadric decimation (fast-simplification) to the face count
  morphomap's surface has.

Reported per stack: seconds (wall and CPU, the CPU time being the steadier on a shared machine),
peak memory, faces, minimum triangle angle (the smallest, and the 1st percentile), and the 3D QM1
of a normal mapping of the frame onto the next (each pipeline's own surfaces). Printed as a
markdown table; ratios peer / morphomap within each run, the two pipelines taking turns
``--runs`` times: the table shows the first run, the ratio rows the median and the range.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

import numpy as np

SPACING = (2.0, 0.5, 0.5)


def blob(shape, grown=False):
    """A lumpy blob filling about 70% of the stack's smallest extent, as a [z, y, x] bool array.
    Made slice by slice, so that making it does not set the peak memory of the process."""
    extent = np.array(shape) * SPACING
    centre = extent / 2
    y, x = (np.arange(n) * h - c for n, h, c in zip(shape[1:], SPACING[1:], centre[1:]))
    Y, X = np.meshgrid(y, x, indexing="ij")
    phi = np.arctan2(Y, X)
    stack = np.empty(shape, bool)
    for k in range(shape[0]):
        Z = k * SPACING[0] - centre[0]
        r = np.sqrt(X**2 + Y**2 + Z**2) + 1e-9
        theta = np.arccos(Z / r)
        bumps = 0.12 * np.sin(3 * phi) * np.sin(theta) ** 3 + 0.08 * np.cos(2 * theta) + 0.05 * np.cos(5 * phi)
        radius = 0.35 * extent.min() * (1 + bumps) * (1.06 if grown else 1.0)
        if grown:
            radius = radius * (1 + 0.1 * np.exp(-((theta - 1.0) ** 2 + (phi - 0.5) ** 2) / 0.1))
        stack[k] = r <= radius
    return stack


def morphomap_surface(stack):
    import morphomap as mm

    return mm.surface_from_mask(stack, SPACING, smooth=0.5)


def peer_surface(stack, faces):
    import trimesh
    from scipy import ndimage
    from skimage import measure

    image = ndimage.gaussian_filter(np.pad(stack, 4).astype(np.float32), [0.5 / h for h in SPACING])
    vertices, triangles, _, _ = measure.marching_cubes(image, 0.5, spacing=SPACING)
    mesh = trimesh.Trimesh(vertices[:, ::-1], triangles[:, ::-1], process=True)
    trimesh.smoothing.filter_taubin(mesh, iterations=10)
    mesh = mesh.simplify_quadric_decimation(face_count=faces)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def one(pipeline, shape, faces):
    """Run one pipeline on both frames in this process; print its measurements as JSON."""
    import morphomap as mm

    frames = [blob(shape), blob(shape, grown=True)]
    start, cpu = time.perf_counter(), time.process_time()
    surfaces = [morphomap_surface(f) if pipeline == "morphomap" else peer_surface(f, faces) for f in frames]
    seconds, cpu = (time.perf_counter() - start) / 2, (time.process_time() - cpu) / 2
    angles = np.degrees(surfaces[0].face_angles.min(axis=1))
    try:
        field = mm.map_surfaces(surfaces[0], surfaces[1], "normal")
        qm1 = mm.quality(field, surfaces[0], surfaces[1]).qm1
    except ValueError as error:  # the peer's surface may not be closed after decimation
        qm1 = f"refused: {str(error).split(':')[1].strip()[:40]}"
    print(json.dumps({"seconds": seconds, "cpu": cpu, "faces": len(surfaces[0].faces), "min_angle": float(angles.min()),
                      "p1_angle": float(np.percentile(angles, 1)), "qm1": qm1,
                      "watertight": bool(surfaces[0].is_watertight),
                      "max_rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20}))


def child(pipeline, shape, faces=0):
    done = subprocess.run([sys.executable, __file__, "--one", pipeline, "x".join(map(str, shape)), str(faces)],
                          capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def parse_shape(text):
    parts = [int(v) for v in text.split("x")]
    return tuple(parts * 3) if len(parts) == 1 else tuple(parts)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", nargs="+", default=["256", "128x512x512"])
    parser.add_argument("--runs", type=int, default=1, help="times each pipeline runs, taking turns")
    parser.add_argument("--one", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        pipeline, shape, faces = args.one
        one(pipeline, parse_shape(shape), int(faces))
        return
    print(
        "| stack (z x y x x) | pipeline | s per frame | CPU s per frame | peak GB | faces | min angle | 1% angle "
        "| watertight | QM1 normal |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|---|---:|")
    for text in args.sizes:
        shape = parse_shape(text)
        runs = []
        for _ in range(args.runs):
            ours = child("morphomap", shape)
            runs.append((ours, child("peer", shape, ours["faces"])))
        ours, peer = runs[0]
        for name, r in (("morphomap", ours), ("skimage + trimesh", peer)):
            qm1 = f"{r['qm1']:.4g}" if isinstance(r["qm1"], float) else r["qm1"]
            print(
                f"| {'x'.join(map(str, shape))} | {name} | {r['seconds']:.2f} | {r['cpu']:.2f} | {r['max_rss_gb']:.2f} "
                f"| {r['faces']} | {r['min_angle']:.1f} | {r['p1_angle']:.1f} | {r['watertight']} | {qm1} |"
            )

        def ratio(key):
            values = sorted(p[key] / o[key] for o, p in runs)
            spread = f" ({values[0]:.2f}–{values[-1]:.2f})" if len(values) > 1 else ""
            return f"{np.median(values):.2f}{spread}"

        print(
            f"| | peer / morphomap, {len(runs)} runs | {ratio('seconds')} | {ratio('cpu')} | {ratio('max_rss_gb')} | | "
            f"morphomap / peer {ours['min_angle'] / max(peer['min_angle'], 1e-9):.0f}× | | | |"
        )


if __name__ == "__main__":
    main()
