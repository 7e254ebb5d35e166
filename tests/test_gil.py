"""The kernels release the GIL: other Python threads run while they work."""

import morphomap as mm


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
