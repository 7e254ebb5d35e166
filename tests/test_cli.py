"""The command line: `morphomap info`, `map`, `extend`, `series` and `batch` end to end."""

import os
import re

import numpy as np
import pytest

import morphomap as mm
from conftest import morphomap


def test_info_prints_versions_and_threads():
    run = morphomap("info")
    assert run.returncode == 0, run.stderr
    out = run.stdout
    info = mm.build_info()
    assert f"morphomap {mm.__version__}" in out
    for key in ("cgal", "embree", "eigen", "tbb"):
        assert info[key] in out
    assert info["threads"] >= 1 and f"threads   {info['threads']}" in out


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
    # The default: the library's map_curves(c1, c2), one vector per point of C1, no crossings.
    expected = mm.map_curves(c1, c2)
    np.testing.assert_allclose(field.ends, expected.ends, rtol=0, atol=1e-12)
    assert list(field.method) == list(expected.method)
    assert len(field) >= len(c1) and mm.count_crossings(field.starts, field.ends) == 0


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


def test_map_refuses_an_unknown_output_suffix_before_mapping(tmp_path):
    c1, c2 = mm.load_example("kidney")
    mm.write_curve(tmp_path / "c1.csv", c1)
    mm.write_curve(tmp_path / "c2.csv", c2)
    run = morphomap("map", tmp_path / "c1.csv", tmp_path / "c2.csv", "-o", tmp_path / "f.vtk")
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert "-o " in run.stderr and "unknown format '.vtk'" in run.stderr and ".csv" in run.stderr
    assert not (tmp_path / "f.vtk").exists()
    # A device is a stream, as "-" is: CSV.
    run = morphomap("map", tmp_path / "c1.csv", tmp_path / "c2.csv", "-o", os.devnull)
    assert run.returncode == 0, run.stderr


