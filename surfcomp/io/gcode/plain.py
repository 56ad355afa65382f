# SPDX-License-Identifier: LGPL-2.1-or-later
"""Runs of plain G0/G1 lines read as arrays (no FreeCAD).

Most lines of a finishing program are plain moves: ``G1 X.. Y.. Z.. F..``, nothing else.
Reading them one :class:`surfcomp.io.gcode.lexer.Word` and one
:class:`surfcomp.io.gcode.interpreter.LineInfo` at a time costs tens of microseconds a
line; here a run of such lines is found by one scan of the block (:mod:`.plain_scan`) and
interpreted as arrays, and :mod:`.plain_write` writes it back as arrays. It is part of the
one reader and writer, not a second one: a run is taken only where the line-by-line
interpreter would do exactly the same (absolute mm positions, every axis known, a G0/G1
motion, nothing to warn about), anything else goes through the line-by-line path, and a
line of a run the writer cannot write as arrays gets its ``LineInfo`` built
(:func:`line_info`) and goes through the line-by-line writer. The output is the same, byte
for byte (``tests/pure/test_gcode_plain.py`` compares both paths).

A plain line: an optional ``G0``/``G1`` (``G00``/``G01``), then ``X``, ``Y``, ``Z`` and
``F`` words in this order (each optional, at least one axis), upper case, a letter
directly before its number, nothing or one blank between words, blanks at the end. Which
lines of a block are plain, and their numbers, is found in array operations
(:mod:`.plain_scan`).
"""

import re
from operator import itemgetter

import numpy as np

from .interpreter import MAX_POSITION, LineInfo
from .lexer import Word, tokenize
from .plain_scan import scan_block

_NUM = r"([+-]?(?:\d+(?:\.\d*)?|\.\d+))"
#: groups: 1 motion code, 3 X, 5 Y, 7 Z, 9 F, the others blanks (the line is their
#: concatenation with the letters)
PLAIN = re.compile(r"(?:G(0?[01]))?( ?)(?:X%s)?( ?)(?:Y%s)?( ?)(?:Z%s)?( ?)(?:F%s)?([ \t]*)"
                   % ((_NUM,) * 4))
#: group of each axis number
AXIS_GROUPS = (3, 5, 7)
#: shortest run read as arrays (shorter ones cost more to set up than they save)
MIN_RUN = 8
#: the switch tests use to compare both paths (False: every line one at a time)
ENABLED = True


class PlainLine:
    """The entry of :attr:`surfcomp.io.gcode.Program.lines` of a line read in a run
    (its :class:`LineInfo` is built when a writer needs it, :func:`line_info`)."""

    __slots__ = ()


PLAIN_LINE = PlainLine()


class PlainRun:
    """Lines ``start`` to ``stop`` (exclusive, indices in the block) read as arrays.

    ``g_word`` (n,) bool: the line has a G word; ``first_move``: the block's index of the
    first line's move (line ``k`` of the run has move ``first_move + k``); ``motion``
    (n,): 0 or 1 per line; ``present`` (n, 3) bool, ``value`` (n, 3) (mm), ``decimals``
    (n, 3) int, ``size`` (n, 3) int (the number's length): the axis words.
    """

    __slots__ = ("start", "stop", "g_word", "first_move", "motion", "present", "value",
                 "decimals", "size")

    def __init__(self, start, stop, g_word, first_move, motion, present, value, decimals,
                 size):
        self.start, self.stop, self.g_word = start, stop, g_word
        self.first_move, self.motion, self.present, self.value = (first_move, motion,
                                                                   present, value)
        self.decimals, self.size = decimals, size


def _candidates(lines):
    """``(start, stop, scan)`` of the runs of at least :data:`MIN_RUN` plain lines, with
    the block's :class:`surfcomp.io.gcode.plain_scan.BlockScan` (``scan``, the same for
    every run)."""
    if not lines:
        return []
    scan = scan_block(list(map(itemgetter(0), lines)))
    flag = np.zeros(len(lines) + 2, dtype=np.int8)
    flag[1:-1] = scan.plain
    edge = np.flatnonzero(np.diff(flag))
    return [(s, e, scan) for s, e in zip(edge[0::2].tolist(), edge[1::2].tolist())
            if e - s >= MIN_RUN]


def plain_groups(content):
    """The ten :data:`PLAIN` groups of a plain line's ``content`` (``""`` for a group that
    took no part)."""
    return tuple(g or "" for g in PLAIN.fullmatch(content).groups())


