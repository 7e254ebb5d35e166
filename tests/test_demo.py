"""`morphomap demo` and `morphomap map` end to end."""

import os
import re
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import morphomap as mm  # noqa: E402
from morphomap import demo  # noqa: E402
from morphomap.io import EXAMPLES  # noqa: E402


def morphomap(*args, cwd=None):
    # The package as imported here, also when running from another folder.
    where = os.path.dirname(os.path.dirname(os.path.abspath(mm.__file__)))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [where, os.environ.get("PYTHONPATH")])))
    return subprocess.run([sys.executable, "-m", "morphomap", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=env)


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
    assert mm.read_image(images / "figure12_t0.tif").spacing == (2.0, 0.5, 0.5)
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


def test_map_round_trip(tmp_path):
    c1, c2 = mm.load_example("kidney")
    mm.write_curve(tmp_path / "c1.csv", c1)
    mm.write_curve(tmp_path / "c2.csv", c2, header=False)
    run = morphomap("map", tmp_path / "c1.csv", tmp_path / "c2.csv", "--method", "normal", "--reverse",
                    "-o", tmp_path / "field.csv", "--plot", tmp_path / "field.png")
    assert run.returncode == 0, run.stderr
    expected = mm.map_curves(c1, c2, "normal", reverse=True)
    field = mm.read_field(tmp_path / "field.csv")
    assert np.array_equal(field.starts, expected.starts, equal_nan=True)
    assert np.array_equal(field.ends, expected.ends, equal_nan=True)
    assert (tmp_path / "field.png").stat().st_size > 10_000
    assert f"{len(expected)} vectors" in run.stderr and "QM1" in run.stderr


def test_map_options_reach_map_curves(tmp_path):
    x = np.linspace(0, 1, 30)
    mm.write_curve(tmp_path / "a.csv", np.column_stack([x, np.zeros(30)]))
    mm.write_curve(tmp_path / "b.csv", np.column_stack([3 * x, 1 + x**2]))
    run = morphomap("map", tmp_path / "a.csv", tmp_path / "b.csv", "--method", "uniform", "--open",
                    "--n", 12, "--no-split", "--transform")
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()  # no -o: the field goes to standard output
    assert lines[0] == "start_x,start_y,end_x,end_y,valid,method" and len(lines) == 13
    a, b = mm.read_curve(tmp_path / "a.csv"), mm.read_curve(tmp_path / "b.csv")
    expected = mm.map_curves(a, b, "uniform", closed=False, n=12, split=False, transform=True)
    got = np.array([[float(v) for v in line.split(",")[:4]] for line in lines[1:]])
    assert np.allclose(got, np.hstack([expected.starts, expected.ends]), rtol=0, atol=1e-15)


def test_map_with_the_default_method(tmp_path):
    c1, c2 = mm.load_example("kidney")
    mm.write_curve(tmp_path / "c1.csv", c1)
    mm.write_curve(tmp_path / "c2.csv", c2)
    run = morphomap("map", tmp_path / "c1.csv", tmp_path / "c2.csv", "-o", tmp_path / "f.csv")
    assert run.returncode == 0, run.stderr
    field = mm.read_field(tmp_path / "f.csv")
    assert set(field.method) == {"normal", "reverse_diffusion"}
    assert mm.count_crossings(field.starts, field.ends) == 0


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (None, "cannot read .*missing.csv: No such file"),
        ("x,y,z\n1,2\n", "expected 3 values like the header"),
        ("1,2,3\n", "line 1: expected 2 values"),
        ("x,y\n1,2\n1,two\n2,2\n", "line 3, column y: 'two' is not a number"),
        ("x,y\n0,0\n1,0\n2,0\n", "cannot map .* encloses zero area"),
    ],
)
def test_map_bad_files_exit_2_with_a_message(tmp_path, content, message):
    c1, _ = mm.load_example("circle_ellipse")
    mm.write_curve(tmp_path / "good.csv", c1)
    if content is not None:
        (tmp_path / "missing.csv").write_text(content)
    run = morphomap("map", tmp_path / "missing.csv", tmp_path / "good.csv", "--method", "normal")
    assert run.returncode == 2
    assert "Traceback" not in run.stderr
    assert run.stderr.startswith("usage: morphomap map")
    assert re.search(message, run.stderr), run.stderr


def test_map_bad_arguments_exit_2(tmp_path):
    for args in (["--method", "closest"], ["--n", "1"], ["--open", "--closed"]):
        run = morphomap("map", "a.csv", "b.csv", *args, cwd=tmp_path)
        assert run.returncode == 2 and "Traceback" not in run.stderr, args
