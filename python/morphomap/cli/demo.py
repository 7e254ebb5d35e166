"""``morphomap demo``: every algorithm and variant on the bundled example pairs.

For each pair in :data:`morphomap.io.EXAMPLES` and each algorithm (minimal distance, normal,
diffusion, uniform) in its plain, reverse and transformed form (always with ``split=True``), map
C1 onto C2, measure the quality, and write the field (CSV) and its picture (PNG), plus one figure
per pair with every variant in a grid (rows: algorithm; columns: plain, reverse, transformed, like
the paper's Figure 5). Then the same from segmented images (:func:`run_images`): mask and stack
files made by :mod:`morphomap.synthetic.masks`, read back, contoured, mapped and drawn, in 2D
and 3D. A mapping that fails is reported in the table with its error, never hidden.
"""

from __future__ import annotations

import math
import os
import pathlib
import sys
import time
from dataclasses import dataclass

import numpy as np
import tifffile

from .._core import METHODS, GeometryError
from ..chooser import BEST
from ..figure_style import method_summary
from ..images import boundary_from_mask, read_image, surface_from_mask
from ..io import EXAMPLES, load_example, write_curve, write_field, write_surface
from ..io.atomic import atomic_text
from ..mapping import map_curves
from ..plot import offscreen_figure, plot_field, plot_field_3d, save_figure
from ..quality import quality
from ..surfaces import map_surfaces
from ..synthetic.masks import ellipsoid_stacks, kidney_masks, lung_stacks

#: The paper's basic algorithms in 2D, in the order of the core's method table, and the variants
#: the demo runs for each; then the basic algorithms beyond the paper, and "best".
ALGORITHMS = tuple(row.name for row in METHODS if row.basic and row.from_paper and row.curves)
VARIANTS = ("plain", "reverse", "transform")
_VARIANT_ARGUMENTS = {"plain": {}, "reverse": {"reverse": True}, "transform": {"transform": True}}
_BEYOND_PAPER = tuple(row.name for row in METHODS if row.basic and not row.from_paper and row.curves) + (BEST,)
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


def format_table(rows, defects: str = "crossings") -> str:
    """The rows as a text table with aligned columns; ``defects`` heads the crossings (2D) or folds
    (3D) column."""
    head = ("pair", "method", "variant", "QM1", "QM2", "QM", defects, "misses")
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


def _write_quality(path, rows, defects="crossings"):
    with atomic_text(path) as handle:
        handle.write(f"pair,method,variant,qm1,qm2,qm,{defects},misses,vectors,seconds,note\n")
        for r in rows:
            handle.write(f"{r.pair},{r.method},{r.variant},{r.qm1!r},{r.qm2!r},{r.qm!r},{r.crossings},"
                         f"{r.misses},{r.vectors},{r.seconds:.3f},{r.note.replace(',', ';')}\n")


def _figure(rows, cols, size):
    fig = offscreen_figure(size * cols, size * rows)
    return fig, fig.subplots(rows, cols, squeeze=False)


