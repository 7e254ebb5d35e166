"""One kernel timed in whichever morphomap the running Python imports: the wheel's or the source build's.

    python bench/wheel_kernel.py [queries]

SurfaceIndex.closest_points (Embree and TBB) for 10^6 points within 0.1 of the vertices of an
ellipsoid of 20480 triangles; the median of five runs after one warm-up. The Embree library the
process loaded is printed too, so the two runs show which copy they used (the wheel's or Debian's).
"""

import statistics
import sys
import time

import numpy as np
import trimesh

import morphomap as mm


def loaded(name):
    with open("/proc/self/maps") as maps:
        return sorted({line.split()[-1] for line in maps if name in line.rsplit("/", 1)[-1]})


def main():
    count = int(float(sys.argv[1])) if len(sys.argv) > 1 else 1_000_000
    sphere = trimesh.creation.icosphere(subdivisions=5)
    vertices = sphere.vertices * [1.5, 1.0, 0.7]
    index = mm.SurfaceIndex(vertices, sphere.faces)
    rng = np.random.default_rng(0)
    queries = vertices[rng.integers(len(vertices), size=count)] + rng.uniform(-0.1, 0.1, (count, 3))
    index.closest_points(queries[:1000])
    times = []
    for _ in range(5):
        start = time.perf_counter()
        index.closest_points(queries)
        times.append(time.perf_counter() - start)
    print(f"closest_points, {count} queries, {len(sphere.faces)} triangles: median {statistics.median(times):.3f} s "
          f"(min {min(times):.3f}, max {max(times):.3f}); {mm.build_info().get('threads', '?')} threads")
    print("extension:", mm._core.__file__)
    print("Embree loaded from:", ", ".join(loaded("libembree")))


if __name__ == "__main__":
    main()
