"""Atomic file writes: into a temporary file beside the target, renamed over it once complete.

An interrupted or failed write then leaves the previous file as it was, never a truncated one.
"""

from __future__ import annotations

import contextlib
import os
import tempfile


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; on success it replaces ``path``, else it is removed."""
    path = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(path))
    # The temporary name keeps the suffix: writers that go by it (matplotlib) still see it.
    handle, temporary = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".part" + os.path.splitext(name)[1])
    os.close(handle)
    try:
        # mkstemp makes the file private; a written file gets the usual permissions.
        os.chmod(temporary, 0o666 & ~_umask())
        yield temporary
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


@contextlib.contextmanager
def atomic_text(path):
    """An open text file (UTF-8, no newline translation) whose content replaces ``path`` on success."""
    with atomic_path(path) as temporary:
        with open(temporary, "w", encoding="utf-8", newline="") as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
