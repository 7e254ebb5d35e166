"""Fuzzing with frames made the way labs make them (issue "Real segmentations").

Each seed gives a pair of rasterised, contoured frames (tests/frames.py): 2D curves from masks on
one anisotropic pixel grid, 3D surfaces from marching cubes on one anisotropic voxel grid; one
seed in four is "raw" (what a careless user passes: the first contour, all contours concatenated,
debris as a curve, every mesh component, unoriented faces). Every method and variant runs on
every pair in a long-lived child process (tests/fuzz_worker.py), which the parent restarts after
a crash or a time-out, so that a segmentation fault, an abort or a hang is a failure naming the
seed, the method and the variant, and the run goes on with the next case.

Invariants, one test per category and dimension (``test_fuzz_2d[crash]``, ...):

- ``crash``: the child died (a signal or an exit) while on the case;
- ``hang``: no answer within the per-case time limit;
- ``unexpected_exception``: an exception other than ValueError / TypeError / morphomap.GeometryError;
- ``unnamed_error``: a ValueError / TypeError whose message does not start with the argument's name;
- ``empty_region``: "the region between the curves is empty" although C1 and C2 differ;
- ``auto_raised``: ``method="auto"`` (in 3D also ``"optimal"``, which starts from auto's field)
  raised on a pair where a basic method answered the same way
  round (plain or reverse; without misses, and in 2D without crossings, in 3D without folds, as
  the default's contract asks);
  ``auto_raised_raw`` the same on a raw pair (invalid curves or meshes, where the error may be
  right but the rule asks for an answer);
- ``auto_crossings`` (2D): the default returned crossings or misses (it must raise instead);
- ``auto_folds`` (3D): the default or ``optimal`` returned folded triangles or misses (it must
  raise instead);
- ``not_s1_field`` (3D): a field that is not one vector per vertex of S1 (every method's is);
- ``ends_off_target`` / ``starts_off_source``: diffusion, auto and optimal ends not on C2 (S2), starts not
  on C1 (S1), within 1e-6 of the curve's (surface's) bounding-box diagonal;
- ``out_of_order`` (2D diffusion): the ends, in the order of their starts along C1, step back along C2
  (the paper's "crossing": the order of the points kept is what diffusion guarantees; straight vectors
  may still cross where streamlines converge into a concave corner, and are only counted);
  ``folds`` (3D diffusion): not 0;
- ``check_error``: measuring the result (``mm.quality``) raised;
- ``harness``: the generator or the worker failed (a bug of this test, not of the library).

Variants: 2D, the 5 methods x {plain, reverse}, and on every ``MORPHOMAP_FUZZ_EXTRA_EVERY``-th
seed auto with ``transform=True`` and auto with ``split=False``; 3D, the 5 methods x {plain,
reverse}, and on every ``MORPHOMAP_FUZZ_FINE_EVERY``-th seed auto on the same frames contoured
from voxels 5 times finer (``fine``: 10,000-55,000 vertices, the surfaces the default maps through
coarse copies), and on every ``MORPHOMAP_FUZZ_CAPPED_EVERY``-th seed auto on the frames cut by one
plane and closed by caps of long thin triangles, as the real limb stages are (``capped``,
``tests/capped_frames.py``; careful pairs only, the others run as they are).

Environment (all optional):

- ``MORPHOMAP_FUZZ_PAIRS`` (300): 2D pairs per run, fresh seeds included;
  ``MORPHOMAP_FUZZ_PAIRS_3D`` (40, or 2D pairs * 40 / 300 when only the former is set).
- ``MORPHOMAP_FUZZ_FRESH`` (4) / ``MORPHOMAP_FUZZ_FRESH_3D`` (2): of those, fresh random seeds
  (printed in every failure message) instead of fixed ones.
- ``MORPHOMAP_FUZZ_SEEDS``: exactly these seeds, e.g. ``"2d:17,203;3d:5"`` (no fixed or fresh ones).
- ``MORPHOMAP_FUZZ_TIMEOUT_2D`` (60) / ``MORPHOMAP_FUZZ_TIMEOUT_3D`` (120): seconds per case (3
  times as long for the ``fine`` variant).
- ``MORPHOMAP_FUZZ_EXTRA_EVERY`` (20; 0: never).
- ``MORPHOMAP_FUZZ_FINE_EVERY`` (8; 0: never).
- ``MORPHOMAP_FUZZ_CAPPED_EVERY`` (4; 0: never).
- ``MORPHOMAP_FUZZ_WORKERS`` (the usable cores, at most 2): child processes at a time. Each
  case still runs alone in a child, so a crash or a hang names its seed whatever the number.
- ``MORPHOMAP_FUZZ_REPORT``: a path; every case's record is appended there as a JSON line as
  soon as it is known.

Quick local run: ``MORPHOMAP_FUZZ_PAIRS=20 python -m pytest tests/test_fuzz_frames.py``.
Reproduce one case in the foreground: ``python tests/fuzz_worker.py 2 17 diffusion --reverse``.
"""

