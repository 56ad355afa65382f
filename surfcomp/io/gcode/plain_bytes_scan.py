# SPDX-License-Identifier: LGPL-2.1-or-later
"""The plain lines of a block and their numbers, found over the block's bytes (no FreeCAD).

:func:`surfcomp.io.gcode.plain_scan.scan_block` of an ASCII block. A line is plain exactly
when :data:`surfcomp.io.gcode.plain_scan._LOOSE` takes its groups and its numbers are
numbers (:mod:`.plain_scan`); that pattern is read here as rules over the bytes, all of
them array operations over the whole block:

* every byte is a digit, ``.``, ``+``, ``-``, a blank, a tab or one of the letters ``G``,
  ``X``, ``Y``, ``Z``, ``F``;
* a word is a letter directly followed by a maximal run of ``[-+.0-9]``; every letter
  starts a word and every run belongs to one;
* the words come in the order G, X, Y, Z, F, each at most once; between two words (and
  before the first) only blanks, at most as many as the pattern's optional blanks between
  them (the letters' distance in that order; before the first word its distance from G);
  tabs only after the last word;
* the G word's number is ``0``, ``1``, ``00`` or ``01``; every other number has at least
  one digit, at most one dot and a sign only in front (the grammar ``float`` reads over
  those characters), and at least one of X, Y and Z is given.

A number of at most 15 digits is read as its digits as an integer divided by the power of
ten of its decimals: both exact in a double, so the one rounding of the division is the
rounding ``float`` makes of the decimal number, bit for bit; longer numbers are read by
``float`` (``tests/pure/test_gcode_plain_scan.py`` compares both with the pattern and
``float`` on random lines).
"""

import re

import numpy as np

#: byte classes
_OTHER, _DIGIT, _DOT, _SIGN, _BLANK, _TAB, _NEWLINE, _G = 0, 1, 2, 3, 4, 5, 6, 7
_CLASS = np.zeros(256, dtype=np.int8)
_CLASS[np.frombuffer(b"0123456789", dtype=np.uint8)] = _DIGIT
_CLASS[ord(".")], _CLASS[ord("+")], _CLASS[ord("-")] = _DOT, _SIGN, _SIGN
_CLASS[ord(" ")], _CLASS[ord("\t")], _CLASS[ord("\n")] = _BLANK, _TAB, _NEWLINE
for _k, _c in enumerate("GXYZF"):
    _CLASS[ord(_c)] = _G + _k
#: numbers read from their digits (longer ones by ``float``)
_FAST_DIGITS = 15
_POW10 = 10.0 ** np.arange(_FAST_DIGITS + 1)
#: runs longer than this are told character by character in Python
_LONG = 24
#: a number of the plain line's pattern (:data:`surfcomp.io.gcode.plain.PLAIN`)
_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)")


