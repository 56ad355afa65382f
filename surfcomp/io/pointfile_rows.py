# SPDX-License-Identifier: LGPL-2.1-or-later
"""The rows of a plain point file (no FreeCAD): lines split into fields, numbers parsed
and checked, and the first bad field located with its file, line and column, for the
readers of :mod:`surfcomp.io.pointfiles`."""

import itertools
import operator
import re

import numpy as np

from ..errors import MeasurementFileError
from .files import clip

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_NONFINITE = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)


def _split_lines(text):
    """Lines without their end-of-line characters; ``\\n``, ``\\r\\n`` and ``\\r`` end lines."""
    return text.replace("\r\n", "\n").replace("\r", "\n").split("\n")


def _is_number(token):
    """True if ``token`` is a decimal number (``[+-]digits[.digits][e[+-]digits]``) or a
    NaN/inf word (those are read as numbers, then rejected as not finite)."""
    return bool(_NUMBER.fullmatch(token) or _NONFINITE.fullmatch(token))


def _fields(text, sep):
    """Split ``text`` into (field, 1-based column of the field's first character)."""
    if sep is None:
        return [(m.group(0), m.start() + 1) for m in re.finditer(r"\S+", text)]
    out = []
    pos = 0
    for part in text.split(sep):
        stripped = part.strip()
        lead = len(part) - len(part.lstrip())
        out.append((stripped, pos + lead + 1))
        pos += len(part) + len(sep)
    return out


def _strip_comment(text):
    """Remove a ``#`` or ``//`` comment from a line of a plain XYZ file."""
    cut = len(text)
    for mark in ("#", "//"):
        k = text.find(mark)
        if 0 <= k < cut:
            cut = k
    return text[:cut]


class _Rows:
    """The data lines of a file: 1-based line numbers (int64 array) and texts (list)."""

    def __init__(self, numbers, texts):
        self.numbers = np.asarray(numbers, dtype=np.int64)
        self.texts = texts

    @classmethod
    def nonblank(cls, lines, first=1):
        """The lines that are not blank; ``first`` is the line number of ``lines[0]``."""
        keep = np.fromiter(map(bool, map(str.strip, lines)), dtype=bool, count=len(lines))
        return cls(np.flatnonzero(keep) + first, list(itertools.compress(lines, keep.tolist())))

    def __len__(self):
        return len(self.texts)

    def __getitem__(self, k):
        if isinstance(k, slice):
            return _Rows(self.numbers[k], self.texts[k])
        return int(self.numbers[k]), self.texts[k]


def _field_counts(rows, sep):
    """Number of fields of every line (vectorised over the lines)."""
    if sep is None:
        counts = map(len, map(str.split, rows.texts))
        return np.fromiter(counts, dtype=np.int64, count=len(rows))
    counts = map(operator.methodcaller("count", sep), rows.texts)
    return np.fromiter(counts, dtype=np.int64, count=len(rows)) + 1


def _raise_field_count(path, row, sep, count, allowed, expected):
    """Raise the wrong-field-count error for one line ``row`` = (line number, text)."""
    lineno, text = row
    fields = _fields(text, sep)
    column = fields[max(allowed)][1] if count > max(allowed) else None
    ends = sep is not None and text.rstrip().endswith(sep) and count > max(allowed)
    raise MeasurementFileError(
        "wrong field count: %d fields, expected %s%s"
        % (count, expected, "; the line ends with a separator" if ends else ""),
        file=str(path), line=lineno, column=column)


def _locate_bad_number(path, rows, sep, decimal_comma, usecols, names):
    """Raise for the first field of ``usecols`` in ``rows`` that is not a decimal number.

    Parameters
    ----------
    rows : _Rows
    usecols : sequence of int
        0-based indices of the numeric fields.
    names : sequence of str
        Field names for messages (``names[k]`` names field ``k``).
    """
    for k in range(len(rows)):
        lineno, text = rows[k]
        fields = _fields(text, sep)
        for c in usecols:
            tok, col = fields[c]
            value = tok.replace(",", ".") if decimal_comma else tok
            if not _is_number(value):
                what = ("empty field %d (%s); expected a number" % (c + 1, names[c]) if not tok
                        else "malformed number %r in field %d (%s); expected a decimal number "
                        "such as -12.345 (%s)" % (clip(tok), c + 1, names[c], "decimal comma"
                                                  if decimal_comma else "decimal point"))
                raise MeasurementFileError(what, file=str(path), line=lineno, column=col)


def _parse_rows(path, rows, sep, decimal_comma, ncols, names, expected, usecols=None):
    """Parse lines of ``ncols`` fields each into a float array, vectorised.

    The fast path is numpy's C reader; on a failure the lines are checked one by one so
    that the error names the exact line and column.

    Parameters
    ----------
    rows : _Rows
    sep : str or None
        Field separator, None for runs of white space.
    ncols : int
        Fields every line must have.
    names : sequence of str
        Field names for messages.
    expected : str
        What a line must hold, for messages.
    usecols : sequence of int, optional
        Fields to read (default all).

    Returns
    -------
    ndarray, shape (len(rows), len(usecols))
    """
    if usecols is not None and list(usecols) == list(range(ncols)):
        usecols = None
    if usecols is not None:     # numpy checks the field count only when reading all fields
        counts = _field_counts(rows, sep)
        bad = np.flatnonzero(counts != ncols)
        if bad.size:
            k = int(bad[0])
            _raise_field_count(path, rows[k], sep, int(counts[k]), {ncols}, expected)
    texts = rows.texts
    if decimal_comma:
        texts = [t.replace(",", ".") for t in texts]
    try:
        arr = np.loadtxt(texts, delimiter=sep, comments=None, dtype=float, ndmin=2,
                         quotechar=None, usecols=usecols)
        if usecols is None and arr.shape[1] != ncols:
            raise ValueError("%d fields" % arr.shape[1])
    except ValueError as exc:
        counts = _field_counts(rows, sep)
        bad = np.flatnonzero(counts != ncols)
        if bad.size:
            k = int(bad[0])
            _raise_field_count(path, rows[k], sep, int(counts[k]), {ncols}, expected)
        cols = list(range(ncols)) if usecols is None else list(usecols)
        _locate_bad_number(path, rows, sep, decimal_comma, cols, names)
        raise MeasurementFileError("cannot read the numbers: %s" % exc, file=str(path)) from exc
    _check_finite(path, arr, rows, sep, list(range(ncols)) if usecols is None else usecols,
                  names)
    return arr


def _check_finite(path, arr, rows, sep, usecols, names):
    """Raise for the first NaN or infinite value (file, line, column)."""
    bad = ~np.isfinite(arr)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        lineno, text = rows[int(r)]
        k = usecols[c]
        tok, col = _fields(text, sep)[k]
        raise MeasurementFileError("%r in field %d (%s) is not a finite number; expected a "
                                   "finite decimal number" % (clip(tok), k + 1, names[k]),
                                   file=str(path), line=lineno, column=col)
