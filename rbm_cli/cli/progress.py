"""Progress of a sweep, on stderr: a bar on a terminal, plain lines otherwise.

The rate and the ETA count only the cells run by this invocation, from the moment the
first one could start (after the compile and the resumed cells): click's bar counted
resumed cells as work done in no time and included the compile, so its ETA was 10x off.
Without a terminal (a log file, nohup, CI) a line is printed at most every
LINE_INTERVAL_S seconds, and at the end.
"""

from __future__ import annotations

import math
import sys
import time
from typing import TextIO

#: Seconds between two plain progress lines (no terminal).
LINE_INTERVAL_S = 10.0
#: Seconds between two redraws of the bar (terminal).
BAR_INTERVAL_S = 0.2
BAR_WIDTH = 30


def duration(seconds: float) -> str:
    """'45 s', '3 min 05 s', '2 h 04 min'."""
    if not math.isfinite(seconds):
        return "?"
    s = int(round(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


class Progress:
    """progress(done, total), as run_sweep calls it: first once before the first cell
    runs (done = the resumed cells), then as chunks finish."""

    def __init__(self, label: str, stream: TextIO | None = None, tty: bool | None = None):
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.tty = self.stream.isatty() if tty is None else tty
        self.start: float | None = None
        self.done0 = 0
        self.last_draw = -math.inf
        self.drawn = False
        self.done = 0
        self.total = 0

    def rate(self, now: float) -> float:
        """Cells a second run by this invocation (NaN before the first finished)."""
        run = self.done - self.done0
        elapsed = now - self.start if self.start is not None else 0.0
        return run / elapsed if run > 0 and elapsed > 0 else math.nan

    def text(self, now: float) -> str:
        rate = self.rate(now)
        left = self.total - self.done
        eta = left / rate if rate > 0 else math.nan
        pct = 100.0 * self.done / self.total if self.total else 100.0
        if not math.isfinite(rate):
            rate_text = "rate ?"
        else:
            rate_text = f"{rate:.0f} cells/s" if rate >= 100 else f"{rate:.3g} cells/s"
        resumed = f", {self.done0} resumed" if self.done0 else ""
        return (
            f"{self.label}: {self.done}/{self.total} cells ({pct:.0f} %{resumed}),"
            f" {rate_text}, ETA {duration(eta) if left else '0 s'}"
        )

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if self.start is None:
            self.start, self.done0 = now, done
        self.done, self.total = done, total
        final = done >= total
        if self.tty:
            if final or now - self.last_draw >= BAR_INTERVAL_S:
                filled = int(BAR_WIDTH * done / total) if total else BAR_WIDTH
                bar = "#" * filled + "-" * (BAR_WIDTH - filled)
                self.stream.write(f"\r[{bar}] {self.text(now)}\x1b[K")
                self.stream.flush()
                self.last_draw, self.drawn = now, True
        elif final or now - self.last_draw >= LINE_INTERVAL_S:
            if done > self.done0 or final or not self.drawn:
                self.stream.write(f"progress: {self.text(now)}\n")
                self.stream.flush()
                self.last_draw, self.drawn = now, True

    def close(self) -> None:
        """End the bar's line (a terminal), so what follows starts on its own line."""
        if self.tty and self.drawn:
            self.stream.write("\n")
            self.stream.flush()
            self.drawn = False
