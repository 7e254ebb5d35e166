"""The paper's Table 1 (circle onto ellipse) next to morphomap's numbers.

    PYTHONPATH=build/dev-NAME/pkg python3 bench/paper_table1.py       (from the repository root)

C1: the circle of radius 0.95, C2: the concentric ellipse with semi-axes 2.177 and 1, 100 points
each (the bundled example "circle_ellipse"; C2 equally spaced in arc length). For each of minimal
distance, normal and diffusion mapping in the plain, reverse and transformed form: QM1, QM2 and QM
from the paper, ours, and ours / paper. Then, for each algorithm, which variant is best (lowest)
for each measure in the paper and in ours. Algorithms this build does not provide yet are shown as
not available.
"""

from __future__ import annotations

import math

import morphomap as mm

#: Table 1 of the paper: (QM1, QM2, QM).
PAPER = {
    ("minimal_distance", "plain"): (13.4, 22.4, 301),
    ("minimal_distance", "reverse"): (0.128, 0.134, 0.017),
    ("minimal_distance", "transform"): (1.69, 2.71, 4.58),
    ("normal", "plain"): (0.103, 0.398, 0.041),
    ("normal", "reverse"): (56.1, 2.45, 137),
    ("normal", "transform"): (0.084, 0.397, 0.033),
    ("diffusion", "plain"): (0.494, 1.17, 0.577),
    ("diffusion", "reverse"): (1.589, 0.088, 0.140),
    ("diffusion", "transform"): (0.224, 0.559, 0.125),
}
ALGORITHMS = ("minimal_distance", "normal", "diffusion")
VARIANTS = ("plain", "reverse", "transform")
NAMES = {"plain": "", "reverse": "reverse ", "transform": "transformed "}
MEASURES = ("QM1", "QM2", "QM")


def ours(c1, c2):
    """{(method, variant): (qm1, qm2, qm, crossings, misses)} or a reason string when not available."""
    results = {}
    for method in ALGORITHMS:
        for variant in VARIANTS:
            try:
                field = mm.map_curves(c1, c2, method, reverse=variant == "reverse",
                                      transform=variant == "transform")
            except ValueError as error:
                if method == "diffusion":  # not provided yet: say so, never fake it
                    results[(method, variant)] = f"n/a (not yet available: {error})"
                    continue
                raise
            q = mm.quality(field, c1, c2)
            results[(method, variant)] = (q.qm1, q.qm2, q.qm, q.crossings, int((~field.valid).sum()))
    return results


def _fmt(value):
    return "nan" if math.isnan(value) else f"{value:.3g}"


def main():
    c1, c2 = mm.load_example("circle_ellipse")
    results = ours(c1, c2)
    head = f"{'mapping':<30}" + "".join(f"{m + ' paper':>11}{m + ' ours':>10}{'ratio':>8}" for m in MEASURES)
    head += f"{'crossings':>11}{'misses':>8}"
    print(f"Table 1: circle (r = 0.95, {len(c1)} points) onto ellipse (2.177 x 1, {len(c2)} points); "
          "pairs with a miss (no target) are left out of QM1, QM2 and QM")
    print(head)
    print("-" * len(head))
    for method in ALGORITHMS:
        for variant in VARIANTS:
            name = f"{NAMES[variant]}{method.replace('_', ' ')}"
            paper, got = PAPER[(method, variant)], results[(method, variant)]
            if isinstance(got, str):
                line = f"{name:<30}" + "".join(f"{p:>11.4g}{'n/a':>10}{'':>8}" for p in paper)
                print(line + "   " + got.split(":")[0] + ")")
                continue
            line = f"{name:<30}"
            for p, o in zip(paper, got[:3]):
                line += f"{p:>11.4g}{_fmt(o):>10}{_fmt(o / p):>8}"
            print(line + f"{got[3]:>11}{got[4]:>8}")
        print()
    print("Best variant (lowest value) per algorithm and measure, paper vs ours:")
    for method in ALGORITHMS:
        for k, measure in enumerate(MEASURES):
            paper_best = min(VARIANTS, key=lambda v: PAPER[(method, v)][k])
            values = {v: results[(method, v)] for v in VARIANTS}
            if any(isinstance(v, str) for v in values.values()):
                our_best = "n/a (not yet available)"
            else:
                our_best = min(VARIANTS, key=lambda v: values[v][k])
            agree = "" if our_best.startswith("n/a") else ("  same" if our_best == paper_best else "  DIFFERENT")
            print(f"  {method.replace('_', ' '):<17}{measure:<4} paper: {paper_best:<10} ours: {our_best}{agree}")


if __name__ == "__main__":
    main()
