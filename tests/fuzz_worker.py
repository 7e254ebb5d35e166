"""The child process of tests/test_fuzz_frames.py: maps the pairs of tests/frames.py, checks the result.

Serve mode (what the test uses): ``python fuzz_worker.py --serve`` reads one case per line on
stdin, as JSON ``{"id", "dim", "seed", "style", "method", "reverse", "transform", "split", "fine"}``, and
answers on stdout with JSON lines: ``{"ready": true}`` once imported, ``{"id", "phase"}`` before
each step (so that the parent knows where a crash happened) and ``{"id", "result": {...}}`` at the
end. The parent restarts it after a crash or a time-out. Anything the library prints goes to
stderr (fd 1 is pointed at it); the protocol has a descriptor of its own. faulthandler prints the
Python stack of a fatal signal on stderr.

One-case mode, to reproduce a failure in the foreground (a segfault kills this process)::

    python tests/fuzz_worker.py 2 17 diffusion --reverse
    python tests/fuzz_worker.py 3 5 auto --style raw

prints the frames' description and the result as JSON.
"""

from __future__ import annotations

import argparse
import faulthandler
import json
import os
import re
import sys
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

#: Names an error message may start with: the arguments of map_curves / map_surfaces.
ARGUMENTS = ("c1", "c2", "s1", "s2", "method", "n", "closed", "reverse", "transform", "split", "anchor",
             "density_threshold")
NAMED = re.compile(r"^(%s)\b" % "|".join(ARGUMENTS))
#: Ends (and starts) must lie on their curve / surface within this fraction of its bounding-box diagonal.
RELATIVE_TOLERANCE = 1e-6
MESSAGE_LIMIT = 600


def _out_of_order(field, c1, c2):
    """Steps backwards along C2 of the ends, taken in the order of their starts along C1 (closed
    curves: cyclic, the shorter way between neighbours, forwards when both curves turn the same
    way; ties allowed)."""
    import morphomap as mm
    import numpy as np

    valid = np.asarray(field.valid)
    if valid.sum() < 3:
        return 0
    along1 = mm.closest_points(np.asarray(field.starts)[valid], c1).arc_lengths
    along2 = mm.closest_points(np.asarray(field.ends)[valid], c2).arc_lengths[np.argsort(along1, kind="stable")]
    length = mm.perimeter(c2)
    steps = np.diff(np.append(along2, along2[0]))
    steps = (steps + length / 2) % length - length / 2
    direction = 1.0 if mm.orientation(c1) == mm.orientation(c2) else -1.0
    return int((direction * steps < -1e-9 * length).sum())


def _polyline_distance(points, curve):
    """Distance of each point (M, 2) to the closed polyline ``curve`` (N, 2)."""
    import numpy as np

    a = curve
    b = np.roll(curve, -1, axis=0)
    d = b - a
    length2 = np.einsum("ij,ij->i", d, d)
    best = np.full(len(points), np.inf)
    for start in range(0, len(points), 256):
        p = points[start:start + 256, None, :]
        t = np.einsum("mnk,nk->mn", p - a[None], d) / np.where(length2 > 0, length2, 1.0)[None]
        t = np.clip(t, 0.0, 1.0)
        q = a[None] + t[..., None] * d[None]
        best[start:start + 256] = np.sqrt(((p - q) ** 2).sum(-1)).min(1)
    return best


def _diagonal(points):
    import numpy as np

    return float(np.linalg.norm(points.max(0) - points.min(0)))


