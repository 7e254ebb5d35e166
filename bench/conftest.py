"""Inputs shared by the benchmarks, built once per pytest run: cases, built indexes and morphomap's answers.

Everything here is made once and outside the timed part; see curve_peers.py for the tools.
"""

from __future__ import annotations

import pytest

import curve_peers as cp


def pytest_configure(config):
    try:
        import morphomap  # noqa: F401
    except ImportError as error:
        raise pytest.UsageError(
            f"cannot import morphomap ({error}); build it with `tests/dev_build.sh bench` and run with "
            "PYTHONPATH=build/dev-bench/pkg"
        ) from None


class _Cache:
    def __init__(self):
        self.cases = {}
        self.states = {}
        self.references = {}

    def case(self, n, q):
        if (n, q) not in self.cases:
            self.cases[(n, q)] = cp.make_case(n, q)
        return self.cases[(n, q)]

    def state(self, tool: cp.Tool, n):
        key = (tool.kernel, tool.name, n)
        if key not in self.states:
            self.states[key] = tool.build(cp.wobbly_curve(n))
        return self.states[key]

    def reference(self, kernel, n, q):
        """morphomap's distances for one kernel and size, the yardstick of the agreement checks."""
        key = (kernel, n, q)
        if key not in self.references:
            tool = cp.tool(kernel, "morphomap")
            state = self.state(tool, n)
            self.references[key] = tool.run(state, tool.prepare(state, self.case(n, q)))
        return self.references[key]


@pytest.fixture(scope="session")
def cache():
    return _Cache()
