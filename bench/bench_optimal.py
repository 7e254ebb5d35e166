"""method="optimal" against elastic curve matching (fdasrsf), and auto / best / optimal over many pairs.

    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_optimal.py              (from the repository root)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_optimal.py --fuzz 5     (fewer fuzz pairs)

1. The peer: fdasrsf's elastic matching of closed curves (square-root velocity functions, a
   dynamic program over reparametrisations, a search over seeds every 4 samples; no rotation, so
   that the correspondence is a displacement): `find_rotation_and_seed_coord(beta1, beta2,
   closed=1, rotation=False)` gives the points of C2 matched to C1's samples. Both methods get the
   same pairs, both curves resampled to N equally spaced points (mm.resample), and are measured on
   those resampled curves: QM1, QM2, QM, crossings, seconds (best of 3 for optimal, one run for
   fdasrsf), and fdasrsf's time over optimal's. Then the time of optimal at 10^4 points per curve.
2. auto, best (default skip rule) and optimal on the bundled pairs (circle_ellipse is the paper's
   Table 1 pair), the shared frames where present, and fuzz pairs (tests/frames.py, careful style):
   QM, crossings, misses and seconds, as given (no resampling); the pieces between split points
   (best chooses per piece) and best's winner ("per_piece" with the candidates that won pieces).

fdasrsf is a bench peer only (the "bench" extra), never a dependency of morphomap.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

import morphomap as mm

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
import frames  # noqa: E402

CASES = ROOT.parent / "shared" / "cases"


def pairs(fuzz: int):
    """[(name, c1, c2)]: the bundled pairs, the shared frames if present, `fuzz` careful fuzz pairs."""
    out = [(name, *mm.load_example(name)) for name in ("circle_ellipse", "kidney")]
    if (CASES / "frame2.csv").exists():
        out.append(("shared frames 2-3", mm.read_curve(CASES / "frame2.csv"), mm.read_curve(CASES / "frame3.csv")))
    seed = 0
    while fuzz > 0:
        pair = frames.curve_pair(seed, "careful")
        seed += 1
        if pair.identical:
            continue
        out.append((f"fuzz {pair.seed}", pair.c1, pair.c2))
        fuzz -= 1
    return out


def elastic(a, b):
    """fdasrsf's elastic matching of the closed curves a -> b: the matched points of b."""
    from fdasrsf import curve_functions as cf

    beta1 = np.vstack([a, a[:1]]).T  # closed: the first point again at the end
    beta2 = np.vstack([b, b[:1]]).T
    matched = cf.find_rotation_and_seed_coord(beta1, beta2, closed=1, rotation=False)[0]
    return mm.DisplacementField(a, matched.T[:-1], "uniform")


def measure(field, a, b):
    q = mm.quality(field, a, b)
    return q.qm1, q.qm2, q.qm, q.crossings, int((~field.valid).sum())


def timed(run, repeat):
    best, result = math.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        result = run()
        best = min(best, time.perf_counter() - start)
    return result, best


def row(cells):
    return "| " + " | ".join(cells) + " |"


def against_elastic(cases, n):
    print(f"\n### optimal vs fdasrsf elastic matching, N = {n} points per curve\n")
    print(row(["pair", "method", "QM1", "QM2", "QM", "crossings", "seconds", "fdasrsf / optimal"]))
    print(row(["---"] * 8))
    for name, c1, c2 in cases:
        a, b = mm.resample(c1, n), mm.resample(c2, n)
        ours, t_ours = timed(lambda: mm.map_curves(a, b, "optimal"), 3)
        try:
            theirs, t_theirs = timed(lambda: elastic(a, b), 1)
        except Exception as error:  # a peer failure is reported, not fatal
            theirs, t_theirs = None, math.nan
            print(f"<!-- fdasrsf failed on {name}: {error} -->")
        for label, field, seconds in (("optimal", ours, t_ours), ("fdasrsf", theirs, t_theirs)):
            if field is None:
                print(row([name, label, "-", "-", "-", "-", "failed", ""]))
                continue
            qm1, qm2, qm, crossings, _ = measure(field, a, b)
            ratio = f"{t_theirs / t_ours:.0f}x" if label == "fdasrsf" else ""
            print(row([name, label, f"{qm1:.4g}", f"{qm2:.4g}", f"{qm:.4g}", str(crossings), f"{seconds:.3f}", ratio]))


