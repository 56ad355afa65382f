# SPDX-License-Identifier: LGPL-2.1-or-later
"""The text of a stretch of plain lines built as bytes in array operations (no FreeCAD).

:mod:`.plain_write` decides which axis numbers of a stretch of plain G0/G1 lines change
and what they become (in integer units of their last decimal, rounded as ``'%.*f'``
rounds). Formatting those numbers one ``'%.4f'`` at a time and joining the pieces of each
line costs microseconds a line; here the digits come from integer arithmetic on all the
numbers at once (:func:`number_bytes`), and the output is gathered, in one indexing
operation, from the original lines' bytes and the new numbers' bytes
(:func:`stretch_text`): a changed line is its original text with the spans of its axis
numbers replaced. The text is the same, byte for byte, as the line-by-line writer's
(``tests/pure/test_gcode_plain.py``).
"""

from itertools import chain

import numpy as np

_POW10 = 10.0 ** np.arange(23)
_MINUS, _DOT, _ZERO = ord("-"), ord("."), ord("0")
#: 1, 2, 3 for the letters X, Y, Z, 0 for any other byte
_AXIS = np.zeros(256, dtype=np.int8)
_AXIS[[ord("X"), ord("Y"), ord("Z")]] = [1, 2, 3]


def number_bytes(units, d):
    """The texts ``'%.*f' % (d, x)`` of numbers given as ``units`` (k,) int64, ``x``
    times ``10**d`` rounded (below 2**52), with ``d`` (k,) >= 1 decimals, without the
    minus sign of a zero (as :func:`surfcomp.io.gcode.emitter._fmt` writes them with
    ``keep = d``): their bytes one after the other (uint8) and the length of each (k,).

    The digits are ``floor(a / 10**p) - 10 floor(a / 10**(p + 1))``, exact in binary64
    for integers ``a`` below 2**52 (a quotient that is not an integer is at least
    ``10**-p`` from one, more than its rounding)."""
    neg = units < 0
    a = np.abs(units).astype(np.float64)
    whole = np.floor(a / _POW10[d])
    size = neg + 2 + d + np.searchsorted(_POW10[1:19], whole, side="right")
    out = np.zeros(int(size.sum()), dtype=np.uint8)
    ends = np.cumsum(size)
    for dd in np.unique(d).tolist():
        k = np.flatnonzero(d == dd) if dd != d[0] or (d != dd).any() else slice(None)
        sz, ng = size[k], neg[k]
        width = int(sz.max())
        # right-aligned rows: the integer digits, the dot, dd decimals
        F = np.floor(a[k][:, None] / _POW10[:width])
        D = (F[:, :-1] - 10.0 * F[:, 1:] + _ZERO).astype(np.uint8)
        char = np.empty((D.shape[0], width), dtype=np.uint8)
        char[:, width - dd:] = D[:, dd - 1::-1]
        char[:, width - dd - 1] = _DOT
        char[:, :width - dd - 1] = D[:, :dd - 1:-1]
        rows = np.flatnonzero(ng)
        char[rows, width - sz[rows]] = _MINUS
        keep = np.arange(width)[None, :] >= (width - sz)[:, None]
        if isinstance(k, slice):
            return char[keep], size
        first = (ends[k] - sz)
        idx = np.repeat(first - (np.cumsum(sz) - sz), sz) + np.arange(int(sz.sum()))
        out[idx] = char[keep]
    return out, size


def _gather(buf, start, length):
    """``buf`` (uint8) at the segments ``start``, ``length`` (in order) as bytes."""
    ends = np.cumsum(length)
    total = int(ends[-1]) if ends.size else 0
    idx = np.arange(total, dtype=np.int64)
    idx += np.repeat(start - (ends - length), length)
    return buf[idx].tobytes()