def run(out="morphomap-demo", *, pairs=EXAMPLES, stream=None, plots=True) -> list:
    """Run the demo, print its table to ``stream`` (default stdout) and return the rows.

    Writes into ``out`` (created if needed), for each pair NAME: ``NAME/c1.csv``, ``NAME/c2.csv``,
    ``NAME/METHOD_VARIANT.csv`` (the field) and ``.png`` (its picture, unless ``plots=False``),
    ``NAME/all.png`` (the grid), and ``quality.csv`` with the table.
    """
    stream = sys.stdout if stream is None else stream
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"morphomap demo: {len(pairs)} example pairs x {len(ALGORITHMS)} algorithms x {len(VARIANTS)} variants "
          "(plain, reverse, transformed), then the default (auto: per piece the crossing-free, "
          "complete candidate of lowest QM); every mapping with split=True (the curves are split where "
          "they cross and each pair of segments is mapped on its own).", file=stream)
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
                title = f"{_VARIANT_TITLES[variant]}{method.replace('_', ' ')}".capitalize()
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
        # The default: per piece the crossing-free, complete candidate of lowest QM.
        field = map_curves(c1, c2)
        q = quality(field, c1, c2, closed=True)
        used = method_summary(field.method)
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
        # Beyond the paper: the order-preserving optimal matching, and the best of every candidate.
        for method in _BEYOND_PAPER:
            tick = time.perf_counter()
            field = map_curves(c1, c2, method)
            q = quality(field, c1, c2, closed=True)
            rows.append(Row(pair, method, "plain", q.qm1, q.qm2, q.qm, q.crossings, int((~field.valid).sum()),
                            len(field), time.perf_counter() - tick))
            if method == BEST:
                winner = next(c.name for c in field.candidates if c.status == "won")
                if winner == "per_piece":  # the pieces' winners, assembled
                    pieces = [r.name for r in field.piece_candidates if r.status == "won"]
                    counts = {n: pieces.count(n) for n in sorted(set(pieces))}
                    won = ", ".join(f"{n} on {k} piece{'s' if k > 1 else ''}" for n, k in counts.items())
                    winner += f" ({won})"
                auto_used[f"{pair} (best)"] = winner
            write_field(folder / f"{method}.csv", field)
            written.append(folder / f"{method}.csv")
            if plots:
                single, single_axes = _figure(1, 1, 6.0)
                plot_field(field, c1, c2, ax=single_axes[0, 0],
                           title=f"{pair}: {method}\nQM1 {_number(q.qm1)}  QM2 {_number(q.qm2)}  QM {_number(q.qm)}")
                save_figure(single, folder / f"{method}.png", dpi=100)
                written.append(folder / f"{method}.png")
        if plots:
            fig.suptitle(f"{pair}: C1 green, C2 blue, vectors red, crossing vectors orange, misses grey x")
            save_figure(fig, folder / "all.png", dpi=80)
            written.append(folder / "all.png")
    table = format_table(rows)
    print(table, file=stream)
    for pair, used in auto_used.items():
        if pair.endswith(" (best)"):
            print(f"best on {pair[:-7]}: the winner is {used}", file=stream)
        else:
            print(f"auto on {pair}: vectors made by {used}", file=stream)
    _write_quality(out / "quality.csv", rows)
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
    return rows + run_images(out / "images", stream=stream, plots=plots)


def command(args, parser) -> int:
    """``morphomap demo``: :func:`run` into ``--out``; 1 where a mapping failed."""
    rows = run(args.out)
    failed = [row for row in rows if row.note.startswith("failed")]
    if failed:
        print(f"morphomap demo: {len(failed)} mappings failed (see the table)", file=sys.stderr)
        return 1
    return 0


#: The 3D frames of the image demo and the algorithms run on each: the paper's Figure 12 case
#: with its three algorithms, the lung-like pair with normal mapping (it folds) and auto.
STACKS = {"figure12": tuple(row.name for row in METHODS if row.basic and row.from_paper and row.surfaces),
          "lung": ("normal", "auto")}


def _write_frames(folder, name, first, second, spacing):
    """Both frames as ImageJ TIFFs with their physical spacing, as a microscope's software writes."""
    paths = []
    for k, frame in enumerate((first, second)):
        path = folder / f"{name}_t{k}.tif"
        resolution = (1.0 / spacing[-2], 1.0 / spacing[-1])
        metadata = {"unit": "um"} if frame.ndim == 2 else {"unit": "um", "spacing": spacing[0], "axes": "ZYX"}
        tifffile.imwrite(path, frame.astype(np.uint8), imagej=True, resolution=resolution, metadata=metadata)
        paths.append(path)
    return paths


