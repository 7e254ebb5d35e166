"""The default against the other methods on real outlines: the mouse limb bud (../shared/cases/limb-bud/2d).

    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_real_2d.py               (from the repository root)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_real_2d.py --all-pairs   (every consecutive, 4 h, 8 h pair)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_real_2d.py --dense       (10^3-10^4 points per curve)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_real_2d.py --cells       (best on cell-sized pixel contours)

1. One table over chosen real pairs (consecutive hours, 4 h and 8 h apart, the long jumps 250->270
   and 330->381; closed by the flank segment and open) and the bundled kidney pair: for the
   default (``auto``), ``paper`` (Algorithm 1 as stated), ``optimal``, ``best``, ``normal`` and
   ``diffusion``: crossings, misses, QM and seconds (one run each, in this process), and the
   default's QM over best's.
2. With ``--all-pairs``: the default over every pair the tests map, closed and open: how many pairs
   have crossings or misses, the largest QM ratio to ``optimal``, the median and largest time.
3. With ``--dense``: the kidney and limb 330->381 h (closed and open) resampled evenly to 10^3,
   2 x 10^3 and 10^4 points per curve: the default's seconds, QM and the labels it kept, and
   ``optimal``'s seconds and QM both ways (``reverse=True``), one run each.
4. With ``--cells``: ``best`` and the default on six consecutive frames of a migrating cell (a
   blob with a turning protrusion, drifting 6 px per frame), contoured from its pixel mask as it
   is (``smooth=0``: the staircase, ~335 points, as a tracking tool's outline): seconds, QM and
   the winning candidate. Needs no shared data.
"""

from __future__ import annotations

import argparse
import math
import time
import warnings
from pathlib import Path

import numpy as np

import morphomap as mm

LIMB = Path(__file__).resolve().parents[1].parent / "shared" / "cases" / "limb-bud" / "2d"
METHODS = ("auto", "paper", "optimal", "best", "normal", "diffusion")
CHOSEN = ((250, 251), (300, 301), (300, 304), (300, 308), (250, 270), (330, 381), (360, 361))


def outline(hour):
    return np.loadtxt(LIMB / f"limb_h{hour}.csv", delimiter=",", skiprows=1)


def run(c1, c2, method, closed):
    """(crossings, misses, QM, seconds) or the error's first line. The curves are made simple
    first (the glitch hours' first point lies across the closing segment), so that every method
    maps and is measured on the same curves."""
    c1, c2 = mm.make_simple(c1, closed=closed)[0], mm.make_simple(c2, closed=closed)[0]
    begin = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            field = mm.map_curves(c1, c2, method, closed=closed)
            seconds = time.perf_counter() - begin
            q = mm.quality(field, c1, c2, closed=closed)
    except (ValueError, RuntimeError) as error:
        return f"{type(error).__name__}: {str(error).splitlines()[0][:60]}"
    return int(q.crossings), int((~field.valid).sum()), float(q.qm), seconds


def table():
    rows = [("pair", "closed", "method", "crossings", "misses", "QM", "s", "QM / best")]
    cases = [(f"limb {a}->{b} h", outline(a), outline(b)) for a, b in CHOSEN]
    cases.append(("kidney (bundled)", *mm.load_example("kidney")))
    for name, c1, c2 in cases:
        for closed in (True, False) if name.startswith("limb") else (True,):
            results = {m: run(c1, c2, m, closed) for m in METHODS}
            best = results["best"][2] if isinstance(results["best"], tuple) else math.nan
            for m, r in results.items():
                if isinstance(r, str):
                    rows.append((name, str(closed), m, r, "", "", "", ""))
                    continue
                crossings, misses, qm, seconds = r
                ratio = f"{qm / best:.3g}" if m == "auto" and best > 0 else ""
                rows.append((name, str(closed), m, str(crossings), str(misses), f"{qm:.4g}", f"{seconds:.3f}", ratio))
    print_table(rows)


