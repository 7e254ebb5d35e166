"""``morphomap demo``: every algorithm and variant on the bundled example pairs.

For each pair in :data:`morphomap.io.EXAMPLES` and each algorithm (minimal distance, normal,
diffusion, uniform) in its plain, reverse and transformed form (always with ``split=True``), map
C1 onto C2, measure the quality, and write the field (CSV) and its picture (PNG), plus one figure
per pair with every variant in a grid (rows: algorithm; columns: plain, reverse, transformed, like
the paper's Figure 5). An algorithm this build does not provide yet is reported as not available
and left out; it is never faked.
"""

from __future__ import annotations

import math
import os
import pathlib
import sys
import time
from dataclasses import dataclass

import numpy as np

from ._core import GeometryError
from .io import EXAMPLES, load_example, write_curve, write_field
from .mapping import map_curves
from .quality import quality

#: The algorithms, in the paper's order, and the variants the demo runs for each.
ALGORITHMS = ("minimal_distance", "normal", "diffusion", "uniform")
VARIANTS = ("plain", "reverse", "transform")
_VARIANT_ARGUMENTS = {"plain": {}, "reverse": {"reverse": True}, "transform": {"transform": True}}
_TITLES = {"minimal_distance": "minimal distance", "normal": "normal", "diffusion": "diffusion",
           "uniform": "uniform"}
_VARIANT_TITLES = {"plain": "", "reverse": "reverse ", "transform": "transformed "}


@dataclass
class Row:
    """One line of the demo's table."""

    pair: str
    method: str
    variant: str
    qm1: float = math.nan
    qm2: float = math.nan
    qm: float = math.nan
    crossings: int = -1
    misses: int = -1
    vectors: int = 0
    seconds: float = 0.0
    note: str = ""  # why there are no numbers: the error raised

    @property
    def ok(self) -> bool:
        return not self.note


def _number(value: float) -> str:
    return "nan" if math.isnan(value) else f"{value:.4g}"


def format_table(rows) -> str:
    """The rows as a text table with aligned columns."""
    head = ("pair", "method", "variant", "QM1", "QM2", "QM", "crossings", "misses")
    lines = []
    for row in rows:
        if row.ok:
            lines.append((row.pair, row.method, row.variant, _number(row.qm1), _number(row.qm2),
                          _number(row.qm), str(row.crossings), str(row.misses)))
        else:
            lines.append((row.pair, row.method, row.variant, row.note))
    widths = [len(h) for h in head]
    for line in lines:
        if len(line) == len(head):
            widths = [max(w, len(cell)) for w, cell in zip(widths, line)]
    numeric = (False, False, False, True, True, True, True, True)

    def render(cells):
        parts = [cell.rjust(w) if right else cell.ljust(w) for cell, w, right in zip(cells, widths, numeric)]
        return "  ".join(parts).rstrip()

    out = [render(head), render(["-" * w for w in widths])]
    for line in lines:
        out.append(render(line) if len(line) == len(head) else render(line[:3]) + "  " + line[3])
    return "\n".join(out)


def _figure(rows, cols, size):
    from matplotlib.figure import Figure  # no pyplot: nothing is shown, figures are freed with them

    fig = Figure(figsize=(size * cols, size * rows), layout="constrained")
    return fig, fig.subplots(rows, cols, squeeze=False)