def scan_bytes(buf, n, out):
    """Fill the :class:`surfcomp.io.gcode.plain_scan.BlockScan` ``out`` for the block
    ``buf`` ((m,) uint8: its ``n`` lines, each ending in ``"\\n"``); return it."""
    cls = np.take(_CLASS, buf)
    newline = np.flatnonzero(cls == _NEWLINE)
    line_start = np.empty(n, dtype=np.int64)
    line_start[:1] = 0
    line_start[1:] = newline[:-1] + 1
    bad = np.zeros(n + 1, dtype=bool)           # the last entry takes what is ignored
    bad[np.searchsorted(newline, np.flatnonzero(cls == _OTHER))] = True
    num = ((cls >= _DIGIT) & (cls <= _SIGN)).view(np.int8)
    edge = np.diff(num, prepend=np.int8(0))
    start = np.flatnonzero(edge == 1)
    stop = np.flatnonzero(edge == -1)           # every run ends before its line's newline
    letter = np.flatnonzero(cls >= _G)
    # every letter starts a word, every run belongs to one
    before = cls[start - 1]         # a run at the start: the last byte, a newline
    orphan = start[before < _G]
    bad[np.searchsorted(newline, orphan)] = True
    lone = letter[num[letter + 1] == 0]
    bad[np.searchsorted(newline, lone)] = True
    word = before >= _G
    start, stop = start[word], stop[word]
    which = (before[word] - _G).astype(np.int64)   # 0 G, 1 X, 2 Y, 3 Z, 4 F
    line = np.searchsorted(newline, start)
    # order and blanks: a word's gap to the word before it in the line (or the line's start)
    first = np.ones(line.size, dtype=bool)
    first[1:] = line[1:] != line[:-1]
    prev_end = np.empty_like(start)
    prev_end[1:] = stop[:-1]
    prev_end[first] = line_start[line[first]]
    prev_which = np.zeros_like(which)
    prev_which[1:] = which[:-1]
    prev_which[first] = 0
    gap = start - 1 - prev_end
    wrong = (gap > which - prev_which) | (~first & (which <= prev_which))
    bad[line[wrong]] = True
    # tabs only after the last word
    tab = np.flatnonzero(cls == _TAB)
    if tab.size:
        last_end = np.full(n, -1, dtype=np.int64)
        last = np.ones(line.size, dtype=bool)
        last[:-1] = line[1:] != line[:-1]
        last_end[line[last]] = stop[last]
        tab_line = np.searchsorted(newline, tab)
        bad[tab_line[tab < last_end[tab_line]]] = True
    # the numbers
    size = stop - start
    mant, digits, dot, valid = _digits(buf, start, size)
    g = which == 0
    motion_ok = (size <= 2) & (digits == size) & (mant <= 1) & \
        ((size == 1) | (buf[start] == ord("0")))
    bad[line[np.where(g, ~motion_ok, ~valid)]] = True
    decimals = np.where(dot >= 0, size - dot - 1, 0)
    value = mant / _POW10[np.minimum(decimals, _FAST_DIGITS)]
    value[buf[start] == ord("-")] *= -1.0
    slow = np.flatnonzero(valid & (digits > _FAST_DIGITS))
    if slow.size:
        text = buf.tobytes()
        value[slow] = [float(text[a:b]) for a, b in zip(start[slow].tolist(),
                                                        stop[slow].tolist())]
    bad = bad[:n]
    out.motion = np.full(n, -1, dtype=np.int64)
    out.motion[line[g]] = buf[stop[g] - 1] - ord("0")
    out.value = np.full((n, 3), np.nan)
    out.size = np.zeros((n, 3), dtype=np.int64)
    out.decimals = np.zeros((n, 3), dtype=np.int64)
    axis = (which >= 1) & (which <= 3)
    at = 3 * line[axis] + which[axis] - 1           # flat index in the (n, 3) arrays
    out.value.ravel()[at] = value[axis]
    out.size.ravel()[at] = size[axis]
    out.decimals.ravel()[at] = decimals[axis]
    out.present = out.size > 0
    out.feed_ok = np.ones(n, dtype=bool)
    feed = which == 4
    out.feed_ok[line[feed]] = np.isfinite(value[feed])
    out.plain = ~bad & out.present.any(axis=1)
    return out


def _digits(buf, start, size):
    """Per run of ``[-+.0-9]`` (``start``, ``size``): its digits as an integer (float,
    exact up to :data:`_FAST_DIGITS` digits), how many, the index of its dot in the run
    (-1: none), and whether it is a number (a digit, at most one dot, a sign only first)."""
    width = min(int(size.max(initial=0)), _LONG)
    # the runs' characters, one row per place in the run (a place after its end: none)
    inside = np.arange(width)[:, None] < size[None, :]
    chars = buf[np.minimum(start[None, :] + np.arange(width)[:, None], buf.size - 1)]
    kind = np.where(inside, np.take(_CLASS, chars), _OTHER)
    is_digit = kind == _DIGIT
    is_dot = kind == _DOT
    digits = np.count_nonzero(is_digit, axis=0)
    dots = np.count_nonzero(is_dot, axis=0)
    place = np.arange(width, dtype=np.float64)[:, None]
    dot = np.where(dots > 0, np.where(is_dot, place, 0.0).sum(axis=0), -1).astype(np.int64)
    valid = (digits > 0) & (dots <= 1) & (np.count_nonzero(kind[1:] == _SIGN, axis=0) == 0)
    # Horner over the places: a digit multiplies by ten and adds itself, the rest nothing
    times = np.where(is_digit, 10.0, 1.0)
    add = np.where(is_digit, chars - np.float64(ord("0")), 0.0)
    mant = np.zeros(start.size)
    with np.errstate(over="ignore"):        # the digits of a long number: read by float
        for k in range(width):
            mant *= times[k]
            mant += add[k]
    long = np.flatnonzero(size > _LONG)
    if long.size:           # character by character would take a pass per character
        text = [buf[a:a + m].tobytes().decode("ascii") for a, m in zip(start[long].tolist(),
                                                                     size[long].tolist())]
        valid[long] = [_NUMBER.fullmatch(t) is not None for t in text]
        dot[long] = [t.find(".") for t in text]
        digits[long] = _FAST_DIGITS + 1         # read by float
    return mant, digits, dot, valid
