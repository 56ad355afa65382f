# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measurement set every reader returns, and what the readers share (no FreeCAD).

:class:`~surfcomp.core.measurement_set.MeasurementSet` (a core type, re-exported here)
holds the points of one measurement in mm: nominal and measured points, normals, deviations
along them, grid indices, ids and the source line of every point (for messages). The
readers (:mod:`surfcomp.io.measurements` for tables, :mod:`surfcomp.io.pointfiles` for
measured-only point files, :mod:`surfcomp.io.qif`) build it, with the shared bounds and
checks below.
"""

import codecs

import numpy as np

from ..core.measurement_set import (  # noqa: F401  (re-exported: their old home)
    _EXPECTED_COMBOS,
    MeasurementSet,
)
from ..errors import MeasurementFileError
from .files import clip

#: largest difference (mm) between a given deviation and (measured - nominal) . normal
DEV_CHECK_TOL = 1e-3
#: largest distance (mm) at which two nominal points are the same point
DUPLICATE_TOL = 1e-9
#: largest | |n| - 1 | of a given normal that passes without a warning
NORMAL_LENGTH_TOL = 1e-3
#: a given normal shorter than this has no direction (an error)
NORMAL_ZERO = 1e-9
#: largest coordinate (mm) of a nominal or measured point: 1 km, beyond any part (and the
#: bound of G-code positions); larger values are a wrong column or unit, and their
#: squared distances would overflow
MAX_COORDINATE = 1e6
#: per-point warnings of one kind listed before they are only counted
MAX_POINT_WARNINGS = 10


def check_duplicates(points, lines, source, what="nominal point"):
    """Refuse a point given twice (within :data:`DUPLICATE_TOL`): names the second line,
    the first and how many pairs there are. ``lines``: the 1-based line of every point."""
    from ..core.surface.kdtree import cKDTree

    pairs = cKDTree(points, balanced_tree=False).query_pairs(DUPLICATE_TOL,
                                                              output_type="ndarray")
    if len(pairs):
        first, again = pairs[np.lexsort((pairs[:, 0], pairs[:, 1]))[0]]
        raise MeasurementFileError(
            "%s (%.9g, %.9g, %.9g) mm is given again; first on line %d (expected each %s "
            "once; %d duplicate pair(s) in all)" % ((what,) + tuple(points[again])
                                                   + (int(lines[first]), what, len(pairs))),
            file=source, line=int(lines[again]))


def check_coordinates(values, lines, source, columns=None, limit=MAX_COORDINATE,
                      what="coordinate"):
    """Refuse values (N, k) in mm that are not finite (a unit conversion can overflow) or
    larger than ``limit``.

    Parameters
    ----------
    values : ndarray (N, k)
    lines : array_like (N,)
        1-based line of every row.
    source : str
    columns : list of int, optional
        1-based column of each of the k values.

    Raises
    ------
    MeasurementFileError
        ``file:line[:column]``, the value and the limit.
    """
    bad = ~(np.isfinite(values) & (np.abs(values) <= limit))
    if not bad.any():
        return
    k, c = (int(x) for x in np.argwhere(bad)[0])
    if np.isfinite(values[k, c]):
        text = "%s %.6g mm is beyond %g mm (1 km; expected a point of a part: wrong column or " \
               "units?)" % (what, values[k, c], limit)
    else:
        text = "the %s overflows when converted to mm (the value is too large for its unit; " \
               "wrong column or units?)" % what
    raise MeasurementFileError(text, file=source, line=int(lines[k]),
                               column=None if columns is None else columns[c])


def decode_utf8(raw, source):
    """Decode file bytes as UTF-8 (a byte order mark is skipped); UTF-16/32 and invalid
    bytes raise MeasurementFileError naming the line."""
    for bom, name in ((codecs.BOM_UTF32_LE, "UTF-32"), (codecs.BOM_UTF32_BE, "UTF-32"),
                      (codecs.BOM_UTF16_LE, "UTF-16"), (codecs.BOM_UTF16_BE, "UTF-16")):
        if raw.startswith(bom):
            raise MeasurementFileError("the file is %s text (expected UTF-8: save it as UTF-8)"
                                       % name, file=source, line=1)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise MeasurementFileError("byte 0x%02x at offset %d is not UTF-8 (expected UTF-8 text: "
                                   "save the file as UTF-8)" % (raw[exc.start], exc.start),
                                   file=source, line=line) from exc


#: ignored columns named one by one in warnings and messages; the others are counted (a
#: table of a million extra columns gave a million warning lines)
LISTED_COLUMNS = 10


def listed_names(names, limit=LISTED_COLUMNS):
    """``'a', 'b', 'c'``, or the first ``limit`` and ``and N more``."""
    shown = ", ".join("'%s'" % clip(n) for n in names[:limit])
    return shown + (" and %d more" % (len(names) - limit) if len(names) > limit else "")


def ignored_column_warnings(source, line, columns):
    """Warnings for the ignored ``columns`` ((1-based column, name, why) in order) of the
    header on ``line``: one each up to :data:`LISTED_COLUMNS`, then one counting the rest."""
    out = ["%s:%d: column %d '%s' is ignored (%s)" % (source, line, c, clip(name), why)
           for c, name, why in columns[:LISTED_COLUMNS]]
    rest = columns[LISTED_COLUMNS:]
    if rest:
        out.append("%s:%d: %d more columns are ignored (columns %d to %d: not known column "
                   "names)" % (source, line, len(rest), rest[0][0], rest[-1][0]))
    return out
