# SPDX-License-Identifier: Apache-2.0
"""Progress of a batch of trials, on stderr."""
import sys
import time


class ProgressBar:
    """`[#####.....] done/total trials, elapsed, ETA` on stderr. Trials differ in cost (a 1 kHz world steps 100x
    more often than a 10 Hz one), so the ETA weighs each trial by an estimate of its cost given by the caller rather
    than counting trials. On a terminal the bar redraws in place; otherwise (CTest, a log file) it prints a line at
    every 10 % so logs stay short."""

    def __init__(self, total_weight, total_count, stream=sys.stderr, width=30):
        self.total_weight = max(total_weight, 1e-9)
        self.total_count = total_count
        self.stream = stream
        self.width = width
        self.done_weight = 0.0
        self.done_count = 0
        self.start = time.monotonic()
        self.tty = stream.isatty()
        self.last_decile = -1

    @staticmethod
    def _clock(seconds):
        seconds = int(round(seconds))
        return f"{seconds // 60:02d}:{seconds % 60:02d}"

    def advance(self, weight, note=""):
        """Counts one finished trial of cost `weight` and redraws; `note` is appended to the line."""
        self.done_weight += weight
        self.done_count += 1
        elapsed = time.monotonic() - self.start
        fraction = min(self.done_weight / self.total_weight, 1.0)
        eta = elapsed * (1.0 - fraction) / fraction if fraction > 0 else 0.0
        filled = int(round(self.width * fraction))
        line = (f"[{'#' * filled}{'.' * (self.width - filled)}] {self.done_count}/{self.total_count} trials, "
                f"{self._clock(elapsed)} elapsed, ETA {self._clock(eta)}{(' ' + note) if note else ''}")
        if self.tty:
            print("\r" + line + "\033[K", end="", file=self.stream, flush=True)
        else:
            decile = int(10 * self.done_count / max(self.total_count, 1))
            if decile != self.last_decile or self.done_count == self.total_count:
                self.last_decile = decile
                print(line, file=self.stream, flush=True)

    def close(self):
        """Ends the bar's line on a terminal."""
        if self.tty:
            print(file=self.stream, flush=True)
