"""The batch's progress on stderr: done, failed, remaining and the time left.

A tqdm bar when stderr is a terminal; otherwise (a log file, CI) one plain line per finished
task, so a log says which task ended how. Nothing at all when quiet.
"""
from __future__ import annotations

import sys
import time

__all__ = ["BatchProgress"]


def _clock(seconds):
    seconds = int(round(seconds))
    h, rest = divmod(seconds, 3600)
    return (f"{h}:" if h else "") + f"{rest // 60:02d}:{rest % 60:02d}"


class BatchProgress:
    """Counts finished tasks and shows them.

    Parameters
    ----------
    total : int
        Tasks to run (skipped ones not counted).
    quiet : bool
        Show nothing.
    stream : file, optional
        stderr by default.
    """

    def __init__(self, total, quiet=False, stream=None):
        self.total, self.done, self.failed = total, 0, 0
        self.stream = stream or sys.stderr
        self.quiet = quiet
        self.t0 = time.perf_counter()
        self.bar = None
        if not quiet and total and self.stream.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, unit="task", desc="batch", file=self.stream,
                            dynamic_ncols=True)

    @property
    def remaining(self):
        return self.total - self.done - self.failed

    def eta(self):
        """Seconds left at the rate so far (None before the first task ends)."""
        finished = self.done + self.failed
        if not finished:
            return None
        return (time.perf_counter() - self.t0) / finished * self.remaining

    def update(self, entry):
        """One task ended with ``entry`` (its manifest entry)."""
        if entry["status"] == "ok":
            self.done += 1
        else:
            self.failed += 1
        if self.quiet:
            return
        counts = f"done {self.done}, failed {self.failed}, remaining {self.remaining}"
        if self.bar is not None:
            self.bar.set_postfix_str(counts, refresh=False)
            self.bar.update(1)
            return
        what = entry["status"] + (f" ({entry['error']})" if entry.get("error") else "")
        # a lost task (its worker died) has no time of its own: None
        took = entry.get("seconds")
        took = f"{took:.1f} s" if isinstance(took, (int, float)) else "no time"
        print(f"[{self.done + self.failed}/{self.total}] {entry['task']}: {what}, "
              f"{took}; {counts}, ETA {_clock(self.eta())}", file=self.stream, flush=True)

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None
