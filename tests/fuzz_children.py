"""The worker children of tests/test_fuzz_frames.py: each maps the pairs of tests/frames.py in its own
process (tests/fuzz_worker.py), so that a crash or a hang fails its case, not the suite; the settings
are read from the environment as test_fuzz_frames.py documents them."""

from __future__ import annotations

import collections
import json
import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import frames

HERE = Path(__file__).resolve().parent
WORKER = HERE / "fuzz_worker.py"


def env_int(name, default):
    value = os.environ.get(name, "").strip()
    return int(value) if value else default


def env_float(name, default):
    value = os.environ.get(name, "").strip()
    return float(value) if value else default


TIMEOUT = {2: env_float("MORPHOMAP_FUZZ_TIMEOUT_2D", 60.0), 3: env_float("MORPHOMAP_FUZZ_TIMEOUT_3D", 120.0)}
# Frames from finer voxels (the "fine" variant) have up to 25 times the vertices: where auto
# refuses one, it has run whole-resolution diffusion twice (two Mesh_3 runs of about a minute each
# on 28k vertices; 130 s in all beside another job), which is slow, not hung.
FINE_TIMEOUT_FACTOR = 3.0


def timeout_of(case):
    """Seconds a case may take before it counts as hung."""
    return TIMEOUT[case["dim"]] * (FINE_TIMEOUT_FACTOR if int(case.get("fine", 1)) > 1 else 1.0)


def _usable_cores():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


# Two children by default: the cases are independent and most of a case's time is one thread
# (2D meshing and tracing, the Python checks), so a second child nearly halves the suite on CI's
# two cores (bench/README, "CI time"); more would multiply the 3D meshes' memory.
WORKERS = max(1, env_int("MORPHOMAP_FUZZ_WORKERS", min(2, _usable_cores())))
STARTUP_TIMEOUT = 300.0
REPORT = os.environ.get("MORPHOMAP_FUZZ_REPORT", "").strip()


def _signal_name(returncode):
    if returncode is None:
        return "no exit status"
    if returncode < 0:
        try:
            return f"{signal.Signals(-returncode).name} (signal {-returncode})"
        except ValueError:
            return f"signal {-returncode}"
    return f"exit status {returncode}"


class Child:
    """One worker process: JSON lines in on stdin, JSON lines out on stdout, stderr to a file."""

    def __init__(self):
        self.proc = None
        self.err = None
        self.buffer = b""
        self.case = None
        self.deadline = None
        self.phase = None
        self.err_offset = 0
        self.sent_at = None
        self.build = None

    @property
    def alive(self):
        return self.proc is not None

    def start(self):
        if self.err is not None:
            self.err.close()
        self.err = tempfile.TemporaryFile()
        env = dict(os.environ, PYTHONFAULTHANDLER="1", PYTHONUNBUFFERED="1")
        # The worker runs in this folder: a relative PYTHONPATH (``PYTHONPATH=python`` from the
        # repository root) would miss the build under test and import an installed copy instead.
        if env.get("PYTHONPATH"):
            env["PYTHONPATH"] = os.pathsep.join(os.path.abspath(part) if part else part
                                                for part in env["PYTHONPATH"].split(os.pathsep))
        self.proc = subprocess.Popen([sys.executable, str(WORKER), "--serve"], cwd=str(HERE), env=env,
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.err)
        self.buffer = b""
        deadline = time.monotonic() + STARTUP_TIMEOUT
        while True:
            lines, eof = self.read(deadline - time.monotonic())
            for message in lines:
                if message.get("ready"):
                    self.build = message.get("build")
                    return
            if eof or time.monotonic() > deadline:
                tail = self.stderr_tail(0)
                self.kill()
                raise RuntimeError(f"the fuzz worker did not start: {tail}")

    def fileno(self):
        return self.proc.stdout.fileno()

    def read(self, timeout=0.0):
        """Complete JSON messages available within ``timeout`` seconds, and whether stdout closed."""
        ready, _, _ = select.select([self.proc.stdout], [], [], max(0.0, timeout))
        if not ready:
            return [], False
        chunk = os.read(self.fileno(), 1 << 16)
        if not chunk:
            return self._split(), True
        self.buffer += chunk
        return self._split(), False

    def _split(self):
        messages = []
        while b"\n" in self.buffer:
            line, self.buffer = self.buffer.split(b"\n", 1)
            if line.strip():
                try:
                    messages.append(json.loads(line))
                except ValueError:
                    messages.append({"garbage": line.decode(errors="replace")[:300]})
        return messages

    def send(self, case, timeout):
        self.case, self.phase = case, "sent"
        self.err.flush()
        self.err_offset = os.fstat(self.err.fileno()).st_size
        self.sent_at = time.monotonic()
        self.deadline = self.sent_at + timeout
        self.proc.stdin.write((json.dumps({k: v for k, v in case.items() if k != "variant"}) + "\n").encode())
        self.proc.stdin.flush()

    def stderr_tail(self, offset, limit=2500):
        self.err.seek(offset)
        text = self.err.read().decode(errors="replace")
        return text[-limit:]

    def kill(self):
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.kill()
            returncode = self.proc.wait()
            for stream in (self.proc.stdin, self.proc.stdout):
                try:
                    stream.close()
                except OSError:
                    pass
            self.proc = None
            return returncode
        return None

    def close(self):
        if self.proc is not None:
            try:
                self.proc.stdin.close()
                self.proc.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                pass
            self.kill()
        if self.err is not None:
            self.err.close()
            self.err = None


