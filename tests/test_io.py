"""Curve and field CSV files, and the bundled example curves."""

import math

import numpy as np
import pytest

import morphomap as mm
from conftest import circle
from morphomap.io import EXAMPLES


def test_curve_round_trip_is_exact(tmp_path, rng):
    points = rng.normal(size=(57, 2)) * 10.0 ** rng.integers(-12, 12, size=(57, 1))
    mm.write_curve(tmp_path / "c.csv", points)
    assert (tmp_path / "c.csv").read_text().splitlines()[0] == "x,y"
    assert np.array_equal(mm.read_curve(tmp_path / "c.csv"), points)
    mm.write_curve(tmp_path / "bare.csv", points, header=False)
    assert np.array_equal(mm.read_curve(str(tmp_path / "bare.csv")), points)


def test_curve_formats_read(tmp_path):
    (tmp_path / "named.csv").write_text("# made by hand\nid, Y ,X\n0, 2.5, 1\n\n1, -3e-1, 4\n")
    assert np.array_equal(mm.read_curve(tmp_path / "named.csv"), [[1, 2.5], [4, -0.3]])
    (tmp_path / "spaces.txt").write_text("1 2\n3\t4\n5 6\n")
    assert np.array_equal(mm.read_curve(tmp_path / "spaces.txt"), [[1, 2], [3, 4], [5, 6]])
    (tmp_path / "any_header.csv").write_text("\ufeffu,v\n1,2\n")  # a byte-order mark, other names
    assert np.array_equal(mm.read_curve(tmp_path / "any_header.csv"), [[1, 2]])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "no points"),
        ("x,y\n", "no points after the header"),
        ("1,2,3\n4,5,6\n", "line 1: expected 2 values"),
        ("x,y\n1,2\n3\n", "line 3: expected 2 values like the header"),
        ("x,y\n1,2\n3,abc\n", "line 3, column y: 'abc' is not a number"),
        ("1,2\n3,nan\n", "line 2, column y: 'nan' is not a finite number"),
        ("a,b,c\n1,2,3\n", "expected a header with columns x and y"),
    ],
)
def test_bad_curve_files_are_named(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as error:
        mm.read_curve(path)
    assert "bad.csv" in str(error.value)


def test_missing_and_binary_curve_files(tmp_path):
    with pytest.raises(FileNotFoundError):
        mm.read_curve(tmp_path / "nothing.csv")
    (tmp_path / "binary.csv").write_bytes(b"\xff\xfe\x00\x81\x9f")
    with pytest.raises(ValueError, match="not a text"):
        mm.read_curve(tmp_path / "binary.csv")


def test_field_round_trip_with_nan_rows(tmp_path):
    starts = circle(6)
    ends = 2 * starts
    ends[[1, 4]] = np.nan
    methods = ["normal", "normal", "diffusion", "normal", "minimal_distance", "uniform"]
    field = mm.DisplacementField(starts, ends, methods)
    mm.write_field(tmp_path / "f.csv", field)
    lines = (tmp_path / "f.csv").read_text().splitlines()
    assert lines[0] == "start_x,start_y,end_x,end_y,valid,method"
    assert lines[2].endswith(",nan,nan,0,normal")
    back = mm.read_field(tmp_path / "f.csv")
    assert np.array_equal(back.starts, field.starts)
    assert np.array_equal(back.ends, field.ends, equal_nan=True)
    assert np.array_equal(back.valid, field.valid) and list(back.method) == methods


def test_3d_field_round_trips_with_its_faces(tmp_path):
    import trimesh

    s1 = trimesh.creation.icosphere(2)
    s2 = s1.copy().apply_scale(1.4)
    field = mm.map_surfaces(s1, s2, "normal")
    mm.write_field(tmp_path / "f.csv", field)
    # One table of vectors, as pandas.read_csv reads it; the faces in a file of their own beside.
    text = (tmp_path / "f.csv").read_text().splitlines()
    assert text[0] == "start_x,start_y,start_z,end_x,end_y,end_z,valid,method" and len(text) == len(field) + 1
    assert all(len(line.split(",")) == 8 for line in text)
    faces = (tmp_path / "f.faces.csv").read_text().splitlines()
    assert faces[0] == "face_a,face_b,face_c" and len(faces) == len(field.faces) + 1
    back = mm.read_field(tmp_path / "f.csv")
    assert np.array_equal(back.starts, field.starts) and np.array_equal(back.ends, field.ends)
    assert np.array_equal(back.faces, field.faces)
    assert mm.quality(back, s1, s2) == mm.quality(field, s1, s2)
    # The faces as a second table after the vectors (as files used to hold them) read the same.
    (tmp_path / "one.csv").write_text("\n".join(text + faces) + "\n")
    assert np.array_equal(mm.read_field(tmp_path / "one.csv").faces, field.faces)
    (tmp_path / "one.faces.csv").write_text("\n".join(faces) + "\n")
    with pytest.raises(ValueError, match="holds its faces itself, and .*one.faces.csv holds faces too"):
        mm.read_field(tmp_path / "one.csv")
    # Faces must index the vectors, and a 2D field has none.
    (tmp_path / "bad.csv").write_text("\n".join(text + faces[:1] + ["0,1,99999"]) + "\n")
    with pytest.raises(ValueError, match="bad.csv: faces: vertex index 99999"):
        mm.read_field(tmp_path / "bad.csv")
    (tmp_path / "g.csv").write_text("\n".join(text) + "\n")
    (tmp_path / "g.faces.csv").write_text("face_a,face_b,face_c\n0,1\n")
    with pytest.raises(ValueError, match="g.faces.csv: line 2: expected three vector indices"):
        mm.read_field(tmp_path / "g.csv")
    # To an open file the vectors alone, said so.
    with open(tmp_path / "stream.csv", "w") as handle, pytest.warns(UserWarning, match="faces of a 3D field"):
        mm.write_field(handle, field)
    assert mm.read_field(tmp_path / "stream.csv").faces is None
    (tmp_path / "flat.csv").write_text(
        "start_x,start_y,end_x,end_y,valid,method\n0,0,1,1,1,normal\nface_a,face_b,face_c\n0,0,0\n"
    )
    with pytest.raises(ValueError, match="a 2D field has no faces"):
        mm.read_field(tmp_path / "flat.csv")


def test_field_of_a_mapping_round_trips(tmp_path):
    c1, c2 = mm.load_example("circle_ellipse")
    field = mm.map_curves(c1, c2, "normal", reverse=True)
    mm.write_field(tmp_path / "f.csv", field)
    back = mm.read_field(tmp_path / "f.csv")
    assert np.array_equal(back.starts, field.starts, equal_nan=True)
    assert np.array_equal(back.ends, field.ends, equal_nan=True)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("start_x,start_y,end_x,end_y,valid\n", r"lacks the column\(s\) method"),
        ("start_x,start_y,end_x,end_y,valid,method\n0,0,1,1,1\n", "line 2: expected 6 values"),
        ("start_x,start_y,end_x,end_y,valid,method\n0,0,1,nan,1,normal\n", "valid is 1 but"),
        ("start_x,start_y,end_x,end_y,valid,method\n0,0,1,1,yes,normal\n", "column valid"),
        ("start_x,start_y,end_x,end_y,valid,method\n0,0,1,1,1,closest\n", "unknown algorithm names"),
    ],
)
def test_bad_field_files_are_named(tmp_path, text, message):
    (tmp_path / "bad.csv").write_text(text)
    with pytest.raises(ValueError, match=message):
        mm.read_field(tmp_path / "bad.csv")


