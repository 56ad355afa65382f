# SPDX-License-Identifier: LGPL-2.1-or-later
"""Which lines of a block are plain G0/G1 lines, and their numbers (no FreeCAD).

:mod:`.plain` reads runs of plain lines as arrays. Matching every line with the full
pattern :data:`surfcomp.io.gcode.plain.PLAIN` and taking its ten groups cost most of the
reading of a large program. Here one pattern (:data:`_LOOSE`) with groups for the motion
code and the numbers only, and every number any run of ``[-+.0-9]``, tells the lines of
that shape; a line is plain exactly when it has that shape, every number is one
``float`` reads (over those characters: at least one digit, at most one dot, a sign only
in front, the grammar of :data:`surfcomp.io.gcode.plain.PLAIN`'s numbers) and it names an
axis. In :data:`PLAIN` nothing after a number can continue it, so its numbers are these
same maximal runs (``tests/pure/test_gcode_plain_scan.py`` compares both on random
lines). An ASCII block (every block a program of those characters gives) is scanned over
its bytes instead (:mod:`.plain_bytes_scan`: the same rules as array operations, about
half the time); the pattern reads the others. The blanks a writer needs to rebuild a line
are taken from :data:`PLAIN` for that line alone (:func:`surfcomp.io.gcode.plain.plain_groups`).
"""

import re
from itertools import repeat

import numpy as np

from .plain_bytes_scan import scan_bytes

#: a plain line's shape, numbers taken loosely (see the module's text); groups: the motion
#: code, the X, Y, Z and F numbers, ``"\n"``; ``""`` for a group that took no part, and
#: for every group of a line of another shape
_LOOSE = re.compile(r"(?:(?:G(0?[01]))? ?(?:X([-+.\d]+))? ?(?:Y([-+.\d]+))? ?"
                    r"(?:Z([-+.\d]+))? ?(?:F([-+.\d]+))?[ \t]*(\n)|[^\n]*\n)")
#: a number of :data:`surfcomp.io.gcode.plain.PLAIN`
_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)")
#: the motion code of a G word (-1: none)
_MOTION = {"": -1, "0": 0, "1": 1, "00": 0, "01": 1}


class BlockScan:
    """The plain lines of a block of n lines and their words (arrays over the block).

    ``plain`` (n,) bool; ``motion`` (n,) int: the G word's motion code (0 or 1; -1
    without one); for the axes X, Y, Z: ``present``, ``value`` (mm, NaN where absent),
    ``size`` (the number's length, 0 where absent), ``decimals`` (digits after its dot),
    all (n, 3); ``feed_ok`` (n,) bool: the F word, if any, is finite. Only the entries of
    plain lines are meaningful.
    """

    __slots__ = ("plain", "motion", "present", "value", "size", "decimals", "feed_ok")


def scan_block(contents):
    """The :class:`BlockScan` of the line contents ``contents`` (list of str, no line
    endings)."""
    text = "\n".join(contents) + "\n"
    if text.isascii():
        return scan_bytes(np.frombuffer(text.encode("ascii"), dtype=np.uint8),
                          len(contents), BlockScan())
    return _scan_pattern(text, len(contents))     # other digits than 0-9 may match \d


def _scan_pattern(text, n):
    """:func:`scan_block` of the block's ``text`` (its ``n`` lines each ending in ``"\n"``)
    with :data:`_LOOSE`."""
    found = _LOOSE.findall(text)
    cols = tuple(zip(*found)) if found else ((),) * 6
    out = BlockScan()
    ok = np.array(cols[5]) == "\n"
    out.motion = np.fromiter(map(_MOTION.__getitem__, cols[0]), dtype=np.int64, count=n)
    out.value = np.empty((n, 3))
    out.size = np.zeros((n, 3), dtype=np.int64)
    out.decimals = np.zeros((n, 3), dtype=np.int64)
    for a in range(3):
        col = cols[a + 1]
        out.value[:, a], good = _values(col)
        ok &= good
        out.size[:, a] = size = np.fromiter(map(len, col), dtype=np.int64, count=n)
        dot = np.fromiter(map(str.find, col, repeat(".")), dtype=np.int64, count=n)
        out.decimals[:, a] = np.where(dot >= 0, size - dot - 1, 0)
    out.present = out.size > 0
    feed, good = _values(cols[4])
    ok &= good
    out.feed_ok = ~np.isinf(feed)
    out.plain = ok & out.present.any(axis=1)
    return out


def _values(col):
    """``float`` of each number of ``col`` (NaN for ``""``) and whether it is a number of
    :data:`surfcomp.io.gcode.plain.PLAIN` (or ``""``)."""
    try:
        return np.array(list(map(float, [t or "nan" for t in col]))), True
    except ValueError:          # a run of those characters that is no number
        good = np.array([not t or _NUMBER.fullmatch(t) is not None for t in col])
        return np.array([float(t) if g and t else np.nan for t, g in zip(col, good)]), good
