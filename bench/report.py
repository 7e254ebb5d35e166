#!/usr/bin/env python3
"""Time morphomap and its peers once, in one process, and print markdown tables.

    PYTHONPATH=build/dev-bench/pkg python3 bench/report.py [--repeat 3] [--curves 1000 10000]

Throughput is queries per second of the best of --repeat runs, more while they take under 0.2 s in
all (time.perf_counter); indexes are built and queries converted to each tool's layout before
timing. The answers of the last run of every peer are checked against morphomap's
(curve_peers.check). Build times are one build each.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np

import curve_peers as cp


def compiler_running() -> bool:
    try:
        return subprocess.run(["pgrep", "-f", "cc1plus"], capture_output=True).returncode == 0
    except FileNotFoundError:
        return False


def busy_cores(seconds: float = 1.0) -> float:
    """Cores kept busy by other processes over a short window (Linux /proc; 0 elsewhere)."""
    def sample():
        with open("/proc/stat") as f:
            fields = [int(x) for x in f.readline().split()[1:]]
        with open("/proc/self/stat") as f:
            mine = f.read().rsplit(")", 1)[1].split()
        return sum(fields) - fields[3] - fields[4], sum(fields), int(mine[11]) + int(mine[12])

    try:
        busy0, total0, own0 = sample()
        time.sleep(seconds)
        busy1, total1, own1 = sample()
    except (OSError, ValueError, IndexError):
        return 0.0
    cores = os.cpu_count() or 1
    return cores * max(0, (busy1 - busy0) - (own1 - own0)) / max(1, total1 - total0)


def wait_for_quiet(limit_s: float) -> bool:
    """Numbers taken while a compiler or tests share the cores are wrong; wait for them to finish."""
    start = time.monotonic()
    told = False
    while time.monotonic() - start < limit_s:
        if not compiler_running() and busy_cores() < 0.3:
            return True
        if not told:
            print("(the machine is busy: waiting for it to become idle)", file=sys.stderr, flush=True)
            told = True
        time.sleep(4.0)
    print("WARNING: the machine is still busy; these numbers are taken under load", file=sys.stderr)
    return False


def best_of(repeat, fn, *args, min_total=0.2):
    """Best time of at least `repeat` runs, and of more while they add up to under min_total
    seconds: a run of a millisecond or so is at the mercy of a thread waking up late."""
    best, result, runs, spent = np.inf, None, 0, 0.0
    while runs < repeat or spent < min_total:
        start = time.perf_counter()
        result = fn(*args)
        elapsed = time.perf_counter() - start
        best, runs, spent = min(best, elapsed), runs + 1, spent + elapsed
    return best, result


def rate(x: float | None) -> str:
    if x is None:
        return "—"
    return f"{x / 1e6:.2f} M" if x >= 1e6 else f"{x / 1e3:.0f} k"


def ratio(a: float | None, b: float | None) -> str:
    return "—" if a is None or b is None else f"{a / b:.2f}x"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--curves", type=int, nargs="+", default=list(cp.CURVE_SIZES))
    parser.add_argument("--queries", type=int, nargs="+", default=list(cp.QUERY_SIZES))
    parser.add_argument("--kernels", nargs="+", default=list(cp.KERNELS), choices=cp.KERNELS)
    parser.add_argument(
        "--wait", type=float, default=900.0, help="seconds to wait, before each size, for other load to end"
    )
    args = parser.parse_args()

    import morphomap as mm

    info = mm.build_info()
    skipped = sorted({f"{t.name} ({t.module})" for t in cp.TOOLS if not t.available()})
    builds: dict[tuple[str, int], float] = {}
    checks: list[str] = []
    loaded: list[str] = []
    tables = []
    for tool in cp.TOOLS:  # first use loads libraries and starts thread pools: not build time
        if tool.available():
            tool.build(cp.wobbly_curve(100))
    for kernel in args.kernels:
        tools = [t for t in cp.tools(kernel) if t.available()]
        rows = []
        for n in args.curves:
            curve = cp.wobbly_curve(n)
            states = {}
            for tool in tools:
                start = time.perf_counter()
                states[tool.name] = tool.build(curve)
                builds.setdefault((tool.name, n), time.perf_counter() - start)
            for q in args.queries:
                if not wait_for_quiet(args.wait):
                    loaded.append(f"{kernel} n={n} q={q}")
                case = cp.make_case(n, q)
                throughput: dict[str, float | None] = {}
                reference = None
                for tool in tools:
                    if not tool.runs_at(n, q):
                        throughput[tool.name] = None
                        continue
                    prepared = tool.prepare(states[tool.name], case)
                    seconds, result = best_of(args.repeat, tool.run, states[tool.name], prepared)
                    throughput[tool.name] = q / seconds
                    if tool.name == "morphomap":
                        reference = result
                    else:
                        checks.append(
                            f"{kernel} n={n} q={q} {tool.name}: {cp.check(kernel, tool.name, reference, result)}"
                        )
                    del prepared, result
                mine = throughput["morphomap"]
                peers = [v for t in tools if t.equal_work and t.name != "morphomap" and (v := throughput[t.name])]
                rows.append(
                    [
                        kernel,
                        f"{n:,}",
                        f"{q:,}",
                        *(rate(throughput[t.name]) for t in tools),
                        ratio(mine, max(peers, default=None)),
                        ratio(mine, throughput.get("shapely")),
                    ]
                )
                print(f"done: {kernel} n={n} q={q}", file=sys.stderr, flush=True)
        header = [
            "kernel",
            "curve vertices",
            "queries",
            *(f"{t.name} (q/s)" + ("" if t.equal_work else " [lower bound]") for t in tools),
            "morphomap / fastest peer",
            "morphomap / shapely",
        ]
        tables.append((header, rows))

    print(
        f"morphomap {info.get('version')} with {info.get('threads', '?')} threads; "
        f"best of {args.repeat}; throughput in queries per second (k = 10^3, M = 10^6)."
    )
    print("Threads: " + ", ".join(sorted({f"{t.name} {t.threads}" for t in cp.TOOLS if t.available()})) + ".")
    if loaded:
        print("WARNING, taken while other processes kept the cores busy: " + ", ".join(loaded) + ".")
    if skipped:
        print("Not installed, left out: " + ", ".join(skipped) + ".")
    print(
        "Shapely is left out (—) above "
        + "; ".join(
            f"{k}: {cp.SHAPELY_MAX_CURVE[k]:,} vertices or {cp.SHAPELY_MAX_WORK[k]:,} queries" for k in cp.KERNELS
        )
        + ".\n"
    )
    for header, rows in tables:
        print("| " + " | ".join(header) + " |")
        print("|" + "|".join("---" if i < 1 else "---:" for i in range(len(header))) + "|")
        for row in rows:
            print("| " + " | ".join(row) + " |")
        print()
    names = sorted({name for name, _ in builds}, key=lambda s: [t.name for t in cp.TOOLS].index(s))
    print("Build time (ms), one build (Open3D and embreex include the lazy BVH build):\n")
    print("| curve vertices | " + " | ".join(names) + " |")
    print("|---:|" + "---:|" * len(names))
    for n in args.curves:
        print(
            f"| {n:,} | " + " | ".join(f"{builds[(m, n)] * 1e3:.1f}" if (m, n) in builds else "—" for m in names) + " |"
        )
    print("\nAgreement with morphomap (not timed):\n")
    for line in checks:
        print(f"- {line}")


if __name__ == "__main__":
    main()