def test_map_reads_masks(tmp_path):
    # Two frames of a growing disc as ImageJ TIFFs at 0.5 um per pixel: the command says which
    # spacing it used, writes the field and maps without crossings.
    import numpy as np
    import tifffile

    rows, columns = np.indices((120, 120))
    for name, radius in (("t0.tif", 20.0), ("t1.tif", 25.0)):
        mask = ((columns - 60) * 0.5) ** 2 + ((rows - 60) * 0.5) ** 2 <= radius**2
        tifffile.imwrite(tmp_path / name, mask.astype(np.uint8), imagej=True, resolution=(2.0, 2.0),
                         metadata={"unit": "um"})
    out = tmp_path / "field.csv"
    done = morphomap("map", str(tmp_path / "t0.tif"), str(tmp_path / "t1.tif"), "--smooth", "0.5", "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "pixel spacing 0.5 x 0.5 (the file)" in done.stderr and "crossings 0" in done.stderr
    field = mm.read_field(out)
    lengths = np.linalg.norm(field.ends - field.starts, axis=1)
    assert np.all(field.valid) and abs(np.median(lengths) - 5.0) < 0.3  # radius 20 -> 25 um
    # --spacing overrides the file (rows,columns); a bad one is refused by argparse.
    done = morphomap("map", str(tmp_path / "t0.tif"), str(tmp_path / "t1.tif"), "--spacing", "1,1", "-o", str(out))
    assert done.returncode == 0 and "pixel spacing 1 x 1 (--spacing)" in done.stderr
    done = morphomap("map", str(tmp_path / "t0.tif"), str(tmp_path / "t1.tif"), "--spacing", "1,2,3")
    assert done.returncode == 2 and "spacing: expected one number or one per axis (rows, columns)" in done.stderr
    # A stack and a mask are not two of a kind.
    np.save(tmp_path / "stack.npy", np.ones((3, 4, 4), np.uint8))
    done = morphomap("map", str(tmp_path / "stack.npy"), str(tmp_path / "t1.tif"))
    assert done.returncode == 2 and "is a surface but" in done.stderr and "is a curve" in done.stderr


def test_map_reads_stacks_and_mesh_files(tmp_path):
    # Two frames of a growing ball as an ImageJ stack (2 x 0.5 x 0.5 um voxels, stated in the file)
    # and a .npy (spacing given): the field is written with its faces, so that read_field and
    # quality round-trip, and drawn in 3D; a mesh file maps the same way.
    import numpy as np
    import tifffile

    z, y, x = np.indices((20, 60, 60))

    def ball(radius):
        return ((x - 30) * 0.5) ** 2 + ((y - 30) * 0.5) ** 2 + ((z - 10) * 2.0) ** 2 <= radius**2

    tifffile.imwrite(
        tmp_path / "t0.tif",
        ball(8.0).astype(np.uint8),
        imagej=True,
        resolution=(2.0, 2.0),
        metadata={"spacing": 2.0, "unit": "um", "axes": "ZYX"},
    )
    np.save(tmp_path / "t1.npy", ball(11.0))
    out, plot = tmp_path / "field.csv", tmp_path / "field.png"
    command = ["map", str(tmp_path / "t0.tif"), str(tmp_path / "t1.npy")]
    done = morphomap(*command, "--spacing", "2,0.5,0.5", "--method", "normal", "-o", str(out), "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    assert "voxel spacing 2 x 0.5 x 0.5 (--spacing)" in done.stderr and "folds 0" in done.stderr
    field = mm.read_field(out)
    assert field.dim == 3 and field.faces is not None and field.valid.all()
    lengths = np.linalg.norm(field.vectors, axis=1)
    assert abs(np.median(lengths) - 3.0) < 0.5  # radius 8 -> 11 um
    s0 = mm.surface_from_mask(ball(8.0), (2.0, 0.5, 0.5))
    s1 = mm.surface_from_mask(ball(11.0), (2.0, 0.5, 0.5))
    assert mm.quality(field, s0, s1).folds == 0
    assert plot.stat().st_size > 10_000
    mm.write_surface(tmp_path / "t1.ply", s1)
    done = morphomap("map", str(tmp_path / "t0.tif"), str(tmp_path / "t1.ply"), "--method", "normal", "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "voxel spacing 2 x 0.5 x 0.5 (the file)" in done.stderr
    # Curve options are refused for surfaces, and uniform is a 2D method.
    done = morphomap(*command, "--spacing", "2,0.5,0.5", "--n", "50")
    assert done.returncode == 2 and "--n applies to curves, not to surfaces" in done.stderr
    done = morphomap(*command, "--spacing", "2,0.5,0.5", "--method", "uniform")
    assert done.returncode == 2 and "method" in done.stderr


def test_extend_writes_the_interior_displacement(tmp_path):
    # The kidney pair: the field extended into the domain C1 encloses, on a mesh made here and on
    # a solver's mesh read from a file; the interior is written where -o says.
    import meshio
    import numpy as np

    c1, c2 = mm.load_example("kidney")
    mm.write_curve(tmp_path / "c1.csv", c1)
    mm.write_curve(tmp_path / "c2.csv", c2)
    command = ["extend", str(tmp_path / "c1.csv"), str(tmp_path / "c2.csv")]
    done = morphomap(*command, "--method", "diffusion", "--dt", "2", "-o", str(tmp_path / "u.vtu"))
    assert done.returncode == 0, done.stderr
    assert "InteriorField(" in done.stderr and "written to" in done.stderr
    made = meshio.read(tmp_path / "u.vtu")
    assert {"displacement", "velocity"} <= set(made.point_data)
    solver = mm.extend_field(mm.map_curves(c1, c2, "diffusion"), mesh_size=0.1)
    meshio.write(tmp_path / "solver.xdmf", meshio.Mesh(solver.points, [("triangle", solver.cells)]))
    done = morphomap(
        *command, "--method", "diffusion", "--mesh", str(tmp_path / "solver.xdmf"), "-o", str(tmp_path / "u.txt")
    )
    assert done.returncode == 0, done.stderr
    table = np.loadtxt(tmp_path / "u.txt", comments="%")
    assert np.allclose(table[:, :2], solver.points) and np.allclose(table[:, 2:], solver.displacement)
    done = morphomap(*command, "--method", "diffusion", "--mesh", str(tmp_path / "solver.xdmf"),
                     "--extension", "elastic", "--substeps", "2", "-o", str(tmp_path / "e.txt"))
    assert done.returncode == 0, done.stderr
    elastic = mm.extend_field(
        mm.map_curves(c1, c2, "diffusion"), mesh=(solver.points, solver.cells), method="elastic", substeps=2
    )
    assert np.allclose(np.loadtxt(tmp_path / "e.txt", comments="%")[:, 2:], elastic.displacement)
    done = morphomap(*command, "--mesh", str(tmp_path / "u.txt"), "-o", str(tmp_path / "v.vtu"))
    assert done.returncode == 2 and "cannot read the mesh" in done.stderr


def test_series_and_batch_commands(tmp_path):
    import numpy as np

    from conftest import circle

    paths = []
    for k in range(3):
        paths.append(tmp_path / f"t{k}.csv")
        mm.write_curve(paths[-1], circle(120, 1.0 + 0.3 * k))
    done = morphomap("series", *map(str, paths), "--method", "normal", "--out", str(tmp_path / "series"))
    assert done.returncode == 0, done.stderr
    assert "step 1:" in done.stderr and "3 frames in 2D" in done.stderr
    table = np.loadtxt(tmp_path / "series" / "trajectories.csv", delimiter=",", skiprows=1)
    assert np.allclose(np.linalg.norm(table[table[:, 0] == 2][:, 2:], axis=1), 1.6)
    (tmp_path / "jobs.csv").write_text("c1,c2\nt0.csv,t1.csv\nt1.csv,t2.csv,diffusion\nt0.csv,missing.csv\n")
    command = ["batch", str(tmp_path / "jobs.csv"), "--out", str(tmp_path / "b"), "--workers", "2"]
    done = morphomap(*command)
    assert done.returncode == 1 and "3 jobs: 2 done or skipped, 1 failed" in done.stderr, done.stderr
    assert mm.read_field(tmp_path / "b" / "002_t1_t2.csv").method[0] == "diffusion"


def test_series_command_writes_growth_maps_figures_and_animation(tmp_path):
    import numpy as np
    from PIL import Image

    from conftest import circle

    paths = []
    for k, radius in enumerate((1.0, 1.5, 2.5)):
        paths.append(tmp_path / f"t{k}.csv")
        mm.write_curve(paths[-1], circle(60, radius))
    done = morphomap(
        "series", *map(str, paths), "--method", "normal", "--dt", "0.5", "--no-progress", "--out", str(tmp_path / "s")
    )
    assert done.returncode == 0, done.stderr
    out = tmp_path / "s"
    born = np.loadtxt(out / "points.csv", delimiter=",", skiprows=1)
    assert (born[:60, 1] == 0).all() and (born[60:, 1] == 2).all() and len(born) == 180  # 2 new points a piece
    speeds = np.loadtxt(out / "normal_speed.csv", delimiter=",", skiprows=1)
    assert np.allclose(speeds[speeds[:, 0] == 1, 2], 2.0)  # (2.5 - 1.5) / 0.5
    stretch = np.loadtxt(out / "stretch.csv", delimiter=",", skiprows=1)
    assert np.allclose(stretch[stretch[:, 0] == 1, -1], 2.5)
    for name in ("trajectories.png", "stretch.png", "normal_speed.png"):
        assert Image.open(out / name).format == "PNG"
    with Image.open(out / "series.gif") as gif:
        assert gif.n_frames == 3
    bad = morphomap("series", *map(str, paths), "--reseed", "1", "--out", str(out))
    assert bad.returncode == 2 and "expected a factor > 1 or 'none'" in bad.stderr
