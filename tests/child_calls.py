"""Calls of morphomap in a long-lived child process, so that an abort or a segmentation fault in the
core fails the test that made the call, naming its input, instead of killing the whole test run.

``ChildCalls().run(expression, expected, **arrays)`` evaluates ``expression`` in the child with
``mm`` (morphomap), ``np`` and the arrays as names and returns its value (pickled; None after an
exception of the types named by ``expected``, a Python expression such as
``"(ValueError, TypeError)"``). Any other exception fails with the child's traceback; a child that
dies fails with its exit status, the input and what it printed (faulthandler's stack), and the
next call starts a new child. Cheap per call (pickled arrays over a pipe), so that a hypothesis
test can send every example through it and still shrink an input that crashes.
"""

from __future__ import annotations

import os
import pickle
import signal
import subprocess
import sys
import tempfile

import numpy as np

_CHILD = r"""
import os, pickle, sys, traceback
import numpy as np
import morphomap as mm

# The protocol has a descriptor of its own; whatever the library prints goes to stderr.
answers = os.fdopen(os.dup(1), "wb")
os.dup2(2, 1)
requests = sys.stdin.buffer
while True:
    try:
        expression, expected, arrays = pickle.load(requests)
    except EOFError:
        break
    try:
        answer = ("value", eval(expression, {"mm": mm, "np": np, **arrays}))
    except BaseException as error:
        answer = ("expected", None) if isinstance(error, eval(expected)) else ("raised", traceback.format_exc())
    try:
        data = pickle.dumps(answer)
    except Exception:  # a value that does not pickle: only its type
        data = pickle.dumps(("value", type(answer[1]).__name__))
    answers.write(data)
    answers.flush()
"""


def _describe(arrays):
    with np.printoptions(precision=17, threshold=10_000):
        return "\n".join(f"{name} = np.{array!r}" if isinstance(array, np.ndarray) else f"{name} = {array!r}"
                         for name, array in arrays.items())


class ChildCalls:
    def __init__(self):
        self._process = None
        self._stderr = None

    def _start(self):
        import morphomap as mm

        where = os.path.dirname(os.path.dirname(os.path.abspath(mm.__file__)))
        env = dict(os.environ, PYTHONFAULTHANDLER="1",
                   PYTHONPATH=os.pathsep.join(filter(None, [where, os.environ.get("PYTHONPATH")])))
        self._stderr = tempfile.TemporaryFile()
        self._process = subprocess.Popen([sys.executable, "-c", _CHILD], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, stderr=self._stderr, env=env)

    def run(self, expression: str, expected: str = "()", **arrays):
        if self._process is None:
            self._start()
        try:
            pickle.dump((expression, expected, arrays), self._process.stdin)
            self._process.stdin.flush()
            answer = pickle.load(self._process.stdout)
        except (EOFError, BrokenPipeError, pickle.UnpicklingError):
            self._died(expression, arrays)
        kind, value = answer
        if kind == "raised":
            raise AssertionError(f"{expression} raised, on\n{_describe(arrays)}\n{value}")
        return value

    def _died(self, expression, arrays):
        process, self._process = self._process, None
        try:
            code = process.wait(timeout=60)
        except subprocess.TimeoutExpired:
            process.kill()
            code = process.wait()
        self._stderr.seek(0)
        printed = self._stderr.read().decode(errors="replace")[-4000:]
        self._stderr.close()
        status = f"signal {signal.Signals(-code).name}" if code < 0 else f"exit status {code}"
        raise AssertionError(f"the child process died ({status}) in {expression}, on\n{_describe(arrays)}\n"
                             f"it printed:\n{printed}")

    def close(self):
        if self._process is not None:
            self._process.stdin.close()
            self._process.wait(timeout=60)
            self._process.stdout.close()
            self._stderr.close()
            self._process = None