def read_block(interp, lines, base, source):
    """Interpret a block of ``(content, ending)`` lines (the first being line index
    ``base``), runs of plain lines as arrays; their entries of ``Program.lines`` and the
    :class:`PlainRun` list.

    Every other line is tokenized first, as :func:`surfcomp.io.gcode.lexer.tokenize` of
    the whole block would be (so the first lexical error of the block is raised first),
    then the lines are interpreted in order."""
    runs = _candidates(lines) if ENABLED else []
    toks = [None] * len(lines)
    pos = 0
    for s, e in [(s, e) for s, e, _cols in runs] + [(len(lines), len(lines))]:
        toks[pos:s] = [tokenize(c, source, base + k + 1)
                       for k, (c, _e) in enumerate(lines[pos:s], pos)]
        pos = e
    infos = []
    done = []
    pos = 0
    for s, e, scan in runs:
        infos.extend(interp.lines(toks[pos:s], base + pos))
        pos = s
        while pos < e:
            run = _read_run(interp, scan, base, pos, e)
            if isinstance(run, PlainRun):
                done.append(run)
                infos.extend([PLAIN_LINE] * (e - pos))
                pos = e
                break
            # the interpreter's state does not allow a run here: one line (or the rest)
            # line by line
            stop = pos + 1 if run == "line" else e
            infos.extend(interp.lines([tokenize(c, source, base + k + 1) for k, (c, _e)
                                       in enumerate(lines[pos:stop], pos)], base + pos))
            pos = stop
    infos.extend(interp.lines(toks[pos:], base + pos))
    return infos, done


def _read_run(interp, scan, base, start, stop):
    """The :class:`PlainRun` of lines ``start`` to ``stop`` of the block (their words in
    ``scan``, :class:`surfcomp.io.gcode.plain_scan.BlockScan`), its moves added to the
    interpreter; or where the line-by-line interpreter could do otherwise: ``"line"`` when
    it should read the first line (after which a run may start), ``"rest"`` when it should
    read them all."""
    if not interp.absolute or interp.factor != 1.0 or interp.path:
        return "rest"
    if not (interp.moved and all(interp.known)):
        return "line"
    given = scan.motion[start:stop]
    if given[0] < 0 and interp.motion not in (0, 1):
        return "line"
    n = stop - start
    motion = given.copy()
    if motion[0] < 0:
        motion[0] = interp.motion
    value = scan.value[start:stop]
    present = scan.present[start:stop]
    if not (np.abs(value[present]) <= MAX_POSITION).all() or \
            not scan.feed_ok[start:stop].all():
        return "rest"       # the interpreter names the line and the word
    motion = motion[np.maximum.accumulate(np.where(motion >= 0, np.arange(n), 0))]
    end = _ffill(value, present, np.array(interp.pos, dtype=float))
    begin = np.vstack([np.array(interp.pos, dtype=float)[None, :], end[:-1]])
    interp._flush()
    first = interp.chunk_moves
    ones = np.ones(n, dtype=bool)
    interp.add_moves({
        "kind": motion, "start": begin, "end": end, "centre": np.full((n, 3), np.nan),
        "plane": np.full(n, interp.plane, dtype=int), "turns": np.ones(n, dtype=int),
        "line": np.arange(base + start, base + stop), "known": np.ones((n, 3), bool),
        "factor": np.ones(n), "absolute": ones})
    interp.pos = end[-1].tolist()
    interp.motion = int(motion[-1])
    return PlainRun(start, stop, given >= 0, first, motion, present, value,
                    scan.decimals[start:stop], scan.size[start:stop])


def _ffill(value, present, initial):
    """``value`` (n, 3) with every absent entry the last present one before it (or
    ``initial`` (3,))."""
    n = value.shape[0]
    idx = np.where(present, np.arange(1, n + 1)[:, None], 0)
    np.maximum.accumulate(idx, axis=0, out=idx)
    full = np.vstack([initial[None, :], value])
    return np.take_along_axis(full, idx, axis=0)


def line_info(run, k, move, content):
    """The :class:`LineInfo` of line ``k`` of a run (its move ``move``, its text
    ``content``), as the line-by-line reader builds it."""
    m = PLAIN.fullmatch(content)
    words = []
    if m.group(1) is not None:
        words.append(Word("G", float(m.group(1)), m.group(1), m.start(1) - 1, m.end(1)))
    axis = [None, None, None]
    for a, g in enumerate(AXIS_GROUPS):
        t = m.group(g)
        if t is not None:
            axis[a] = len(words)
            words.append(Word("XYZ"[a], float(t), t, m.start(g) - 1, m.end(g)))
    if m.group(9) is not None:
        words.append(Word("F", float(m.group(9)), m.group(9), m.start(9) - 1, m.end(9)))
    return LineInfo(words, 1.0, True, int(run.motion[k]),
                    0 if m.group(1) is not None else None, move=move,
                    axis_words=tuple(axis))
