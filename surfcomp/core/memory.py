# SPDX-License-Identifier: LGPL-2.1-or-later
"""Giving freed memory back to the system (no FreeCAD).

A dense job frees gigabytes of temporaries, but glibc's allocator keeps much of it for
reuse once its mmap threshold has grown past the sizes of the arrays freed: the process
then holds it through the CAD export, which needs another gigabyte. On a 1000 x 1000 grid
turned across the parameter lines 600 MB of the 1 GB held after the face build is free
memory that ``malloc_trim`` returns (peak 2.15 GB -> 1.86 GB). Elsewhere (Windows, macOS,
other C libraries) :func:`return_free_memory` does nothing.
"""

import contextlib
import ctypes
import gc
import sys

_TRIM = []      # [malloc_trim] or [None], looked up once
_ONE_COMMAND = []   # [True] once :func:`one_command_process` was called


def _trim():
    if not _TRIM:
        fn = None
        if sys.platform.startswith("linux"):
            try:    # the process's own symbols (the C library is loaded): no ldconfig run
                fn = getattr(ctypes.CDLL(None), "malloc_trim", None)
            except OSError:
                fn = None
        _TRIM.append(fn)
    return _TRIM[0]


def return_free_memory():
    """Return the allocator's free memory to the system where the C library can (glibc's
    ``malloc_trim``); True when it did so."""
    fn = _trim()
    if fn is None:
        return False
    fn(0)
    return True


@contextlib.contextmanager
def collector_paused():
    """The cycle collector off for the block (and on again after it, if it was on), where
    hundreds of thousands of new containers are made and none of them is garbage: importing
    numpy, scipy, FreeCAD and the numerics at a command's start, or a pole net of a million
    poles as nested lists or Vectors. Each collection they would trigger walks every older
    object of the process again."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if _ONE_COMMAND:
            gc.freeze()
        if was:
            gc.enable()


def one_command_process():
    """Mark this process as one that runs a single command and then ends (``python3 -m
    surfcomp``). From then on :func:`collector_paused` also freezes (``gc.freeze``) every
    object alive when it resumes the collector: the imported modules' objects, which live as
    long as the process anyway, so that the collections of the command's own work (reading
    a program's lines makes tens of thousands of containers) no longer walk them again.
    Frozen objects are still freed when their last reference goes; only a reference cycle
    among them would never be: so not in a process that runs on (FreeCAD, a test session)."""
    if not _ONE_COMMAND:
        _ONE_COMMAND.append(True)