from __future__ import annotations

import collections
import os
import random
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import frames  # noqa: E402  (next to this file)
from fuzz_children import env_int, run_cases  # noqa: E402

pytest.importorskip("skimage")
pytest.importorskip("scipy")
pytest.importorskip("trimesh")


PAIRS_2D = env_int("MORPHOMAP_FUZZ_PAIRS", 300)
PAIRS_3D = env_int("MORPHOMAP_FUZZ_PAIRS_3D", 40 if "MORPHOMAP_FUZZ_PAIRS" not in os.environ
                    else max(1, round(PAIRS_2D * 40 / 300)))
FRESH_2D = min(env_int("MORPHOMAP_FUZZ_FRESH", 4), PAIRS_2D)
FRESH_3D = min(env_int("MORPHOMAP_FUZZ_FRESH_3D", 2), PAIRS_3D)
EXTRA_EVERY = env_int("MORPHOMAP_FUZZ_EXTRA_EVERY", 20)
FINE_EVERY = env_int("MORPHOMAP_FUZZ_FINE_EVERY", 8)
CAPPED_EVERY = env_int("MORPHOMAP_FUZZ_CAPPED_EVERY", 4)
#: How many times finer the voxels of the ``fine`` variant are.
FINE = 5

METHODS = {2: ("minimal_distance", "normal", "diffusion", "uniform", "auto"),
           3: ("minimal_distance", "normal", "diffusion", "auto", "optimal")}
BASIC = {"minimal_distance", "normal", "diffusion", "uniform"}

CATEGORIES = {
    2: ("crash", "hang", "unexpected_exception", "unnamed_error", "empty_region", "auto_raised",
        "auto_raised_raw", "auto_crossings", "ends_off_target", "starts_off_source", "out_of_order", "check_error",
        "harness"),
    3: ("crash", "hang", "unexpected_exception", "unnamed_error", "empty_region", "auto_raised",
        "auto_raised_raw", "auto_folds", "not_s1_field", "ends_off_target", "starts_off_source", "folds",
        "check_error", "harness"),
}


# ------------------------------------------------------------------------------------------ seeds

def _explicit_seeds():
    text = os.environ.get("MORPHOMAP_FUZZ_SEEDS", "").strip()
    if not text:
        return None
    seeds = {2: [], 3: []}
    for part in text.split(";"):
        if not part.strip():
            continue
        dim, _, values = part.partition(":")
        dim = int(dim.strip().lower().rstrip("d"))
        seeds[dim] += [int(v) for v in values.split(",") if v.strip()]
    return seeds


def _seeds(dim):
    """(fixed seeds, fresh seeds) of this run."""
    explicit = _explicit_seeds()
    if explicit is not None:
        return explicit[dim], []
    pairs, fresh = (PAIRS_2D, FRESH_2D) if dim == 2 else (PAIRS_3D, FRESH_3D)
    system = random.SystemRandom()
    fresh_seeds = sorted({system.randrange(10**6, 2**31) for _ in range(fresh)})
    return list(range(pairs - len(fresh_seeds))), fresh_seeds


def _cases(dim, seeds):
    cases = []
    for seed in seeds:
        style = frames.style_of(seed)
        for method in METHODS[dim]:
            for reverse in (False, True):
                cases.append(dict(dim=dim, seed=seed, style=style, method=method, reverse=reverse,
                                  transform=False, split=True, variant="reverse" if reverse else "plain"))
        if dim == 2 and EXTRA_EVERY and seed % EXTRA_EVERY == 0:
            cases.append(dict(dim=dim, seed=seed, style=style, method="auto", reverse=False,
                              transform=True, split=True, variant="transform"))
            cases.append(dict(dim=dim, seed=seed, style=style, method="auto", reverse=False,
                              transform=False, split=False, variant="no_split"))
        if dim == 3 and FINE_EVERY and seed % FINE_EVERY == 0:
            cases.append(dict(dim=dim, seed=seed, style=style, method="auto", reverse=False,
                              transform=False, split=True, fine=FINE, variant="fine"))
        if dim == 3 and CAPPED_EVERY and seed % CAPPED_EVERY == 0:
            cases.append(dict(dim=dim, seed=seed, style=style, method="auto", reverse=False,
                              transform=False, split=True, capped=True, variant="capped"))
    return cases