def stretch_text(contents, sizes, units, d, change, rows, other, bounds=None):
    """The output text of a stretch of plain lines (or of consecutive stretches).

    Parameters
    ----------
    contents : list of (str, str)
        ``(content, ending)`` of the n lines.
    sizes : ndarray (n, 3) int
        Length of each axis word's number in the line (where ``present``).
    units, d : ndarray (n, 3) int
        The new numbers in units of their last decimal, and their decimals (>= 1).
    change : ndarray (n, 3) bool
        The numbers written anew (lines with a change and every axis word: the words'
        numbers replaced; the other lines with a change are in ``other``).
    rows : ndarray (r,) int
        The lines with a change whose text is built here.
    other : dict
        ``{line: text}`` of the lines with a change built by the caller (endings
        included).
    bounds : ndarray (s,) int, optional
        The line after each of s stretches (the last one ``n``): their texts are returned
        one by one.

    Returns
    -------
    str, or list of s str with ``bounds``
    """
    n = len(contents)
    text = "".join(chain.from_iterable(contents))
    buf = np.frombuffer(text.encode("latin-1"), dtype=np.uint8)
    llen = _line_lengths(contents, buf)
    lstart = np.zeros(n, dtype=np.int64)
    np.cumsum(llen[:-1], out=lstart[1:])
    # segments per line: original up to X's number, X's number, up to Y's, Y's, up to
    # Z's, Z's, the rest with the ending; a line kept or built elsewhere has one segment
    seg_start = np.zeros((n, 7), dtype=np.int64)
    seg_len = np.zeros((n, 7), dtype=np.int64)
    seg_start[:, 0] = lstart
    seg_len[:, 0] = llen
    parts = [buf]
    size = buf.size
    if rows.size:
        sz = sizes[rows]
        # the numbers' starts: after their letter (a plain line has each letter once)
        axis = np.take(_AXIS, buf)
        pos = np.flatnonzero(axis)
        at = np.zeros((n, 3), dtype=np.int64)
        at[np.searchsorted(lstart, pos, side="right") - 1, axis[pos] - 1] = pos + 1
        starts = at[rows]
        ch = change[rows]
        nb, nsize = number_bytes(units[rows][ch], d[rows][ch])
        noff = np.zeros(nsize.size, dtype=np.int64)
        np.cumsum(nsize[:-1], out=noff[1:])
        num_start = starts.copy()
        num_len = sz.copy()
        num_start[ch] = size + noff
        num_len[ch] = nsize
        parts.append(nb)
        size += nb.size
        ls = lstart[rows]
        le = ls + llen[rows]
        ends = starts + sz
        seg_start[rows] = np.column_stack([ls, num_start[:, 0], ends[:, 0], num_start[:, 1],
                                           ends[:, 1], num_start[:, 2], ends[:, 2]])
        seg_len[rows] = np.column_stack([starts[:, 0] - ls, num_len[:, 0],
                                         starts[:, 1] - ends[:, 0], num_len[:, 1],
                                         starts[:, 2] - ends[:, 1], num_len[:, 2],
                                         le - ends[:, 2]])
    if other:
        keys = sorted(other)
        extra = "".join(other[k] for k in keys).encode("latin-1")
        lens = np.array([len(other[k]) for k in keys], dtype=np.int64)
        off = np.zeros(lens.size, dtype=np.int64)
        np.cumsum(lens[:-1], out=off[1:])
        seg_start[keys, 0] = size + off
        seg_len[keys, 0] = lens
        parts.append(np.frombuffer(extra, dtype=np.uint8))
    if len(parts) == 1:
        return text if bounds is None else _split(text, llen, bounds)
    out = _gather(np.concatenate(parts), seg_start.ravel(), seg_len.ravel())
    text = out.decode("latin-1")
    return text if bounds is None else _split(text, seg_len.sum(axis=1), bounds)


def _split(text, line_len, bounds):
    """``text`` cut after the lines ``bounds`` (``line_len`` the length of each)."""
    ends = np.cumsum(line_len)[np.asarray(bounds) - 1].tolist()
    return [text[a:b] for a, b in zip([0] + ends[:-1], ends)]


def _line_lengths(contents, buf):
    """Length of each ``(content, ending)`` line with its ending (n,) int64; ``buf`` is
    their text (uint8). A line ends at its ``"\n"`` (the ending is ``"\n"`` or
    ``"\r\n"``, the content has none), the file's last one perhaps without one."""
    n = len(contents)
    if not n:
        return np.zeros(0, dtype=np.int64)
    ends = np.flatnonzero(buf == ord("\n")) + 1
    if ends.size == n - 1:
        ends = np.append(ends, buf.size)
    if ends.size == n and ends[-1] == buf.size:
        return np.diff(ends, prepend=0)
    cont, ends = zip(*contents)
    return (np.fromiter(map(len, cont), dtype=np.int64, count=n)
            + np.fromiter(map(len, ends), dtype=np.int64, count=n))