class Worker:
    def __init__(self, say):
        import morphomap
        import numpy  # noqa: F401

        import frames

        self.mm = morphomap
        self.frames = frames
        self.say = say
        self._cached = None
        geometry = getattr(morphomap, "GeometryError", None)
        self.allowed = (ValueError, TypeError) + ((geometry,) if geometry is not None else ())
        self.geometry = geometry

    def pair(self, dim, seed, style, fine, capped):
        key = (dim, seed, style, fine, capped)
        if self._cached is None or self._cached[0] != key:
            self._cached = (key, self.frames.pair(dim, seed, style, fine, capped))
        return self._cached[1]

    def run(self, case):
        import numpy as np

        mm = self.mm
        ident = case.get("id")
        dim, seed, style = int(case["dim"]), int(case["seed"]), case.get("style")
        result = {"phase": "frames"}
        self.say({"id": ident, "phase": "frames"})
        made = self.pair(dim, seed, style, int(case.get("fine", 1)), bool(case.get("capped", False)))
        result["info"] = made.info
        result["identical"] = bool(made.identical)
        method, reverse = case["method"], bool(case.get("reverse", False))
        self.say({"id": ident, "phase": "map"})
        result["phase"] = "map"
        clock = time.perf_counter()
        try:
            if dim == 2:
                field = mm.map_curves(made.c1, made.c2, method=method, reverse=reverse,
                                      transform=bool(case.get("transform", False)),
                                      split=bool(case.get("split", True)))
            else:
                field = mm.map_surfaces(made.s1, made.s2, method=method, reverse=reverse)
        except BaseException as error:  # noqa: BLE001 - every exception is reported and classified
            result["seconds"] = time.perf_counter() - clock
            result.update(status="error", error_type=f"{type(error).__module__}.{type(error).__qualname__}",
                          message=str(error)[:MESSAGE_LIMIT],
                          allowed=isinstance(error, self.allowed),
                          geometry=self.geometry is not None and isinstance(error, self.geometry),
                          named=bool(NAMED.match(str(error))))
            if not isinstance(error, Exception):
                raise
            if not result["allowed"]:
                result["traceback"] = traceback.format_exc()[-2000:]
            return result
        result["seconds"] = time.perf_counter() - clock
        result["status"] = "ok"
        valid = np.asarray(field.valid)
        result.update(vectors=int(len(field)), valid=int(valid.sum()),
                      methods=sorted(set(np.asarray(field.method).tolist())))
        if dim == 2:
            # The straight vectors' crossings: the 2D default returns none (or raises), and a pair
            # on which a basic method answers without crossings or misses must not make it raise.
            result["crossings"] = int(mm.count_crossings(np.asarray(field.starts)[valid],
                                                         np.asarray(field.ends)[valid]))
        else:
            # Every 3D field is one of S1's vertices; its folds decide whether a basic method
            # "answered" (the default must then answer too) and whether the default folded.
            result["s1_rows"] = bool(len(field) == len(made.arrays(made.s1)[0]))
            try:
                result["surface_folds"] = int(mm.quality(field, made.s1, made.s2).folds)
            except Exception as error:  # noqa: BLE001
                result["check_error"] = f"quality: {type(error).__name__}: {error}"[:MESSAGE_LIMIT]
        if method not in ("diffusion", "auto", "optimal"):
            return result

        # The ends lie on C2 (S2), the starts on C1 (S1).
        self.say({"id": ident, "phase": "check_ends"})
        result["phase"] = "check_ends"
        starts, ends = np.asarray(field.starts)[valid], np.asarray(field.ends)[valid]
        try:
            if dim == 2:
                target, source = made.c2, made.c1
                end_distance = _polyline_distance(ends, target) if len(ends) else np.zeros(0)
                start_distance = _polyline_distance(starts, source) if len(starts) else np.zeros(0)
            else:
                (v1, f1), (v2, f2) = made.arrays(made.s1), made.arrays(made.s2)
                target, source = v2, v1
                end_distance = (mm.SurfaceIndex(v2, f2).closest_points(ends).distances
                                if len(ends) else np.zeros(0))
                start_distance = (mm.SurfaceIndex(v1, f1).closest_points(starts).distances
                                  if len(starts) else np.zeros(0))
        except Exception as error:  # noqa: BLE001
            result["check_error"] = f"distances: {type(error).__name__}: {error}"[:MESSAGE_LIMIT]
            return result
        end_tol, start_tol = RELATIVE_TOLERANCE * _diagonal(target), RELATIVE_TOLERANCE * _diagonal(source)
        far_ends = np.flatnonzero(end_distance > end_tol)
        far_starts = np.flatnonzero(start_distance > start_tol)
        result.update(end_tolerance=end_tol, max_end_distance=float(end_distance.max(initial=0.0)),
                      far_ends=int(len(far_ends)), start_tolerance=start_tol,
                      max_start_distance=float(start_distance.max(initial=0.0)), far_starts=int(len(far_starts)))
        if method != "diffusion":
            return result

        # Diffusion: no crossings (2D), no folds (3D).
        self.say({"id": ident, "phase": "quality"})
        result["phase"] = "quality"
        try:
            if dim == 2:
                # What diffusion guarantees is the paper's "no crossing": the order of the points
                # along C1 kept along C2. Straight vectors can still cross where streamlines
                # converge into a concave corner and fan out: counted, not a failure.
                result["out_of_order"] = _out_of_order(field, made.c1, made.c2)
                result["chord_crossings"] = int(mm.quality(field, made.c1, made.c2).crossings)
            else:
                result["folds"] = int(mm.quality(field, made.s1, made.s2).folds)
        except Exception as error:  # noqa: BLE001
            result["check_error"] = f"quality: {type(error).__name__}: {error}"[:MESSAGE_LIMIT]
        return result


