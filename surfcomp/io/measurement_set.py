# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measurement set every reader returns, and what the readers share (no FreeCAD).

:class:`MeasurementSet` holds the points of one measurement in mm: nominal and measured
points, normals, deviations along them, grid indices, ids and the source line of every
point (for messages). The readers (:mod:`surfcomp.io.measurements` for tables,
:mod:`surfcomp.io.pointfiles` for measured-only point files, :mod:`surfcomp.io.qif`) build
it, with the shared bounds and checks below.
"""

import codecs
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, MeasurementFileError
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

_EXPECTED_COMBOS = "expected nominal+normal+deviation or nominal+measured"


@dataclass
class MeasurementSet:
    """Points read from a measurement file; all lengths in mm.

    Attributes
    ----------
    nominal : ndarray, shape (N, 3) or None
        Nominal points (mm).
    measured : ndarray, shape (N, 3) or None
        Measured (actual) points (mm).
    normal : ndarray, shape (N, 3) or None
        Unit normals (direction cosines, Werner 2022 eq. 1), renormalised.
    deviation : ndarray, shape (N,) or None
        Signed deviation along the normal (mm), positive when the measured point lies on
        the side the normal points to: ``(measured - nominal) . normal``.
    row, col : ndarray of int64, shape (N,) or None
        Grid indices, when the file has them.
    ids : list of str or None
        Point names, when the file has them.
    lines : ndarray of int64, shape (N,)
        1-based line of each point in the source (for messages); ``1..N`` when None is
        given.
    source : str
        File path or name used in messages.
    sha256 : str
        Hex SHA-256 of the raw file bytes.
    units : str
        Unit of the file's length columns (``'mm'``, ``'um'``, ``'in'``, ``'cm'``, ``'m'``),
        or ``'mixed'`` when they differ.
    columns : dict
        Role (``'x_nom'``, ..., ``'i'``, ``'dev'``, ``'row'``, ``'col'``, ``'id'``) -> the
        column name as written in the header.
    ignored_columns : list of str
        Header names of the columns not used.
    warnings : list of str
        ``'file:line: ...'`` texts (ignored columns, normal lengths, deviation check).
    separator : str
        ``','``, ``';'``, ``'\\t'`` or ``' '`` (runs of blanks).
    decimal_comma : bool
        The numbers were written with a decimal comma.
    tip_centres : bool
        The measured points are stylus tip centres (LinuxCNC probe logs), not contact
        points: they need the tip radius (``Options.tip_radius``).
    """

    nominal: np.ndarray = None
    measured: np.ndarray = None
    normal: np.ndarray = None
    deviation: np.ndarray = None
    row: np.ndarray = None
    col: np.ndarray = None
    ids: list = None
    lines: np.ndarray = None
    source: str = "<data>"
    sha256: str = ""
    units: str = "mm"
    columns: dict = field(default_factory=dict)
    ignored_columns: list = field(default_factory=list)
    warnings: list = field(default_factory=list)
    separator: str = ","
    decimal_comma: bool = False
    tip_centres: bool = False

    def __post_init__(self):
        if self.lines is None:
            n = next((len(a) for a in (self.nominal, self.measured, self.normal, self.deviation)
                      if a is not None), 0)
            self.lines = np.arange(1, n + 1, dtype=np.int64)

    def kind(self):
        """Which accepted combination of columns the set holds.

        Returns
        -------
        str
            ``'nominal+normal+deviation'``, ``'nominal+measured'``,
            ``'nominal+measured+normal'`` or ``'all'`` (the deviation given as well);
            for the measured-only sets of :mod:`surfcomp.io.pointfiles` (no nominal)
            ``'measured'`` or ``'measured+normal'``.

        Raises
        ------
        InputError
            For a set built by hand that holds none of these.
        """
        if self.nominal is None:
            if self.measured is not None and self.deviation is None:
                return "measured" if self.normal is None else "measured+normal"
        else:
            if self.measured is None:
                if self.normal is not None and self.deviation is not None:
                    return "nominal+normal+deviation"
            elif self.normal is None:
                return "nominal+measured"
            elif self.deviation is not None and "dev" in self.columns:
                return "all"
            else:
                return "nominal+measured+normal"
        raise InputError("the measurement set holds no accepted combination of nominal, "
                         "measured, normal and deviation (%s)" % _EXPECTED_COMBOS, file=self.source)

    def __len__(self):
        return len(self.lines)


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