def _fatal_lines(tail):
    """The faulthandler header and the first frames of its stack, for the failure message."""
    lines = [line for line in tail.splitlines() if line.strip()]
    for i, line in enumerate(lines):
        if line.startswith("Fatal Python error") or "terminate called" in line or "Assertion" in line:
            return " | ".join(lines[i:i + 6])
    return " | ".join(lines[-4:])


def _share_tail(idle, others):
    """Moves the back half of the longest other queue to the idle child's queue. Cases of one seed
    go to one child (the frames are made once per child and seed); at the end of a run that left
    one child with a whole 3D seed (8 cases, minutes) while the other had nothing to do."""
    longest = max(others, key=len, default=None)
    if longest is None or len(longest) < 2:
        return
    moved = [longest.pop() for _ in range(len(longest) // 2)]
    idle.extend(reversed(moved))


def run_cases(cases):
    """Run every case in worker children; returns one record per case, in order."""
    groups = collections.OrderedDict()
    for index, case in enumerate(cases):
        groups.setdefault((case["dim"], case["seed"]), []).append(index)
    pending = collections.deque(groups.values())
    records = [None] * len(cases)
    children = [Child() for _ in range(WORKERS)]
    queues = {id(child): collections.deque() for child in children}
    startup_failures = 0

    def finish(child, **record):
        index = child.case["index"]
        if "info" not in record:  # the child died: describe the frames from here
            try:
                made = frames.pair(cases[index]["dim"], cases[index]["seed"], cases[index]["style"])
                record.update(info=made.info, identical=bool(made.identical))
            except Exception as error:  # noqa: BLE001
                record.update(info={}, info_error=str(error)[:300])
        records[index] = dict(cases[index], wall=time.monotonic() - child.sent_at, build=child.build, **record)
        child.case = None
        if REPORT:  # as they come, so that an interrupted run leaves its records
            with open(REPORT, "a") as out:
                out.write(json.dumps(records[index]) + "\n")

    def dispatch(child):
        nonlocal startup_failures
        queue = queues[id(child)]
        if not queue and not pending:
            _share_tail(queue, [queues[id(other)] for other in children if other is not child])
        while queue or pending:
            if not queue:
                queue.extend(pending.popleft())
            index = queue.popleft()
            case = dict(cases[index], index=index)
            if not child.alive:
                try:
                    child.start()
                    startup_failures = 0
                except (RuntimeError, OSError) as error:
                    startup_failures += 1
                    records[index] = dict(cases[index], outcome="harness", message=str(error)[:1500], wall=0.0)
                    if startup_failures >= 3:  # the worker cannot start at all: give up on the rest
                        for rest in list(queue) + [i for group in pending for i in group]:
                            records[rest] = dict(cases[rest], outcome="harness", wall=0.0,
                                                 message="not run: the fuzz worker does not start")
                        queue.clear()
                        pending.clear()
                        return
                    continue
            try:
                child.send(case, timeout_of(case))
            except OSError:  # the child died between two cases: start a new one for this case
                child.kill()
                queue.appendleft(index)
                continue
            return

    try:
        for child in children:
            dispatch(child)
        while True:
            busy = [child for child in children if child.case is not None]
            if not busy:
                break
            wait = max(0.0, min(child.deadline for child in busy) - time.monotonic())
            readable, _, _ = select.select([child.proc.stdout for child in busy], [], [], min(wait, 5.0))
            for child in busy:
                if child.proc.stdout in readable:
                    messages, eof = child.read(0.0)
                    for message in messages:
                        if "phase" in message:
                            child.phase = message["phase"]
                        elif "result" in message and child.case is not None:
                            result = message["result"]
                            outcome = result.pop("status", "harness")
                            if outcome == "harness_error":
                                outcome = "harness"
                            finish(child, outcome=outcome, **result)
                            dispatch(child)
                            break
                    if eof and child.case is not None:
                        tail = child.stderr_tail(child.err_offset)
                        returncode = child.kill()
                        finish(child, outcome="crash", phase=child.phase, signal=_signal_name(returncode),
                               returncode=returncode, stderr=tail, message=_fatal_lines(tail))
                        dispatch(child)
                elif child.case is not None and time.monotonic() > child.deadline:
                    phase = child.phase
                    child.kill()
                    finish(child, outcome="timeout", phase=phase,
                           message=f"no answer within {timeout_of(child.case):g} s (phase {phase})")
                    dispatch(child)
    finally:
        for child in children:
            child.close()
    return records