def build_id(mm):
    """Which morphomap this process loaded: version, and the extension module's path, size and mtime."""
    core = sys.modules.get("morphomap._core")
    path = getattr(core, "__file__", None) or ""
    try:
        stat = os.stat(path)
        stamp = f"{stat.st_size} bytes, modified {time.strftime('%Y-%m-%d %H:%M:%S', time.localtime(stat.st_mtime))}"
    except OSError:
        stamp = "?"
    return f"morphomap {getattr(mm, '__version__', '?')} ({os.path.basename(path)}, {stamp})"


def _jsonable(value):
    import numpy as np

    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return repr(value)
    return value


def serve():
    faulthandler.enable(file=sys.stderr, all_threads=True)
    protocol = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)  # whatever the library prints goes to stderr
    sys.stdout = sys.stderr

    def say(message):
        protocol.write(json.dumps(_jsonable(message)) + "\n")
        protocol.flush()

    worker = Worker(say)
    say({"ready": True, "pid": os.getpid(), "build": build_id(worker.mm)})
    for line in sys.stdin:
        line = line.strip()
        if not line:
            continue
        case = json.loads(line)
        try:
            result = worker.run(case)
        except Exception as error:  # noqa: BLE001 - a bug of the harness (the generators), not the library
            result = {"status": "harness_error", "message": f"{type(error).__name__}: {error}"[:MESSAGE_LIMIT],
                      "traceback": traceback.format_exc()[-2000:]}
        say({"id": case.get("id"), "result": result})


def main(argv=None):
    parser = argparse.ArgumentParser(description="Run one fuzz case in this process (reproduce a failure).")
    parser.add_argument("--serve", action="store_true", help="the JSON-lines worker of test_fuzz_frames.py")
    parser.add_argument("dim", nargs="?", type=int, choices=(2, 3))
    parser.add_argument("seed", nargs="?", type=int)
    parser.add_argument("method", nargs="?", default="auto")
    parser.add_argument("--style", choices=("careful", "raw"), default=None, help="default: frames.style_of(seed)")
    parser.add_argument("--reverse", action="store_true")
    parser.add_argument("--transform", action="store_true")
    parser.add_argument("--no-split", action="store_true")
    parser.add_argument("--fine", type=int, default=1, help="3D: voxels this many times finer")
    parser.add_argument("--capped", action="store_true", help="3D: cut by a plane, closed by thin-triangle caps")
    args = parser.parse_args(argv)
    if args.serve:
        serve()
        return
    if args.dim is None or args.seed is None:
        parser.error("give dim and seed (or --serve)")
    faulthandler.enable(all_threads=True)
    case = {"id": 0, "dim": args.dim, "seed": args.seed, "style": args.style, "method": args.method,
            "reverse": args.reverse, "transform": args.transform, "split": not args.no_split, "fine": args.fine,
            "capped": args.capped}
    print(json.dumps(case), flush=True)
    result = Worker(lambda message: print(json.dumps(_jsonable(message)), flush=True)).run(case)
    print(json.dumps(_jsonable(result), indent=1))


if __name__ == "__main__":
    main()
