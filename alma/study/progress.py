"""The study's progress line on stderr: done/total, failures, elapsed, time left."""

from __future__ import annotations

import sys
import time
from typing import Any


class _Progress:
    """Plain-text progress bar on stderr: done/total, failures, elapsed, time left."""

    def __init__(self, total: int, resumed: int, enabled: bool, stream: Any = None, work: float = 0.0) -> None:
        self.total = total
        self.work = work  # estimated work of the panels to solve (ETA weights)
        self.work_done = 0.0
        self.resumed = resumed
        self.done = resumed
        self.failed = 0
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.start = time.monotonic()
        self._last = 0.0
        self._last_len = 0
        self._shown: tuple[int, int] | None = None

    def update(self, failed: bool, work: float = 0.0) -> None:
        self.work_done += work
        self.done += 1
        self.failed += int(failed)
        self.show()

    def _line(self) -> str:
        elapsed = time.monotonic() - self.start
        new = self.done - self.resumed
        left = self.total - self.done
        if new == 0:
            eta = "--"
        elif self.work > 0 and self.work_done > 0:
            eta = _hms(elapsed / self.work_done * max(0.0, self.work - self.work_done))
        else:
            eta = _hms(elapsed / new * left)
        width = 24
        filled = int(width * self.done / self.total) if self.total else width
        resumed = f" ({self.resumed} resumed)" if self.resumed else ""
        return (
            f"doe [{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total}"
            f"{resumed}, {self.failed} failed, elapsed {_hms(elapsed)}, left {eta}"
        )

    def show(self, force: bool = False) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        final = self.done >= self.total
        if not (force or final or now - self._last >= (0.2 if self.tty else 5.0)):
            return
        if final and self._shown == (self.done, self.failed):
            return
        self._shown = (self.done, self.failed)
        self._last = now
        line = self._line()
        if self.tty:
            pad = " " * max(0, self._last_len - len(line))
            self.stream.write("\r" + line + pad)
            self._last_len = len(line)
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def close(self, note: str = "") -> None:
        if not self.enabled:
            return
        self.show(force=True)
        if self.tty:
            self.stream.write("\n")
        if note:
            self.stream.write(note + "\n")
        self.stream.flush()


def _hms(seconds: float) -> str:
    s = int(round(seconds))
    h, rem = divmod(s, 3600)
    m, s = divmod(rem, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"
