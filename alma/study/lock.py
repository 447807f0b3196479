"""One run at a time on a study's folder: an advisory lock on ``OUT/.alma.lock``.

The lock is ``flock`` on an open file descriptor, which the operating system releases when the
process ends however it ends (a kill, a crash): a lock file left behind by a killed run is
never stale.  A second run on the same folder is refused at once with the first one's pid, so
no panel is ever solved twice by two runs.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows has no flock: studies there run unlocked
    fcntl = None  # type: ignore[assignment]

LOCK_FILE = ".alma.lock"


class StudyBusy(RuntimeError):
    """Another run holds the study's folder."""


@contextmanager
def study_lock(out_dir: str | os.PathLike[str]) -> Iterator[Path]:
    """Hold the lock of ``out_dir`` for the duration of the block; :class:`StudyBusy` when
    another process holds it."""
    path = Path(out_dir) / LOCK_FILE
    if fcntl is None:  # pragma: no cover
        yield path
        return
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        if not _try_lock(fd):
            holder = os.pread(fd, 64, 0).decode("ascii", "replace").strip() or "unknown"
            raise StudyBusy(
                f"{out_dir}: another alma run (pid {holder}) is writing this study; "
                "wait for it to finish, or choose another --out"
            )
        os.ftruncate(fd, 0)
        os.pwrite(fd, str(os.getpid()).encode("ascii"), 0)
        yield path
    finally:
        os.close(fd)  # closing the descriptor releases the lock


def _try_lock(fd: int) -> bool:
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True
