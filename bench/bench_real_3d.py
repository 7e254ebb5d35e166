"""The 3D default and diffusion on real organ stages: the mouse limb bud (../shared/cases/limb-bud/3d).

    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_real_3d.py     (from the repository root)

One table over the three stages' pairs in both directions (250/270/290 h; 270 and 290 cross near
the flank), as given (coarse, closed by flat caps of long thin triangles) and remeshed at each
stage's median edge length (``remesh_surface``): for the default (``auto``) and ``diffusion``,
the vectors (one per vertex of S1), valid ones, folded triangles, QM and seconds (one run each),
or the error's first words where the call raised. Then the stages voxelised at 12 units on one
grid and contoured by ``surface_from_mask`` (18k / 68k / 123k faces, ``tests/limb_stages.py``),
and the same masks blurred by one voxel first (``smooth=12``: 17k / 63k / 114k faces, the
issue's inputs): both methods on every pair again.
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import morphomap as mm

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from limb_stages import voxelised  # noqa: E402

STAGES = ROOT.parent / "shared" / "cases" / "limb-bud" / "3d"
PAIRS = ((250, 270), (270, 250), (270, 290), (290, 270), (250, 290), (290, 250))
METHODS = ("auto", "diffusion")


def row(label, a, b, method, s1, s2):
    begin = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            field = mm.map_surfaces(s1, s2, method)
    except (ValueError, RuntimeError) as error:
        seconds = time.perf_counter() - begin
        print(f"{label:8s} {a}->{b:<4d} {method:10s} {'':>8s} {'':>6s} {'':>6s} {'':>9s} {seconds:8.1f}  "
              f"raised: {str(error)[:60]}")
        return
    seconds = time.perf_counter() - begin
    q = mm.quality(field, s1, s2)
    print(f"{label:8s} {a}->{b:<4d} {method:10s} {len(field):8d} {int(field.valid.sum()):6d} {q.folds:6d} "
          f"{q.qm:9.3g} {seconds:8.1f}", flush=True)


def main():
    import trimesh

    given = {h: trimesh.load(STAGES / f"limb_{h}h_closed.ply", process=False) for h in (250, 270, 290)}
    even = {h: mm.remesh_surface(s, float(np.median(s.edges_unique_length))) for h, s in given.items()}
    print(f"{'input':8s} {'pair':9s} {'method':10s} {'vectors':>8s} {'valid':>6s} {'folds':>6s} {'QM':>9s} "
          f"{'seconds':>8s}  note")
    for label, stages in (("given", given), ("remeshed", even)):
        for a, b in PAIRS:
            s1, s2 = stages[a], stages[b]
            for method in METHODS:
                row(label, a, b, method, s1, s2)
    for label, smooth in (("voxels", 0.0), ("blurred", 12.0)):
        masks = voxelised(given, smooth=smooth)
        for a, b in PAIRS:
            for method in METHODS:
                row(label, a, b, method, masks[a], masks[b])

if __name__ == "__main__":
    main()
