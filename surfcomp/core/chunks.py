# SPDX-License-Identifier: LGPL-2.1-or-later
"""Chunked array work on the machine's cores (no FreeCAD).

The evaluations of millions of points (B-spline derivatives, field values) run in
chunks that stay in cache; numpy releases the interpreter lock inside its kernels, so
the chunks of one call can run on several threads at once. ``SURFCOMP_THREADS`` sets
the number of threads (1: serial); the default is the number of cores, at most 4. A
chunk that itself maps chunks runs them serially (no nested waiting on the same pool).
"""

import os
import threading
from concurrent.futures import ThreadPoolExecutor, wait

_POOLS = {}          # threads -> executor (one per thread count, kept for the process)
_LOCK = threading.Lock()
_INSIDE = threading.local()


def threads():
    """Threads a chunked call uses (``SURFCOMP_THREADS``, else the cores, at most 4)."""
    try:
        env = int(os.environ.get("SURFCOMP_THREADS", ""))
    except ValueError:
        env = 0
    return env if env > 0 else max(1, min(4, os.cpu_count() or 1))


def _guarded(job):
    def run(sl):
        _INSIDE.active = True
        try:
            job(sl)
        finally:
            _INSIDE.active = False
    return run


def _submit(workers, run, slices):
    """Submit the slices to the pool of ``workers`` threads (made on first use)."""
    with _LOCK:
        if workers not in _POOLS:
            _POOLS[workers] = ThreadPoolExecutor(workers, thread_name_prefix="surfcomp-chunk")
        return [_POOLS[workers].submit(run, sl) for sl in slices]


def for_chunks(job, n, step, workers=None, done=None):
    """Call ``job(slice)`` for the slices of ``range(n)`` ``step`` long, on ``workers``
    threads (default :func:`threads`) when there are several slices. ``job`` writes its
    results into arrays it shares with the caller (each slice its own part).

    ``done(k, count)``, if given, is called in the caller's thread once slice ``k`` has
    finished, in slice order (progress); when it raises (a cancel), or the wait is
    interrupted, the slices not started are cancelled and the running ones waited for.
    Returns when every slice has finished; then the first failed slice's exception is
    raised."""
    slices = [slice(k, min(k + step, n)) for k in range(0, n, step)]
    workers = workers or threads()
    if len(slices) < 2 or workers < 2 or getattr(_INSIDE, "active", False):
        for k, sl in enumerate(slices):
            job(sl)
            if done is not None:
                done(k, len(slices))
        return
    futures = _submit(workers, _guarded(job), slices)
    try:
        for k, fut in enumerate(futures):
            if fut.exception() is None and done is not None:
                done(k, len(slices))
    except BaseException:
        for fut in futures:
            fut.cancel()
        wait(futures)
        raise
    for fut in futures:
        fut.result()
