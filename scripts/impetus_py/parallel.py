# SPDX-License-Identifier: Apache-2.0
"""Running many trials at once.

A trial keeps about one core busy whichever way it runs (in-process, or three daemons taking turns in lockstep), so
`jobs = nproc` trials fill the machine without oversubscribing it. Each task runs in a worker process: an in-process
trial holds the physics engine's process-wide state, which two trials must not share.
"""
import concurrent.futures


def run_parallel(tasks, jobs):
    """Runs `tasks`, an iterable of (key, function, args) with a module-level function and picklable arguments, on
    `jobs` worker processes and yields (key, result) in completion order. An exception raised by a task propagates
    out of the loop that consumes this generator (after the tasks already queued have finished, as the executor's exit
    waits for them); callers that want to carry on wrap their function to return the error instead."""
    with concurrent.futures.ProcessPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(function, *args): key for key, function, args in tasks}
        for future in concurrent.futures.as_completed(futures):
            yield futures[future], future.result()
