"""Shapes with closed-form geometry, shared by the tests."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from child_calls import ChildCalls


def circle(n, radius=1.0, centre=(0.0, 0.0), clockwise=False):
    """n points on a circle, starting at angle 0."""
    angles = 2 * np.pi * np.arange(n) / n
    if clockwise:
        angles = -angles
    return np.column_stack([centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles)])


def ellipse(n, a, b, centre=(0.0, 0.0)):
    """n points on the ellipse x^2/a^2 + y^2/b^2 = 1, equally spaced in the parameter angle."""
    angles = 2 * np.pi * np.arange(n) / n
    return np.column_stack([centre[0] + a * np.cos(angles), centre[1] + b * np.sin(angles)])


@pytest.fixture
def rng():
    return np.random.default_rng(20141)


@pytest.fixture(scope="module")
def child():
    """A child process that evaluates calls (child_calls.py): an abort there fails the test, not the run."""
    calls = ChildCalls()
    yield calls
    calls.close()


@pytest.fixture
def wobbly():
    """A non-convex closed curve (a star-like blob) with 700 points."""
    t = 2 * np.pi * np.arange(700) / 700
    r = 1.0 + 0.3 * np.sin(5 * t) + 0.1 * np.cos(11 * t)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


#: The real cases beside the project (../shared/cases): read by the tests, never copied in.
SHARED_CASES = Path(__file__).resolve().parents[1].parent / "shared" / "cases"


def require_cases(path: Path) -> None:
    """Skip a test of the real cases where ``path`` (under SHARED_CASES) is absent; in CI (CI=true)
    fail instead: CI must run them."""
    if path.exists():
        return
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"the real cases are missing ({path.relative_to(SHARED_CASES.parent)}); CI must run this test")
    pytest.skip("the shared real cases are not beside the project")


def require_client(available: bool, what: str) -> None:
    """Skip a test of a real client (FEniCSx, ParaView) that this machine lacks; in CI (CI=true),
    where .ci/run installs them, fail instead."""
    if available:
        return
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"{what} is missing, and CI must run this test (.ci/run installs it)")
    pytest.skip(f"{what} is not installed")


def morphomap(*args, cwd=None):
    """Runs the `morphomap` command with the package as imported here (also from another folder)."""
    import morphomap as mm

    where = os.path.dirname(os.path.dirname(os.path.abspath(mm.__file__)))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [where, os.environ.get("PYTHONPATH")])))
    return subprocess.run([sys.executable, "-m", "morphomap", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=env)