def run(out="morphomap-demo", *, pairs=EXAMPLES, stream=None, plots=True) -> list:
    """Run the demo, print its table to ``stream`` (default stdout) and return the rows.

    Writes into ``out`` (created if needed), for each pair NAME: ``NAME/c1.csv``, ``NAME/c2.csv``,
    ``NAME/METHOD_VARIANT.csv`` (the field) and ``.png`` (its picture, unless ``plots=False``),
    ``NAME/all.png`` (the grid), and ``quality.csv`` with the table.
    """
    from .plot import plot_field, save_figure

    stream = sys.stdout if stream is None else stream
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"morphomap demo: {len(pairs)} example pairs x {len(ALGORITHMS)} algorithms x {len(VARIANTS)} variants "
          "(plain, reverse, transformed), then the automatic workflow (the paper's Algorithm 1, the "
          "default); every mapping with split=True (the curves are split where they cross and each "
          "pair of segments is mapped on its own).", file=stream)
    rows, written, auto_used = [], [], {}
    started = time.perf_counter()
    for pair in pairs:
        c1, c2 = load_example(pair)
        folder = out / pair
        folder.mkdir(exist_ok=True)
        write_curve(folder / "c1.csv", c1)
        write_curve(folder / "c2.csv", c2)
        written += [folder / "c1.csv", folder / "c2.csv"]
        fig, axes = _figure(len(ALGORITHMS), len(VARIANTS), 4.0) if plots else (None, None)
        for i, method in enumerate(ALGORITHMS):
            for j, variant in enumerate(VARIANTS):
                row = Row(pair, method, variant)
                rows.append(row)
                title = f"{_VARIANT_TITLES[variant]}{_TITLES[method]}".capitalize()
                tick = time.perf_counter()
                try:
                    field = map_curves(c1, c2, method, split=True, **_VARIANT_ARGUMENTS[variant])
                    q = quality(field, c1, c2, closed=True)
                except (ValueError, ArithmeticError, GeometryError) as error:  # reported in the table, not hidden
                    row.note = f"failed: {type(error).__name__}: {error}"
                    if plots:
                        axes[i, j].set_axis_off()
                        axes[i, j].text(0.5, 0.5, f"{title}:\nfailed", ha="center", va="center",
                                        transform=axes[i, j].transAxes)
                    continue
                row.seconds = time.perf_counter() - tick
                row.qm1, row.qm2, row.qm, row.crossings = q.qm1, q.qm2, q.qm, q.crossings
                row.misses = int((~field.valid).sum())
                row.vectors = len(field)
                stem = folder / f"{method}_{variant}"
                write_field(stem.with_suffix(".csv"), field)
                written.append(stem.with_suffix(".csv"))
                if plots:
                    label = f"{title}\nQM1 {_number(q.qm1)}  QM2 {_number(q.qm2)}  QM {_number(q.qm)}"
                    single, single_axes = _figure(1, 1, 6.0)
                    plot_field(field, c1, c2, ax=single_axes[0, 0], title=f"{pair}: {label}")
                    save_figure(single, stem.with_suffix(".png"), dpi=100)
                    written.append(stem.with_suffix(".png"))
                    plot_field(field, c1, c2, ax=axes[i, j], title=label)
        # The default: normal mapping, reverse diffusion where it crosses or misses.
        field = map_curves(c1, c2)
        q = quality(field, c1, c2, closed=True)
        names, counts = np.unique(field.method, return_counts=True)
        used = ", ".join(f"{n} {c}" for n, c in zip(names, counts))
        rows.append(Row(pair, "auto", "plain", q.qm1, q.qm2, q.qm, q.crossings, int((~field.valid).sum()),
                        len(field)))
        auto_used[pair] = used
        write_field(folder / "auto.csv", field)
        written.append(folder / "auto.csv")
        if plots:
            single, single_axes = _figure(1, 1, 6.0)
            plot_field(field, c1, c2, ax=single_axes[0, 0],
                       title=f"{pair}: auto ({used})\nQM1 {_number(q.qm1)}  QM2 {_number(q.qm2)}  QM {_number(q.qm)}")
            save_figure(single, folder / "auto.png", dpi=100)
            written.append(folder / "auto.png")
        if plots:
            fig.suptitle(f"{pair}: C1 green, C2 blue, vectors red, crossing vectors orange, misses grey x")
            save_figure(fig, folder / "all.png", dpi=80)
            written.append(folder / "all.png")
    table = format_table(rows)
    print(table, file=stream)
    for pair, used in auto_used.items():
        print(f"auto on {pair}: vectors made by {used}", file=stream)
    with open(out / "quality.csv", "w", encoding="utf-8") as handle:
        handle.write("pair,method,variant,qm1,qm2,qm,crossings,misses,vectors,note\n")
        for r in rows:
            handle.write(f"{r.pair},{r.method},{r.variant},{r.qm1!r},{r.qm2!r},{r.qm!r},{r.crossings},"
                         f"{r.misses},{r.vectors},{r.note.replace(',', ';')}\n")
    written.append(out / "quality.csv")
    elapsed = time.perf_counter() - started
    figures = sum(1 for p in written if p.suffix == ".png")
    fields = sum(1 for p in written if p.suffix == ".csv" and p.stem not in ("c1", "c2", "quality"))
    print(f"\nWrote {fields} fields (CSV), {figures} figures (PNG), the curves and quality.csv to "
          f"{os.path.abspath(out)} in {elapsed:.1f} s:", file=stream)
    for pair in pairs:
        print(f"  {os.path.join(os.path.abspath(out), pair)}{os.sep}  (all.png: every variant in one grid)",
              file=stream)
    print(f"  {os.path.abspath(out / 'quality.csv')}", file=stream)
    return rows
