"""Surfaces to and from STL, PLY, OBJ and OFF files."""

import os

import numpy as np
import pytest
import trimesh

import morphomap as mm


@pytest.mark.parametrize("suffix", [".stl", ".ply", ".obj", ".off"])
def test_round_trip(tmp_path, suffix):
    sphere = trimesh.creation.icosphere(3, radius=2.5)
    path = tmp_path / f"s{suffix}"
    mm.write_surface(path, sphere)
    back = mm.read_surface(path)
    # STL repeats each triangle's corners: reading merges them back into the same vertices.
    assert len(back.vertices) == len(sphere.vertices) and len(back.faces) == len(sphere.faces)
    tolerance = {".stl": 1e-6, ".ply": 0.0}.get(suffix, 1e-12)  # STL stores float32, PLY doubles
    assert np.abs(np.sort(back.vertices, axis=0) - np.sort(sphere.vertices, axis=0)).max() <= tolerance
    assert back.volume == pytest.approx(sphere.volume, rel=1e-5)
    # The pair form writes too, and the file maps like the mesh it came from.
    mm.write_surface(path, (sphere.vertices, sphere.faces))
    field = mm.map_surfaces(mm.read_surface(path), sphere.copy().apply_scale(1.5), "normal")
    assert field.valid.all()


def test_bad_files_are_named(tmp_path):
    sphere = trimesh.creation.icosphere(2)
    with pytest.raises(ValueError, match="unknown mesh format '.xyz'"):
        mm.write_surface(tmp_path / "a.xyz", sphere)
    with pytest.raises(ValueError, match="no such file"):
        mm.read_surface(tmp_path / "missing.stl")
    open_mesh = trimesh.Trimesh(sphere.vertices, sphere.faces[1:], process=False)
    open_mesh.export(tmp_path / "open.ply")
    with pytest.raises(ValueError, match="open.ply"):
        mm.read_surface(tmp_path / "open.ply")
    inward = trimesh.Trimesh(sphere.vertices, sphere.faces[:, ::-1], process=False)
    inward.export(tmp_path / "inward.off")
    with pytest.raises(ValueError, match="inward.off: the faces are oriented inwards"):
        mm.read_surface(tmp_path / "inward.off")
    two = trimesh.util.concatenate([sphere, sphere.copy().apply_translation([3, 0, 0])])
    two.export(tmp_path / "two.stl")
    with pytest.raises(ValueError, match="two.stl"):
        mm.read_surface(tmp_path / "two.stl")
    (tmp_path / "junk.obj").write_text("this is not a mesh\n")
    with pytest.raises(ValueError, match="path"):
        mm.read_surface(tmp_path / "junk.obj")


def test_writes_are_atomic(tmp_path, monkeypatch):
    path = tmp_path / "s.ply"
    sphere = trimesh.creation.icosphere(1)
    mm.write_surface(path, sphere)
    before = path.read_bytes()

    def broken(self, *args, **kwargs):
        raise OSError("disk full")

    import meshio

    monkeypatch.setattr(meshio, "write", broken)
    with pytest.raises(OSError, match="disk full"):
        mm.write_surface(path, trimesh.creation.icosphere(3))
    assert path.read_bytes() == before
    assert os.listdir(tmp_path) == ["s.ply"]
    monkeypatch.setattr(trimesh.Trimesh, "export", broken)
    with pytest.raises(OSError, match="disk full"):
        mm.write_surface(tmp_path / "s.off", trimesh.creation.icosphere(3))
    assert os.listdir(tmp_path) == ["s.ply"]