def test_write_to_an_open_file(tmp_path):
    with open(tmp_path / "c.csv", "w") as handle:
        mm.write_curve(handle, [[0, 0], [1, 0.5]])
        assert not handle.closed
    assert (tmp_path / "c.csv").read_text() == "x,y\n0.0,0.0\n1.0,0.5\n"
    with pytest.raises(TypeError, match="field: expected a DisplacementField"):
        mm.write_field(tmp_path / "f.csv", np.zeros((3, 4)))


def test_bundled_examples():
    assert set(EXAMPLES) == {"circle_ellipse", "kidney"}
    for name in EXAMPLES:
        c1, c2 = mm.load_example(name)
        for curve in (c1, c2):
            assert not mm.is_self_intersecting(curve)
            assert mm.orientation(curve) == 1
    c1, c2 = mm.load_example("circle_ellipse")
    assert c1.shape == c2.shape == (100, 2)
    assert np.allclose(np.hypot(*c1.T), 0.95, rtol=0, atol=1e-15)
    assert np.allclose(c1[0], [0.95, 0]) and np.allclose(c2[0], [2.177, 0])
    assert np.allclose(np.hypot(c2[:, 0] / 2.177, c2[:, 1]), 1.0, atol=1e-5)
    steps = np.hypot(*(np.roll(c2, -1, axis=0) - c2).T)
    assert steps.max() / steps.min() < 1.01  # equal arcs, so nearly equal chords
    k1, k2 = mm.load_example("kidney")
    assert 300 <= len(k1) <= 600 and 300 <= len(k2) <= 600
    assert len(mm.curve_intersections(k1, k2)) >= 2
    with pytest.raises(ValueError, match="name: expected one of"):
        mm.load_example("lung")