def reproduce(record):
    """The one-liner that runs a case in the foreground."""
    flags = {"plain": "", "reverse": " --reverse", "transform": " --transform", "no_split": " --no-split",
             "fine": f" --fine {record.get('fine', FINE)}", "capped": " --capped"}
    return (f"python tests/fuzz_worker.py {record['dim']} {record['seed']} {record['method']}"
            f"{flags[record['variant']]}")


# ------------------------------------------------------------------------------------ the children

# ---------------------------------------------------------------------------------- classification

def classify(records):
    """{category: [(record, message)]} of the invariant failures."""
    failures = collections.defaultdict(list)
    # A basic method answered on this pair, this way round (in 2D without crossings or misses).
    answered = collections.defaultdict(list)

    def way(record):  # auto/transform and auto/no_split have no basic counterpart
        return (record["dim"], record["seed"], record["variant"])

    for record in records:
        if record["method"] in BASIC and record["variant"] in ("plain", "reverse") and record["outcome"] == "ok":
            if record["dim"] == 2 and (record.get("crossings", 0) or record.get("valid") != record.get("vectors")):
                continue
            if record["dim"] == 3 and (record.get("surface_folds", 1) or record.get("valid") != record.get("vectors")):
                continue
            answered[way(record)].append(f"{record['method']}/{record['variant']}")
    for record in records:
        outcome = record["outcome"]
        if outcome == "crash":
            why = f"{record['signal']} in phase {record.get('phase')}: {record['message']}"
            failures["crash"].append((record, why))
            continue
        if outcome == "timeout":
            failures["hang"].append((record, record["message"]))
            continue
        if outcome == "harness":
            failures["harness"].append((record, record.get("message", "") + " " + record.get("traceback", "")[-600:]))
            continue
        if outcome == "error":
            message = f"{record['error_type']}: {record['message']}"
            if not record["allowed"]:
                failures["unexpected_exception"].append((record, message))
            elif not record["geometry"] and not record["named"]:
                failures["unnamed_error"].append((record, message))
            if "is empty" in record["message"] and not record.get("identical", False):
                failures["empty_region"].append((record, message))
            if record["method"] in ("auto", "optimal") and answered.get(way(record)):
                basic = ", ".join(answered[way(record)][:4])
                category = "auto_raised" if record["style"] == "careful" else "auto_raised_raw"
                failures[category].append((record, f"{message} (answered: {basic})"))
            continue
        # outcome "ok"
        if record["method"] == "auto" and record["dim"] == 2 and (
                record.get("crossings", 0) or record.get("valid") != record.get("vectors")):
            failures["auto_crossings"].append(
                (record, f"{record.get('crossings')} crossing pairs, {record['vectors'] - record['valid']} misses"))
        if record["method"] in ("auto", "optimal") and record["dim"] == 3 and (
                record.get("surface_folds", 0) or record.get("valid") != record.get("vectors")):
            misses = record["vectors"] - record["valid"]
            failures["auto_folds"].append((record, f"{record.get('surface_folds')} folded triangles, {misses} misses"))
        if record["dim"] == 3 and record.get("s1_rows") is False:
            failures["not_s1_field"].append((record, f"{record['vectors']} vectors, not one per vertex of S1"))
        if record.get("far_ends"):
            failures["ends_off_target"].append(
                (
                    record,
                    (
                        f"{record['far_ends']} of {record['valid']} ends farther than {record['end_tolerance']:.2e} "
                        f"from the target, up to {record['max_end_distance']:.3e}"
                    ),
                )
            )
        if record.get("far_starts"):
            failures["starts_off_source"].append(
                (
                    record,
                    (
                        f"{record['far_starts']} of {record['valid']} starts farther than "
                        f"{record['start_tolerance']:.2e} "
                        f"from the source, up to {record['max_start_distance']:.3e}"
                    ),
                )
            )
        if record.get("out_of_order"):
            failures["out_of_order"].append(
                (
                    record,
                    (
                        f"{record['out_of_order']} ends out of order along C2 ({record['valid']} valid vectors, "
                        f"{record.get('chord_crossings')} crossing pairs)"
                    ),
                )
            )
        if record.get("folds"):
            failures["folds"].append((record, f"{record['folds']} folds ({record['valid']} valid vectors)"))
        if record.get("check_error"):
            failures["check_error"].append((record, record["check_error"]))
    return failures


def _describe(record):
    info = record.get("info") or {}
    shape = ", ".join(
        f"{k}={info[k]}"
        for k in ("style", "raw", "kind", "smoothing", "n1", "n2", "vertices")
        if info.get(k) not in (None, [])
    )
    return f"seed {record['seed']} {record['method']}/{record['variant']} [{shape}]"


