"""rodmol's one progress display (tqdm), for ``simulate(..., progress=True)``,
``rodmol run`` and ``rodmol render``.

A run goes through stages (preparing the compiled kernels, the initial
equilibrium) that are announced with their durations and are not counted as
integration; the bar then follows the simulated time, so its rate and ETA
come from integration alone. On a terminal the bar redraws in place; written
to a file or a pipe it becomes plain lines, every tenth of the work and at
least every ``LINE_INTERVAL`` seconds, so logs stay readable.
"""

import sys
import time
from contextlib import contextmanager

from tqdm import tqdm

#: Longest silence [s] between plain progress lines (files, pipes).
LINE_INTERVAL = 10.0
_BAR = "{desc}: {percentage:3.0f}%|{bar}| {n:.3f}/{total:.3g} {unit} [{elapsed}<{remaining}]"
_LINE = "{desc}: {percentage:3.0f}%  {n:.3f} of {total:.3g} {unit}, {elapsed} elapsed, ETA {remaining}"


class Progress:
    """``progress(t, t_end)`` callback of a run, with announced stages.

    ``label`` starts every line; ``stream`` defaults to standard error (so
    that a program's standard output stays its own).
    """

    def __init__(self, label="rodmol", stream=None):
        self.label, self.stream = label, stream or sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.bar = None

    @contextmanager
    def stage(self, text):
        """Announce a stage; its duration is printed when it ends."""
        self._line(f"{self.label}: {text} ...", end="" if self.tty else "\n")
        start = time.perf_counter()
        try:
            yield
        finally:
            took = f"{time.perf_counter() - start:.2f} s"
            self._line(f" {took}" if self.tty else f"{self.label}: {text}: {took}")

    def __call__(self, t, t_end):
        if self.bar is None:  # the first call: the integration starts now
            self.bar = _Bar(self, t, t_end, "integrating", "s simulated")
        self.bar.update(t - self.bar.start)

    def frames(self, iterable, total, what):
        """Iterate over ``iterable`` (``total`` items), showing the count of ``what``."""
        bar = _Bar(self, 0, total, what, "frames", integer=True)
        for k, item in enumerate(iterable, 1):
            yield item
            bar.update(k)
        bar.close()

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def _line(self, text, end="\n"):
        self.stream.write(text + end)
        self.stream.flush()


class _Bar:
    """A tqdm bar over [start, end]; plain lines when the stream is not a terminal."""

    def __init__(self, owner, start, end, desc, unit, integer=False):
        self.owner, self.start, self.total = owner, start, max(end - start, 0)
        fmt = _BAR if owner.tty else _LINE
        if integer:
            fmt = fmt.replace("{n:.3f}", "{n:.0f}").replace("{total:.3g}", "{total:.0f}")
        self.format = fmt
        self.desc, self.unit = f"{owner.label}: {desc}", unit
        self.created = time.perf_counter()
        self.shown, self.next_fraction = -float("inf"), 0.0
        self.tqdm = (tqdm(total=self.total, desc=self.desc, unit=unit, bar_format=fmt, file=owner.stream,
                          mininterval=0.1, leave=True, dynamic_ncols=True) if owner.tty else None)
        self.n = 0

    def update(self, n):
        n = min(max(n, 0), self.total)
        if self.tqdm is not None:
            self.tqdm.update(n - self.tqdm.n)
            return
        self.n = n
        fraction = n / self.total if self.total else 1.0
        now = time.perf_counter()
        if fraction >= self.next_fraction - 1e-12 or now - self.shown >= LINE_INTERVAL:
            self.owner._line(self._text(now))
            self.shown = now
            while self.next_fraction <= fraction + 1e-12:
                self.next_fraction += 0.1

    def _text(self, now):
        return tqdm.format_meter(self.n, self.total, now - self.created, prefix=self.desc,
                                 unit=self.unit, bar_format=self.format)

    def close(self):
        if self.tqdm is not None:
            self.tqdm.close()
        elif self.n < self.total:  # stopped early: say where
            self.owner._line(self._text(time.perf_counter()))
