"""The command line."""

import subprocess
import sys

import morphomap as mm


def test_info_prints_versions_and_threads():
    out = subprocess.run([sys.executable, "-m", "morphomap", "info"], capture_output=True, text=True, check=True).stdout
    info = mm.build_info()
    assert f"morphomap {mm.__version__}" in out
    for key in ("cgal", "embree", "eigen", "tbb"):
        assert info[key] in out
    assert info["threads"] >= 1 and f"threads   {info['threads']}" in out


def test_kernels_release_the_gil():
    """While one thread runs a long query, another Python thread keeps running."""
    import threading

    import numpy as np

    from conftest import circle

    index = mm.CurveIndex(circle(20000))
    queries = np.random.default_rng(1).uniform(-2, 2, size=(2_000_000, 2))
    started = threading.Event()

    def work():
        started.set()
        index.closest_points(queries)

    worker = threading.Thread(target=work)
    worker.start()
    started.wait()
    spins = 0
    while worker.is_alive():
        spins += 1
    worker.join()
    # Holding the GIL, the kernel would leave this thread a handful of switch intervals at most.
    assert spins > 1000
