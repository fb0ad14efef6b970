# SPDX-License-Identifier: Apache-2.0
"""Progress of a batch of trials on stderr: a tqdm bar with the elapsed time and an ETA, shown on a terminal and
silent otherwise (CTest, a log file) or when the script was given --quiet."""
import sys

from tqdm import tqdm


class ProgressBar:
    """`label: 40%|####      | 12/30 trials [00:14<00:21]`. Trials differ in cost (a 1 kHz world steps 100x more often
    than a 10 Hz one), so the bar and its ETA advance by an estimate of each trial's cost given by the caller rather
    than by a count of trials; the count is shown beside it."""

    def __init__(self, total_weight, total_count, label="trials", quiet=False, stream=sys.stderr):
        self.total_count = total_count
        self.done_count = 0
        self.bar = tqdm(total=max(float(total_weight), 1e-9), file=stream, desc=label, leave=True,
                        disable=quiet or not stream.isatty(),
                        bar_format="{desc}: {percentage:3.0f}%|{bar:30}| {postfix} [{elapsed}<{remaining}]")
        self.bar.set_postfix_str(f"0/{total_count}")

    def advance(self, weight=1.0, note=""):
        """Counts one finished trial of cost `weight`; `note` (e.g. a failure) is shown after the count."""
        self.done_count += 1
        self.bar.set_postfix_str(f"{self.done_count}/{self.total_count}{(' ' + note) if note else ''}", refresh=False)
        self.bar.update(weight)

    def close(self):
        self.bar.close()


def track(results, keys, label="trials", quiet=False, weight=None):
    """Yields the (key, result) pairs of `results` (run_parallel's generator over the tasks `keys`) while a
    ProgressBar counts them; `weight(key)` is a trial's relative cost (default: all equal)."""
    weight = weight or (lambda key: 1.0)
    progress = ProgressBar(sum(weight(key) for key in keys), len(keys), label, quiet)
    try:
        for key, result in results:
            progress.advance(weight(key))
            yield key, result
    finally:
        progress.close()