def test_kidney_example_defeats_plain_normal_mapping():
    c1, c2 = mm.load_example("kidney")
    field = mm.map_curves(c1, c2, "normal", split=True)
    assert mm.count_crossings(field.starts, field.ends) > 0
    assert math.isfinite(mm.quality(field, c1, c2).qm)


def test_an_unknown_suffix_is_refused_with_the_known_ones(tmp_path):
    c1 = circle(40)
    field = mm.DisplacementField(c1, 1.5 * c1, "normal", source=c1)
    with pytest.raises(ValueError, match=r"path: unknown format '\.vtk' for a displacement field: use one of "
                                         r"\.csv \(.*\); \.txt \(.*\); \.vtu \(.*\); \.vtp \(.*\); \.xdmf \("):
        mm.write_field(tmp_path / "x.vtk", field)
    interior = mm.extend_field(field, mesh_size=0.3)
    with pytest.raises(ValueError, match=r"unknown format '\.csv' for an interior field: use one of \.txt .*\.vtu"):
        mm.write_interior(tmp_path / "u.csv", interior)
    with pytest.raises(ValueError, match=r"unknown format '\.vtu' for a series of interior fields: use one of "
                                         r"\.xdmf .*\.pvd"):
        mm.io.write_interior_series(tmp_path / "s.vtu", [interior], [0.0])
    with pytest.raises(ValueError, match="unknown format '\\(no suffix\\)'"):
        mm.write_field(tmp_path / "field", field)
    assert list(tmp_path.iterdir()) == []  # nothing written
    assert set(mm.io.FORMATS) == {".csv", ".txt", ".vtu", ".vtp", ".xdmf", ".pvd"}


def test_comsol_tables_carry_the_velocity_when_dt_is_given(tmp_path):
    c1 = circle(40)
    field = mm.DisplacementField(c1, 1.5 * c1, "normal", source=c1)
    interior = mm.extend_field(field, mesh_size=0.3)
    mm.write_field(tmp_path / "f.txt", field, dt=0.5)
    mm.write_interior(tmp_path / "u.txt", interior, dt=0.5)
    for name, points, displacement in (("f.txt", field.starts, field.vectors),
                                       ("u.txt", interior.points, interior.displacement)):
        lines = (tmp_path / name).read_text().splitlines()
        assert lines[1] == "% x y ux uy vx vy" and "displacement, velocity" in lines[0]
        table = np.loadtxt(tmp_path / name, comments="%")
        assert np.array_equal(table[:, :2], points) and np.array_equal(table[:, 2:4], displacement)
        assert np.allclose(table[:, 4:], displacement / 0.5, rtol=0, atol=1e-15)
    mm.write_interior(tmp_path / "plain.txt", interior)
    assert (tmp_path / "plain.txt").read_text().splitlines()[1] == "% x y ux uy"


def test_series_files_hold_every_step_at_its_time(tmp_path):
    import xml.etree.ElementTree as ElementTree

    import meshio

    c1 = circle(40)
    field = mm.DisplacementField(c1, 1.5 * c1, "normal", source=c1)
    first = mm.extend_field(field, mesh_size=0.3)
    steps = [first, mm.extend_field(field, mesh=(first.points, first.cells), substeps=3)]
    mm.io.write_interior_series(tmp_path / "s.pvd", steps, [1.0, 2.5])
    entries = ElementTree.parse(tmp_path / "s.pvd").getroot().findall("./Collection/DataSet")
    assert [(e.get("timestep"), e.get("file")) for e in entries] == [("1.0", "s_0000.vtu"), ("2.5", "s_0001.vtu")]
    for entry, step in zip(entries, steps):
        back = meshio.read(tmp_path / entry.get("file"))
        assert np.allclose(back.point_data["displacement"][:, :2], step.displacement)
        assert np.allclose(back.point_data["displacement"][:, 2], 0)
    from morphomap.io.fenicsx import read_point_data

    mm.io.write_interior_series(tmp_path / "s.xdmf", steps, [1.0, 2.5])
    assert np.array_equal(read_point_data(tmp_path / "s.xdmf", time=2.5)[:, :2], steps[1].displacement)
    assert np.array_equal(read_point_data(tmp_path / "s.xdmf")[:, :2], steps[0].displacement)
    other = mm.extend_field(field, mesh_size=0.2)
    with pytest.raises(ValueError, match="interiors: step 1 has other cells than step 0.*write a .pvd"):
        mm.io.write_interior_series(tmp_path / "t.xdmf", [first, other], [0.0, 1.0])
    with pytest.raises(ValueError, match="times: expected 2 increasing values"):
        mm.io.write_interior_series(tmp_path / "t.pvd", steps, [1.0, 1.0])
