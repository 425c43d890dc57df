"""Progress of a run on the command line: a bar on a terminal, plain lines
(every 10 %, at least every 10 s) when the output is a file or a pipe."""

import sys
import time


class Progress:
    """``progress(t, t_end)`` callback: a bar on a terminal, plain lines otherwise."""

    def __init__(self, t_end, stream=None):
        self.stream = stream or sys.stdout
        self.tty = self.stream.isatty()
        self.t_end, self.start = t_end, time.perf_counter()
        self.shown, self.next_fraction = -float("inf"), 0.1  # the first call always shows

    def __call__(self, t, t_end):
        now = time.perf_counter()
        fraction = min(t / t_end, 1.0) if t_end > 0 else 1.0
        wall = now - self.start
        eta = wall * (1.0 - fraction) / fraction if fraction > 0.02 else float("nan")
        text = (f"t = {t:8.3f} / {t_end:g} s  {100 * fraction:3.0f}%  wall {_clock(wall)}  "
                f"ETA {_clock(eta)}")
        if self.tty:
            if now - self.shown >= 0.1 or fraction >= 1.0:
                bar = "#" * int(30 * fraction)
                self.stream.write(f"\r[{bar:<30}] {text}")
                self.stream.flush()
                self.shown = now
        elif fraction >= self.next_fraction - 1e-12 or now - self.shown >= 10.0:
            self.stream.write(text + "\n")
            self.stream.flush()
            self.shown = now
            while self.next_fraction <= fraction + 1e-12:
                self.next_fraction += 0.1

    def close(self):
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()


def _clock(seconds):
    if seconds != seconds or seconds == float("inf"):
        return "--:--"
    minutes, sec = divmod(int(round(seconds)), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{sec:02d}" if hours else f"{minutes:02d}:{sec:02d}"