def all_pairs():
    hours = range(248, 382)
    curves = {h: outline(h) for h in hours}
    pairs = [(h, h + 1) for h in range(248, 381)] + [(h, h + 4) for h in range(248, 378, 4)]
    pairs += [(h, h + 8) for h in range(248, 374, 8)] + [(250, 270), (330, 381)]
    for closed in (True, False):
        bad, times, ratios = [], [], []
        for a, b in pairs:
            r = run(curves[a], curves[b], "auto", closed)
            o = run(curves[a], curves[b], "optimal", closed)
            if isinstance(r, str) or r[0] or r[1]:
                bad.append(f"{a}->{b}: {r}")
                continue
            times.append(r[3])
            if isinstance(o, tuple) and o[2] > 0:
                ratios.append(r[2] / o[2])
        print(f"closed={closed}: {len(pairs)} pairs, {len(bad)} with crossings, misses or errors; "
              f"default QM / optimal's: max {max(ratios):.3g}, median {np.median(ratios):.3g}; "
              f"time median {np.median(times) * 1e3:.1f} ms, max {max(times) * 1e3:.1f} ms")
        for line in bad[:10]:
            print("   ", line)


def dense():
    rows = [("pair", "points", "default s", "default QM", "kept", "optimal s", "optimal QM", "reverse s",
             "reverse QM")]
    kidney = mm.load_example("kidney")
    cases = [("kidney", *kidney, True)]
    for closed in (True, False):
        c1, c2 = (mm.make_simple(outline(h), closed=closed)[0] for h in (330, 381))
        cases.append((f"limb 330->381 h {'closed' if closed else 'open'}", c1, c2, closed))
    for name, a, b, closed in cases:
        for n in (1000, 2000, 10_000):
            c1, c2 = mm.resample(a, n, closed=closed), mm.resample(b, n, closed=closed)
            cells = [name, str(n)]
            for method, reverse in (("auto", False), ("optimal", False), ("optimal", True)):
                begin = time.perf_counter()
                try:
                    field = mm.map_curves(c1, c2, method, closed=closed, reverse=reverse)
                except (ValueError, RuntimeError) as error:
                    cells += [f"{time.perf_counter() - begin:.2f}", f"raises: {str(error)[:40]}"]
                    cells += [""] if method == "auto" else []
                    continue
                seconds = time.perf_counter() - begin
                q = mm.quality(field, c1, c2, closed=closed)
                cells += [f"{seconds:.2f}", f"{q.qm:.3g}" + (f" ({q.crossings} crossings)" if q.crossings else "")]
                if method == "auto":
                    cells.append(", ".join(sorted(set(map(str, field.method)))))
            rows.append(tuple(cells))
    print_table(rows)


def cell_mask(frame, shape=(160, 200)):
    """A migrating cell at one frame: a lobed blob whose protrusion turns, drifting right."""
    rows, columns = np.mgrid[0:shape[0], 0:shape[1]].astype(float)
    cx, cy = 70 + 6 * frame, 80 + 2 * np.sin(frame)
    theta = np.arctan2(rows - cy, columns - cx)
    protrusion = np.angle(np.exp(1j * (theta - 0.4 * frame))) / 0.35
    radius = (38 + 7 * np.cos(2 * theta + 0.3 * frame) + 9 * np.exp(-protrusion ** 2)
              + 5 * np.cos(3 * theta - 0.5 * frame))
    return np.hypot(columns - cx, rows - cy) < radius


def cells():
    rows = [("frames", "points", "best s", "best QM", "won", "default s", "default QM", "crossings")]
    for frame in range(6):
        c1 = mm.boundary_from_mask(cell_mask(frame), smooth=0)
        c2 = mm.boundary_from_mask(cell_mask(frame + 1), smooth=0)
        best = run(c1, c2, "best", True)
        default = run(c1, c2, "auto", True)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            won = next(c.name for c in mm.map_curves(c1, c2, "best").candidates if c.status == "won")
        rows.append((f"{frame}->{frame + 1}", f"{len(c1)}/{len(c2)}", f"{best[3]:.2f}", f"{best[2]:.4g}", won,
                     f"{default[3]:.3f}", f"{default[2]:.4g}", str(best[0] + default[0])))
    print_table(rows)


def print_table(rows):
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        print("| " + " | ".join(x.ljust(w) for x, w in zip(r, widths)) + " |")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--all-pairs", action="store_true", help="the default over every pair the tests map")
    parser.add_argument("--dense", action="store_true", help="the default and optimal at 10^3-10^4 points per curve")
    parser.add_argument("--cells", action="store_true", help="best on cell-sized pixel contours (no shared data)")
    args = parser.parse_args()
    if args.cells:
        raise SystemExit(cells())
    if not LIMB.is_dir():
        raise SystemExit(f"the limb-bud outlines are not beside the project ({LIMB.name} missing)")
    dense() if args.dense else all_pairs() if args.all_pairs else table()