def scaling(cases, sizes, peer_sizes):
    print("\n### seconds per map, the kidney pair resampled to N points per curve\n")
    print(row(["N", "optimal", "fdasrsf", "fdasrsf / optimal"]))
    print(row(["---"] * 4))
    _, c1, c2 = next(c for c in cases if c[0] == "kidney")
    for n in sizes:
        a, b = mm.resample(c1, n), mm.resample(c2, n)
        _, t_ours = timed(lambda: mm.map_curves(a, b, "optimal"), 3)
        if n in peer_sizes:
            _, t_theirs = timed(lambda: elastic(a, b), 1)
            print(row([str(n), f"{t_ours:.3f}", f"{t_theirs:.2f}", f"{t_theirs / t_ours:.0f}x"]))
        else:
            print(row([str(n), f"{t_ours:.3f}", "not run", ""]))


def auto_best_optimal(cases):
    print("\n### auto, best and optimal on the pairs as given\n")
    print(row(["pair", "points", "pieces", "auto QM", "auto X/miss", "auto s", "best QM", "best X/miss", "best s",
               "best's winner", "optimal QM", "optimal X/miss", "optimal s"]))
    print(row(["---"] * 13))
    never_worse, crossing_free = True, True
    for name, c1, c2 in cases:
        pieces = len(mm._core.split_curves(c1, c2, True, True, -1.0).pieces)
        cells = [name, f"{len(c1)}/{len(c2)}", str(pieces)]
        results = {}
        for method in ("auto", "best", "optimal"):
            try:
                field, seconds = timed(lambda: mm.map_curves(c1, c2, method), 1)
            except (ValueError, RuntimeError) as error:
                cells += ["failed", str(error).splitlines()[0][:40], ""]
                if method == "best":
                    cells.append("")
                continue
            _, _, qm, crossings, misses = measure(field, c1, c2)
            results[method] = (qm, crossings, misses)
            cells += [f"{qm:.4g}", f"{crossings}/{misses}", f"{seconds:.2f}"]
            if method == "best":
                winner = next(c.name for c in field.candidates if c.status == "won")
                if winner == "per_piece":  # which candidates won the pieces
                    wins = sorted({r.name for r in field.piece_candidates if r.status == "won"})
                    winner += " (" + ", ".join(wins) + ")"
                cells.append(winner)
                if crossings and any(c.defects == 0 for c in field.candidates):
                    crossing_free = False
        if "auto" in results and "best" in results:
            auto, chosen = results["auto"], results["best"]
            if auto[1] == 0 and auto[2] == 0 and not chosen[0] <= auto[0]:
                never_worse = False
            if chosen[1] > 0 and auto[1] == 0:
                never_worse = False
        print(row(cells))
    print(f"\nbest's QM <= auto's wherever auto is crossing- and miss-free, and no crossings where auto has none: "
          f"{'yes' if never_worse else 'NO'}")
    print(f"best crossing-free wherever one of its candidates is: {'yes' if crossing_free else 'NO'}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fuzz", type=int, default=20, help="fuzz pairs in the auto/best/optimal table (default 20)")
    parser.add_argument("--n", type=int, default=200, help="points per curve against fdasrsf (default 200)")
    parser.add_argument("--table-only", action="store_true", help="only the auto/best/optimal table (no fdasrsf)")
    args = parser.parse_args(argv)
    cases = pairs(args.fuzz)
    if not args.table_only:
        import fdasrsf

        print(f"morphomap {mm.__version__}, fdasrsf {fdasrsf.__version__}")
        against_elastic(cases[:6], args.n)
        scaling(cases, (200, 400, 1000, 10**4), (200, 400))
    else:
        print(f"morphomap {mm.__version__}")
    auto_best_optimal(cases)


if __name__ == "__main__":
    main()