def summary(run):
    """Counts of outcomes, of the allowed errors by message, and the time, as text."""
    records = run["records"]
    lines = [
        f"{run['dim']}D: {len(run['fixed']) + len(run['fresh'])} pairs ({len(run['fixed'])} fixed seeds, "
        f"fresh seeds {run['fresh']}), {len(records)} cases in {run['seconds']:.0f} s"
    ]
    builds = collections.Counter(r.get("build") for r in records if r.get("build"))
    if len(builds) > 1:
        lines.append(
            "WARNING: the library was reinstalled during the run; cases per build: "
            + "; ".join(f"{build}: {count}" for build, count in builds.items())
        )
    elif builds:
        lines.append(f"library: {next(iter(builds))}")
    outcomes = collections.Counter(r["outcome"] for r in records)
    lines.append("outcomes: " + ", ".join(f"{k} {v}" for k, v in sorted(outcomes.items())))
    errors = collections.Counter()
    for r in records:
        if r["outcome"] == "error":
            text = r["message"].split(";")[0].split(" (")[0][:90]
            errors[(r["info"]["style"] if r.get("info") else "?", r["error_type"].rsplit(".", 1)[-1], text)] += 1
    if errors:
        lines.append("errors (style, type, message: count):")
        lines += [f"  {style:7s} {kind}: {text}: {count}" for (style, kind, text), count in errors.most_common(25)]
    missing = [
        r
        for r in records
        if r["outcome"] == "ok" and r["method"] in ("diffusion", "auto") and r.get("valid", 0) < r.get("vectors", 0)
    ]
    if missing:
        lines.append(
            f"diffusion/auto fields with missing ends (NaN): {len(missing)}, e.g. "
            + "; ".join(
                f"{r['seed']} {r['method']}/{r['variant']} {r['vectors'] - r['valid']} of {r['vectors']}"
                for r in missing[:6]
            )
        )
    slow = sorted((r for r in records if r["outcome"] in ("ok", "error")), key=lambda r: -r.get("wall", 0))[:5]
    lines.append("slowest: " + "; ".join(f"{r['seed']} {r['method']}/{r['variant']} {r['wall']:.1f} s" for r in slow))
    per_method = collections.defaultdict(float)
    for r in records:
        per_method[r["method"]] += r.get("wall", 0.0)
    lines.append("time per method: " + ", ".join(f"{k} {v:.0f} s" for k, v in sorted(per_method.items())))
    return "\n".join(lines)


_RUNS = {}


def _run(dim):
    if dim not in _RUNS:
        fixed, fresh = _seeds(dim)
        clock = time.monotonic()
        records = run_cases(_cases(dim, fixed + fresh))
        run = dict(dim=dim, fixed=fixed, fresh=fresh, records=records, seconds=time.monotonic() - clock)
        run["failures"] = classify(records)
        print("\n" + summary(run))
        _RUNS[dim] = run
    return _RUNS[dim]


@pytest.fixture(scope="module")
def run_2d():
    return _run(2)


@pytest.fixture(scope="module")
def run_3d():
    return _run(3)


def _check(run, category):
    found = run["failures"].get(category, [])
    if not found:
        return
    by_variant = collections.Counter(f"{r['method']}/{r['variant']}" for r, _ in found)
    lines = [
        f"{len(found)} {category} failures in {run['dim']}D "
        f"({', '.join(f'{k}: {v}' for k, v in by_variant.most_common())}); "
        f"fresh seeds this run: {run['fresh']}"
    ]
    for record, message in found[:40]:
        lines.append(f"- {_describe(record)}: {message[:400]}")
        lines.append(f"    {reproduce(record)}")
    if len(found) > 40:
        lines.append(f"... and {len(found) - 40} more")
    pytest.fail("\n".join(lines), pytrace=False)


@pytest.mark.parametrize("category", CATEGORIES[2])
def test_fuzz_2d(run_2d, category):
    _check(run_2d, category)


@pytest.mark.parametrize("category", CATEGORIES[3])
def test_fuzz_3d(run_3d, category):
    _check(run_3d, category)


def test_fuzz_2d_ran_every_case(run_2d):
    print(summary(run_2d))
    assert all(record is not None for record in run_2d["records"])
    assert len(run_2d["fixed"]) + len(run_2d["fresh"]) >= (PAIRS_2D if _explicit_seeds() is None else 0)


def test_fuzz_3d_ran_every_case(run_3d):
    print(summary(run_3d))
    assert all(record is not None for record in run_3d["records"])
    assert len(run_3d["fixed"]) + len(run_3d["fresh"]) >= (PAIRS_3D if _explicit_seeds() is None else 0)
