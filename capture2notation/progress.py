"""Progress on stderr: a live bar on a terminal, a sparse line in a log.

A tqdm bar redraws itself several times a second with carriage returns;
written to a file or a CI log that is thousands of lines.  When stderr is
not a terminal, :func:`progress` prints one plain line at most every
:data:`LINE_INTERVAL_S` seconds, and one when the work ends.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from typing import Any

__all__ = ["LINE_INTERVAL_S", "progress"]

#: Seconds between two progress lines when stderr is not a terminal: often
#: enough to show a long job is alive, rare enough to keep a log readable.
LINE_INTERVAL_S = 30.0


def progress(
    iterable: Iterable | None = None,
    *,
    total: int | None = None,
    desc: str = "",
    unit: str = "it",
    enabled: bool = True,
    leave: bool = True,
) -> Any:
    """A progress reporter with tqdm's ``update()``/``close()``/iteration interface.

    Parameters
    ----------
    iterable : iterable, optional
        Items to pass through while counting them.
    total : int, optional
        Expected count (default ``len(iterable)`` when it has one).
    desc, unit : str
        Label and unit of the count.
    enabled : bool
        False gives a silent reporter.
    leave : bool
        Keep the finished bar on screen (terminal only).
    """
    if total is None and iterable is not None and hasattr(iterable, "__len__"):
        total = len(iterable)  # type: ignore[arg-type]
    if not enabled:
        return _Lines(iterable, total, desc, unit, stream=None)
    if sys.stderr.isatty():
        from tqdm import tqdm

        return tqdm(iterable, total=total, desc=desc, unit=unit, leave=leave)
    return _Lines(iterable, total, desc, unit, stream=sys.stderr)


class _Lines:
    """Counts work and writes a line every :data:`LINE_INTERVAL_S` seconds and at the end."""

    def __init__(self, iterable, total, desc, unit, stream):
        self.iterable = iterable
        self.total = total
        self.desc = desc
        self.unit = unit
        self.stream = stream
        self.n = 0
        self.start = time.monotonic()
        self.last = self.start
        self.closed = False

    def update(self, n: int = 1) -> None:
        self.n += n
        now = time.monotonic()
        if self.stream is not None and now - self.last >= LINE_INTERVAL_S:
            self.last = now
            self._write(now)

    def _write(self, now: float) -> None:
        of = f"/{self.total}" if self.total else ""
        pct = f" ({100 * self.n / self.total:.0f} %)" if self.total else ""
        label = f"{self.desc}: " if self.desc else ""
        self.stream.write(f"{label}{self.n}{of} {self.unit}s{pct}, {now - self.start:.0f} s\n")
        self.stream.flush()

    def close(self) -> None:
        if not self.closed and self.stream is not None and self.n:
            self._write(time.monotonic())
        self.closed = True

    def __iter__(self) -> Iterator:
        try:
            for item in self.iterable if self.iterable is not None else ():
                yield item
                self.update()
        finally:
            self.close()

    def __enter__(self) -> _Lines:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
