"""Query throughput of morphomap's CurveIndex against its peers, one benchmark group per size.

    python -m pytest bench            (from the repository root; bench/pytest.ini sets the options)

Each group holds morphomap and its peers for one kernel, curve size and query count. Indexes and
scenes are built outside the timed part (the build_* groups time them), and the queries are put in
each tool's own layout beforehand. Before timing, every peer's answer is checked once against
morphomap's (curve_peers.check), so that all tools do the same work.
"""

from __future__ import annotations

import pytest

import curve_peers as cp


def _query_params():
    for kernel in cp.KERNELS:
        for n in cp.CURVE_SIZES:
            for q in cp.QUERY_SIZES:
                for tool in cp.tools(kernel):
                    yield pytest.param(kernel, tool.name, n, q, id=f"{kernel}-n{n:.0e}-q{q:.0e}-{tool.name}")


@pytest.mark.parametrize(("kernel", "name", "n", "q"), list(_query_params()))
def test_query(benchmark, cache, kernel, name, n, q):
    tool = cp.tool(kernel, name)
    pytest.importorskip(tool.module)
    if not tool.runs_at(n, q):
        pytest.skip(f"{name} is left out at curve={n} queries={q}: one call takes too long")
    case = cache.case(n, q)
    benchmark.group = f"{kernel} {case.label}"
    benchmark.extra_info.update(queries=q, curve_vertices=n, threads=tool.threads)
    state = cache.state(tool, n)
    prepared = tool.prepare(state, case)
    result = tool.run(state, prepared)  # also the warm-up round
    reference = cache.reference(kernel, n, q)
    if name != "morphomap":
        benchmark.extra_info["check"] = cp.check(kernel, name, reference, result)
    benchmark.pedantic(tool.run, args=(state, prepared), rounds=5 if q <= 10**5 else 3, iterations=1)
    benchmark.extra_info["queries_per_s"] = q / benchmark.stats.stats.min


def _build_params():
    seen = set()
    for tool in cp.TOOLS:
        if tool.build in seen:  # shapely builds the same tree for both kernels, morphomap too
            continue
        seen.add(tool.build)
        for n in cp.CURVE_SIZES:
            yield pytest.param(tool.kernel, tool.name, n, id=f"build-n{n:.0e}-{tool.name}")


@pytest.mark.parametrize(("kernel", "name", "n"), list(_build_params()))
def test_build(benchmark, kernel, name, n):
    tool = cp.tool(kernel, name)
    pytest.importorskip(tool.module)
    benchmark.group = f"build curve=1e{len(str(n)) - 1}"
    curve = cp.wobbly_curve(n)
    benchmark.pedantic(tool.build, args=(curve,), rounds=3, iterations=1, warmup_rounds=1)
