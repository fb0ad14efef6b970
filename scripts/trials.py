"""Helpers shared by the experiment scripts (phase_experiment.py, speed_vs_error.py): run one trial through
scripts/run.sh, run many in parallel, and show progress.

Each trial is three real processes in lockstep (DESIGN.md §3); they take turns on semaphores, so one trial keeps
about one core busy and `jobs = nproc` trials fill the machine without oversubscribing it.
"""
import concurrent.futures
import json
import subprocess
import sys
import time
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent


def run_trial(out_dir, scene, trajectory, coupling, rate, phase, extra):
    """Runs one lockstep trial into out_dir and returns its summary.json; raises RuntimeError if it failed.
    `extra` are further run.sh arguments (e.g. ["--substeps", "5"])."""
    out_dir.mkdir(parents=True, exist_ok=True)
    command = ["bash", str(ROOT / "scripts/run.sh"), "--scene", str(scene), "--trajectory", trajectory,
               "--coupling", coupling, "--rate", str(rate), "--phase", str(phase), "--clock", "lockstep",
               "--out", str(out_dir), "--quiet"] + extra
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"trial failed ({' '.join(command)}):\n{result.stdout}{result.stderr}")
    summary = json.loads((out_dir / "summary.json").read_text())
    return summary


def run_parallel(tasks, jobs):
    """Runs `tasks`, an iterable of (key, function, args), on `jobs` threads (each trial is its own processes, so
    threads are enough) and yields (key, result) in completion order. An exception raised by a task propagates out
    of the loop that consumes this generator (after the tasks already queued have finished, as the executor's exit
    waits for them); callers that want to carry on wrap their function to return the error instead."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(function, *args): key for key, function, args in tasks}
        for future in concurrent.futures.as_completed(futures):
            yield futures[future], future.result()


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
        if self.tty:
            print(file=self.stream, flush=True)
