"""Results cross the binding as dicts keyed by the C++ field names and become Python types by
keyword: each record's keys are its class's fields, so a key renamed on one side fails here."""

import inspect

import numpy as np
import pytest
import trimesh

import morphomap as mm
from morphomap import _core


def circle(r, n):
    t = 2 * np.pi * np.arange(n) / n
    return r * np.c_[np.cos(t), np.sin(t)]


C1, C2 = circle(1.0, 64), circle(1.5, 80)
S1 = trimesh.creation.icosphere(subdivisions=2)
S2 = trimesh.creation.icosphere(subdivisions=2)
S2.vertices *= [1.6, 1.3, 1.1]


def field_2d():
    return mm.map_curves(C1, C2, "normal")


def field_3d():
    return mm.map_surfaces(S1, S2, "normal")


# (the Python type, the binding that makes its record, a public call that goes through it)
BOUND = [
    (mm.CurveQuality, "curve_quality", lambda: mm.quality(field_2d(), C1, C2)),
    (mm.CurveQuality, "prepared_curve_quality",
     lambda: mm.quality(field_2d(), mm.PreparedCurve(C1, "c1"), mm.PreparedCurve(C2, "c2"))),
    (mm.SurfaceQuality, "surface_quality", lambda: mm.quality(field_3d(), S1, S2)),
    (mm.SurfaceQuality, "prepared_surface_quality",
     lambda: mm.quality(field_3d(), mm.PreparedSurface(S1, "s1"), mm.PreparedSurface(S2, "s2"))),
    (mm.DiffusionSolution, "solve_diffusion", lambda: mm.solve_diffusion(C1, C2)),
    (mm.ShellDiffusionSolution, "solve_diffusion_3d", lambda: mm.solve_diffusion_3d(S1, S2, progress=False)),
    (mm.Similarity, "align_curves", lambda: mm.align_curves(C1, C2)),
    (mm.InteriorField, "extend_field_2d", lambda: mm.extend_field(field_2d())),
]

# Index queries are methods of the core's index classes: their records, asked directly.
QUERIED = [
    (mm.CurveHits, lambda: _core.CurveIndex(C1, True).closest_points(C2)),
    (mm.CurveHits, lambda: _core.CurveIndex(C1, True).line_intersections(C2, C2)),
    (mm.SurfaceHits, lambda: _core.SurfaceIndex(S1.vertices, np.asarray(S1.faces)).closest_points(S2.vertices)),
    (mm.SurfaceHits, lambda: _core.SurfaceIndex(S1.vertices, np.asarray(S1.faces)).line_intersections(
        S2.vertices, S2.vertices)),
]


def required_fields(cls) -> set:
    """The fields a record must give: those without a default (the others are Python's own, such
    as InteriorField's substeps and attempts)."""
    parameters = inspect.signature(cls).parameters.values()
    return {p.name for p in parameters if p.default is p.empty}


@pytest.mark.parametrize("cls, binding, call", BOUND, ids=[b for _, b, _ in BOUND])
def test_the_bindings_records_are_the_classes_fields(monkeypatch, cls, binding, call):
    records, original = [], getattr(_core, binding)

    def spy(*args, **kwargs):
        records.append(original(*args, **kwargs))
        return records[-1]

    monkeypatch.setattr(_core, binding, spy)
    result = call()
    assert records, f"{binding} was not called"
    assert isinstance(result, cls)
    assert set(records[-1]) == required_fields(cls)


@pytest.mark.parametrize("cls, query", QUERIED)
def test_the_index_records_are_the_hits_fields(cls, query):
    assert set(query()) == required_fields(cls) == set(cls._fields)
