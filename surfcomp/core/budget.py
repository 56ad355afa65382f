# SPDX-License-Identifier: LGPL-2.1-or-later
"""Memory bounds: the memory a command will need, estimated before the work, against a limit.

Every command that grows with its input (``simulate``'s grids and replicas, the points of
``inspect``/``compensate``, the lines of a G-code program) estimates its peak memory from
the sizes it knows before the work starts and refuses, with the estimate and the limit,
when that is more than ``--max-memory`` (default: the machine's memory,
:func:`machine_memory`). The per-item costs are peak resident sizes measured by
``bench/bench_memory.py`` with a margin; they are estimates, not guarantees, meant to
turn an out-of-memory kill an hour into the run into a message at its start.
"""

import os
import re

from ..errors import InputError

_UNITS = {"": 1, "b": 1, "k": 1024, "kb": 1024, "kib": 1024, "m": 1024 ** 2, "mb": 1024 ** 2,
          "mib": 1024 ** 2, "g": 1024 ** 3, "gb": 1024 ** 3, "gib": 1024 ** 3,
          "t": 1024 ** 4, "tb": 1024 ** 4, "tib": 1024 ** 4}
#: the smallest ``--max-memory`` accepted (Python, numpy and FreeCAD alone take about this)
MIN_LIMIT = 64 * 1024 ** 2
#: bytes of the process before the work (Python, numpy, scipy; FreeCAD adds ~150 MB)
BASE = 300 * 1024 ** 2


def parse_size(text, option="max_memory"):
    """``'4G'``, ``'512M'``, ``'1.5GB'``, ``'4000000000'`` -> bytes (binary units).

    Raises
    ------
    InputError
        Not a size, or below :data:`MIN_LIMIT`.
    """
    m = re.fullmatch(r"\s*([0-9]+(?:\.[0-9]*)?|\.[0-9]+)\s*([A-Za-z]*)\s*", str(text))
    unit = m and m.group(2).lower()
    if not m or unit not in _UNITS:
        raise InputError("%s %r: expected a size such as 4G, 512M or a number of bytes"
                         % (option, text), options=(option,))
    value = float(m.group(1)) * _UNITS[unit]
    if value < MIN_LIMIT:
        raise InputError("%s %r: expected at least %d M (the program alone needs about that)"
                         % (option, text, MIN_LIMIT // 1024 ** 2), options=(option,))
    return int(value)


def _cgroup_limit():
    """The cgroup (container) memory limit in bytes, or None."""
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            with open(path, encoding="ascii") as fh:
                text = fh.read().strip()
        except OSError:
            continue
        if text.isdigit() and int(text) < 1 << 60:
            return int(text)
    return None


def machine_memory():
    """The memory this process may use at most: the machine's physical memory, or the
    container's limit when lower (bytes). None when it cannot be found out."""
    total = None
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        pass
    limit = _cgroup_limit()
    if total is None or (limit is not None and limit < total):
        total = limit
    return total


def _gb(n):
    return "%.1f GB" % (n / 1024 ** 3) if n >= 1024 ** 3 / 10 else "%d MB" % (n // 1024 ** 2)


def check(needed, limit=None, what="this run", hint=""):
    """Refuse a run whose estimated peak memory ``needed`` (bytes) is above ``limit``
    (bytes; None: :func:`machine_memory`).

    Raises
    ------
    InputError
        With the estimate, the limit and where it comes from, and ``hint``.
    """
    source = "max_memory"
    if limit is None:
        limit, source = machine_memory(), "the machine's memory"
    if limit is None or needed <= limit:
        return needed
    raise InputError("%s needs about %s of memory, more than %s (%s)%s"
                     % (what, _gb(needed), source, _gb(limit), hint and "; " + hint),
                     options=("max_memory",))


# ----------------------------------------------------------------------------- estimates
#: ``simulate``: bytes per point of the evaluation grid (nodes and between) and per node
#: of the measurement grid (its compensations), and per replica and method (statistics).
#: Measured peaks (2026-12-02, example face, one replica, see docs/benchmarks.md): 100x100
#: 227 MB, 200x200 486 MB (313 MB with --between 1), 400x400 728 MB, 600x600 989 MB,
#: 800x800 1622 MB; these costs estimate 355, 520 (384), 1183, 2289 and 3836 MB
SIM_PER_EVAL_POINT = 1200
SIM_PER_GRID_POINT = 1000
SIM_PER_REPLICA_METHOD = 4000
#: ``inspect``/``compensate``: bytes per measured point (inspect measured 2026-12-01:
#: 561 MB peak for a million scattered points, docs/benchmarks.md bench_scale.py)
JOB_PER_POINT = 1000
JOB_PER_POINT_COMPENSATE = 6000
#: ``gcode``: bytes per line of the block being compensated (parsed words, the block's
#: arrays, its output; measured 2026-12-02 before the program was read in blocks: 252 MB
#: peak for 50 000 lines of random G1 moves up to 140 mm long), and per program line in
#: all (the program is compensated :data:`GCODE_BLOCK_LINES` lines at a time; issue 25
#: asks for at most 300 bytes a line)
GCODE_PER_BLOCK_LINE = 6000
GCODE_PER_LINE = 300
#: ``compensate --program``: bytes per piece of the block being planned (its moved points,
#: the displacement's arrays, its output lines; measured 2026-12-03: 1.4 and 2.9 GB peak
#: for 2.3 and 4.6 million pieces in one block)
PROGRAM_PER_PIECE = 700
#: :data:`surfcomp.io.gcode.stream.BLOCK_LINES` (core does not import io)
GCODE_BLOCK_LINES = 10_000


def simulate_bytes(eval_points, grid_points, replicas, methods):
    """Estimated peak bytes of ``simulate``."""
    return int(BASE + SIM_PER_EVAL_POINT * eval_points + SIM_PER_GRID_POINT * grid_points
               + SIM_PER_REPLICA_METHOD * replicas * max(1, methods))


def job_bytes(points, build=False):
    """Estimated peak bytes of ``inspect`` (``build`` False) or ``compensate``."""
    return int(BASE + (JOB_PER_POINT_COMPENSATE if build else JOB_PER_POINT) * points)


def check_job(points, build, limit=None):
    """:func:`check` of an ``inspect`` (``build`` False) or ``compensate`` run on ``points``
    measured points, named so in the message."""
    return check(job_bytes(points, build), limit,
                 "%s of %d points" % ("compensate" if build else "inspect", points))


def gcode_bytes(lines):
    """Estimated peak bytes of ``gcode`` on a program of ``lines`` lines."""
    return int(BASE + GCODE_PER_BLOCK_LINE * min(lines, GCODE_BLOCK_LINES)
               + GCODE_PER_LINE * lines)
