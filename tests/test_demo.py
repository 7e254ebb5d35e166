"""`morphomap demo` end to end."""

import pytest

pytest.importorskip("matplotlib")

import morphomap as mm  # noqa: E402
from morphomap.cli import demo  # noqa: E402
from morphomap.io import EXAMPLES  # noqa: E402
from conftest import morphomap  # noqa: E402


def test_demo_runs_every_algorithm_and_writes_everything(tmp_path):
    run = morphomap("demo", "--out", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    out = run.stdout
    assert "split=True" in out
    table = [line.split() for line in out.splitlines()]
    for pair in EXAMPLES:
        folder = tmp_path / "out" / pair
        assert (folder / "all.png").stat().st_size > 10_000
        c1, c2 = mm.read_curve(folder / "c1.csv"), mm.read_curve(folder / "c2.csv")
        for method in demo.ALGORITHMS:
            for variant in demo.VARIANTS:
                row = [cells for cells in table if cells[:3] == [pair, method, variant]]
                assert len(row) == 1, (pair, method, variant)
                assert (folder / f"{method}_{variant}.csv").exists()
                qm1, qm2, qm, crossings, misses = row[0][3:]
                field = mm.read_field(folder / f"{method}_{variant}.csv")
                assert (folder / f"{method}_{variant}.png").stat().st_size > 10_000
                assert int(misses) == int((~field.valid).sum())
                quality = mm.quality(field, c1, c2)
                assert int(crossings) == quality.crossings
                assert float(qm) == pytest.approx(quality.qm, rel=1e-3, nan_ok=True)
        auto = [cells for cells in table if cells[:3] == [pair, "auto", "plain"]]
        assert len(auto) == 1 and auto[0][6] == "0"  # the default workflow leaves no crossings
        assert f"auto on {pair}: vectors made by" in out
        assert (folder / "auto.png").exists() and len(mm.read_field(folder / "auto.csv")) > 0
        # Beyond the paper: optimal and best, crossing-free, best no worse than auto.
        for method in ("optimal", "best"):
            row = [cells for cells in table if cells[:3] == [pair, method, "plain"]]
            assert len(row) == 1 and row[0][6] == "0" and row[0][7] == "0", (pair, method)
            assert (folder / f"{method}.png").stat().st_size > 10_000
        best = [cells for cells in table if cells[:3] == [pair, "best", "plain"]][0]
        assert float(best[5]) <= float(auto[0][5])
        assert f"best on {pair}: the winner is" in out
    # The kidney pair is there to show crossings of plain normal mapping.
    normal = [cells for cells in table if cells[:3] == ["kidney", "normal", "plain"]][0]
    assert int(normal[6]) > 0
    assert str((tmp_path / "out").resolve()) in out
    assert (tmp_path / "out" / "quality.csv").read_text().count("\n") == 1 + len(EXAMPLES) * 15
    # From images: the frames are TIFFs a user can map again with the command line; every field of
    # the table is on disk with its figure and its measures hold when recomputed.
    images = tmp_path / "out" / "images"
    stack = mm.read_image(images / "figure12_t0.tif")
    assert (stack.axes, stack.spacing, stack.unit, stack.frame_interval) == ("ZYX", (2.0, 0.5, 0.5), "um", None)
    for pair, method in [("kidney", "normal"), ("kidney", "diffusion"), ("kidney", "auto"),
                         *[(name, m) for name, methods in demo.STACKS.items() for m in methods]]:
        kind = "masks" if pair == "kidney" else "stacks"
        [row] = [cells for cells in table if cells[:3] == [f"{pair}_{kind}", method, "plain"]]
        field = mm.read_field(images / f"{pair}_{method}.csv")
        assert (images / f"{pair}_{method}.png").stat().st_size > 10_000
        if kind == "masks":
            b1, b2 = mm.read_curve(images / "kidney_c1.csv"), mm.read_curve(images / "kidney_c2.csv")
            defects = mm.quality(field, b1, b2).crossings
        else:
            b1, b2 = mm.read_surface(images / f"{pair}_s1.ply"), mm.read_surface(images / f"{pair}_s2.ply")
            defects = mm.quality(field, b1, b2).folds
        assert int(row[6]) == defects and int(row[7]) == int((~field.valid).sum())
        if method in ("diffusion", "auto"):
            assert defects == 0  # the bijective methods and the workflow on real-looking frames


def test_demo_default_folder_and_failures(monkeypatch):
    from morphomap import cli

    calls = []
    monkeypatch.setattr(demo, "run", lambda out: calls.append(out) or [demo.Row("p", "normal", "plain")])
    assert cli.main(["demo"]) == 0 and calls == ["morphomap-demo"]
    monkeypatch.setattr(demo, "run", lambda out: [demo.Row("p", "normal", "plain", note="failed: ValueError: x")])
    assert cli.main(["demo", "--out", "elsewhere"]) == 1
