# SPDX-License-Identifier: LGPL-2.1-or-later
"""What a fork of this process needs, for the two places that fork one (the CAD reader,
:mod:`surfcomp.app.cadfork`, and the program's planner,
:mod:`surfcomp.io.gcode.offset_stream`): one thread to copy, no GUI, and nothing buffered
that the child would write a second time."""

import os
import sys


def threads():
    """The number of threads of this process (Linux), or None when it cannot be told."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return None


def may_fork():
    """Whether a fork may do work beside this process: ``os.fork`` exists, the FreeCAD GUI
    is not loaded, and the process has one thread (a fork copies only the calling thread: a
    lock another one held would never be released in the child)."""
    return hasattr(os, "fork") and "FreeCADGui" not in sys.modules and threads() == 1


def flush_streams():
    """Flush standard output and error before a fork, so that nothing buffered is written
    twice (a caller's replaced stream may not flush: left alone)."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, OSError, ValueError):
            pass
