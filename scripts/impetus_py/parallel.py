# SPDX-License-Identifier: Apache-2.0
"""Running many trials at once.

Each trial is three real processes in lockstep (DESIGN.md §3); they take turns on semaphores, so one trial keeps
about one core busy and `jobs = nproc` trials fill the machine without oversubscribing it.
"""
import concurrent.futures


def run_parallel(tasks, jobs):
    """Runs `tasks`, an iterable of (key, function, args), on `jobs` threads (each trial is its own processes, so
    threads are enough) and yields (key, result) in completion order. An exception raised by a task propagates out
    of the loop that consumes this generator (after the tasks already queued have finished, as the executor's exit
    waits for them); callers that want to carry on wrap their function to return the error instead."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(function, *args): key for key, function, args in tasks}
        for future in concurrent.futures.as_completed(futures):
            yield futures[future], future.result()