def run_images(out="morphomap-demo/images", *, stream=None, plots=True) -> list:
    """The pipeline from segmented images: masks and stacks written as TIFF files, read back
    (:func:`morphomap.read_image`, spacing from the file), contoured (:func:`boundary_from_mask`,
    :func:`surface_from_mask`, smoothed by the finest pixel size), mapped, measured and drawn.

    Writes into ``out``: the frames (``*_t0.tif``, ``*_t1.tif``), the boundaries (``.csv`` curves,
    ``.ply`` surfaces), the fields (``.csv``, 3D with faces) and figures (``.png``), and prints
    one table for 2D and one for 3D. Returns the rows.
    """
    stream = sys.stdout if stream is None else stream
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    print("\nFrom segmented images: masks and stacks written as ImageJ TIFFs, read back, contoured "
          "(smoothed by the finest pixel size), mapped.", file=stream)

    def read_both(paths):
        images = [read_image(path) for path in paths]
        return [image.data for image in images], images[0].spacing, images[0].unit

    rows2, rows3 = [], []
    (mask1, mask2), spacing, unit = read_both(_write_frames(out, "kidney", *kidney_masks()))
    c1, c2 = (boundary_from_mask(m, spacing, smooth=min(spacing)) for m in (mask1, mask2))
    write_curve(out / "kidney_c1.csv", c1)
    write_curve(out / "kidney_c2.csv", c2)
    for method in ("normal", "diffusion", "auto"):
        rows2.append(
            _image_row(
                "kidney_masks",
                method,
                lambda: map_curves(c1, c2, method),
                c1,
                c2,
                out / f"kidney_{method}",
                lambda field, ax, title: plot_field(field, c1, c2, ax=ax, title=title, y_down=True, unit=unit),
                plots,
            )
        )
    makers = {"figure12": ellipsoid_stacks, "lung": lung_stacks}
    for name, methods in STACKS.items():
        (stack1, stack2), spacing, unit = read_both(_write_frames(out, name, *makers[name]()))
        s1, s2 = (surface_from_mask(v, spacing, smooth=min(spacing)) for v in (stack1, stack2))
        write_surface(out / f"{name}_s1.ply", s1)
        write_surface(out / f"{name}_s2.ply", s2)
        for method in methods:
            rows3.append(
                _image_row(
                    f"{name}_stacks",
                    method,
                    lambda: map_surfaces(s1, s2, method),
                    s1,
                    s2,
                    out / f"{name}_{method}",
                    lambda field, ax, title: plot_field_3d(field, s1, s2, ax=ax, title=title, y_down=True,
                                                                 unit=unit),
                    plots,
                    projection="3d",
                )
            )
    print(format_table(rows2), file=stream)
    print(format_table(rows3, defects="folds"), file=stream)
    _write_quality(out / "quality.csv", rows2 + rows3, defects="crossings_or_folds")
    print(f"Wrote the frames, boundaries, fields, figures and quality.csv to {os.path.abspath(out)}", file=stream)
    return rows2 + rows3


def _image_row(pair, method, mapping, b1, b2, stem, draw, plots, projection=None) -> Row:
    """Run one mapping of the image demo; write its field and figure; its row of the table."""
    row = Row(pair, method, "plain")
    tick = time.perf_counter()
    try:
        field = mapping()
        q = quality(field, b1, b2)
    except (ValueError, ArithmeticError, GeometryError) as error:  # reported in the table, not hidden
        row.note = f"failed: {type(error).__name__}: {error}"
        return row
    row.seconds = time.perf_counter() - tick
    row.qm1, row.qm2, row.qm = q.qm1, q.qm2, q.qm
    row.crossings = q.folds if field.dim == 3 else q.crossings
    row.misses, row.vectors = int((~field.valid).sum()), len(field)
    write_field(stem.with_suffix(".csv"), field)
    if plots:
        figure = offscreen_figure(7, 7)
        used = method_summary(field.method)
        draw(
            field,
            figure.add_subplot(projection=projection),
            f"{pair}: {method} ({used})\nQM1 {_number(q.qm1)}  QM2 {_number(q.qm2)}  QM {_number(q.qm)}",
        )
        save_figure(figure, stem.with_suffix(".png"), dpi=100)
    return row
