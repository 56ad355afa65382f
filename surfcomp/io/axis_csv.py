# SPDX-License-Identifier: LGPL-2.1-or-later
"""Per-axis error measurement files (no FreeCAD): the input of the axis error model.

Two layouts are read; the first non-blank, non-comment line tells which.

1. Long form, one row per measured position of one slide::

       axis,position,ex,ey,ez
       X,0,0,0,0
       X,100,0.012,-0.003,0.001
       Y,50,...

   ``axis`` is ``X``, ``Y`` or ``Z`` (any case); ``ex, ey, ez`` are the tool-position errors
   along X, Y and Z (actual minus commanded) when that slide stands at ``position`` and the
   others at the reference. Column order is free; names are case-insensitive. An empty
   error field is not measured in that row (NaN, as a column a table leaves out); a row
   needs at least one error.

2. Per-axis tables (the common laser-calibration form); several tables may follow one
   another, each starting with its header::

       X    EXX    EYX    EZX
       0    0      0      0
       100  0.012  -0.003 0.001
       Y    EXY    EYY    EZY
       ...

   ``E<i><a>`` is the error along ``i`` while slide ``a`` moves. A slide may appear in
   several tables (repeated runs); their rows are pooled. A column a table leaves out is
   not measured in its rows (NaN: left out of that component's fit); a column no table of
   the slide gives is taken as 0 in all its rows (with a warning).

Common rules
------------
- Separator detected per header line: tab, else ``;``, else ``,``, else runs of blanks.
  Data lines use their header's separator. Decimal point only.
- Lines whose first non-blank characters are ``#`` or ``//`` are comments; blank lines
  (and lines of separators only) are skipped.
- Unit suffixes as in :mod:`surfcomp.io.units`: ``position[mm]``, ``ex[um]``, ``EXX_um``,
  ``X(in)``. Columns without a suffix are in ``units`` (default mm). Values are returned in
  mm.
- Every value must be finite and every position within 1 km; with ``max_error`` an error
  larger than it (mm, after the unit conversion) is refused, since it is most likely a unit
  mistake (micrometres read as millimetres).
- Every problem raises :class:`surfcomp.errors.MeasurementFileError` naming
  ``file:line[:column]``, what is wrong and what was expected.
"""

import math
import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, MeasurementFileError
from .atomic import write_text
from .files import clip, read_bytes
from .measurement_set import MAX_COORDINATE
from .units import split_unit_suffix, unit_factor

AXES = ("x", "y", "z")
LONG_COLUMNS = ("axis", "position", "ex", "ey", "ez")
_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_TABLE_ERR = re.compile(r"^e([xyz])([xyz])$")
_ANY_SUFFIX = re.compile(r"^(?P<base>.*?)\s*[\[(]\s*(?P<unit>[^\])]+?)\s*[\])]\s*$")


@dataclass
class AxisErrorTable:
    """Measured per-axis errors read from a file.

    Attributes
    ----------
    data : dict
        ``{'x': (positions (n,), errors (n, 3))}`` in mm, the input of
        :func:`surfcomp.core.axis.axis_errors.fit_axis_errors`; NaN where a table left
        that component out.
    lines : dict
        ``{'x': ndarray (n,) int}``: the 1-based file line of every row.
    path : str or None
    layout : str
        ``'long'`` (``axis,position,ex,ey,ez``) or ``'tables'`` (``X EXX EYX EZX``).
    """

    data: dict
    lines: dict
    path: str = None
    layout: str = "long"
    warnings: list = field(default_factory=list)

    def rows(self):
        """Number of measured rows per axis, e.g. ``{'x': 11, 'z': 6}``."""
        return {a: int(p.size) for a, (p, _) in self.data.items()}


def _is_comment(text):
    s = text.strip()
    return not s or s.startswith("#") or s.startswith("//")


def _separator(header):
    if "\t" in header:
        return "\t"
    if ";" in header:
        return ";"
    if "," in header:
        return ","
    return None


def _split(text, sep):
    if sep is None:
        return text.split()
    return [f.strip() for f in text.split(sep)]


def _factor(unit, path, line, col):
    try:
        return unit_factor(unit, file=path, line=line, column=col)
    except InputError as exc:
        raise MeasurementFileError(exc.message, file=path, line=line, column=col) from None


def _split_name(name):
    """``(base, unit or None)``; a bracketed suffix with an unknown unit is still split."""
    base, unit = split_unit_suffix(name)
    if unit is None:
        m = _ANY_SUFFIX.match(name.strip())
        if m:
            return m.group("base").strip(), m.group("unit").strip()
    return base, unit


def _number(text, path, line, col, what, factor=1.0):
    """The value of a field in mm (``factor`` mm per unit of its column); finite."""
    s = text.strip()
    if not _NUMBER.match(s):
        raise MeasurementFileError("%s: %r is not a number (expected e.g. 12.5 or -0.003; "
                                   "decimal point, no thousands separators)" % (what, clip(text)),
                                   file=path, line=line, column=col)
    v = float(s) * factor
    if not math.isfinite(v):
        raise MeasurementFileError("%s: %r is out of range (expected a finite number)"
                                   % (what, clip(text)), file=path, line=line, column=col)
    return v


def _position(text, path, line, col, what, factor):
    """A slide position in mm, within 1 km (as G-code positions; larger ones are a wrong
    column or unit, and their powers overflow in the fit)."""
    v = _number(text, path, line, col, what, factor)
    if not abs(v) <= MAX_COORDINATE:
        raise MeasurementFileError("%s: %r = %.6g mm is beyond %g mm (1 km; expected a slide "
                                   "position in mm: check the column and the units)"
                                   % (what, text.strip(), v, MAX_COORDINATE), file=path,
                                   line=line, column=col)
    return v


def _error(text, path, line, col, what, factor, max_error):
    """An error value in mm, refused when larger than ``max_error`` (mm; None: no limit)."""
    v = _number(text, path, line, col, what, factor)
    if max_error is not None and not abs(v) <= max_error:
        raise MeasurementFileError("%s: error %r = %.6g mm is larger than max_error %g mm "
                                   "(expected the error of a machine axis: check the unit; "
                                   "a column in um needs a suffix such as %s[um], or units "
                                   "um)" % (what, text.strip(), v, max_error, what),
                                   file=path, line=line, column=col,
                                   options=("max_error", "units"))
    return v


def read_axis_errors(path, units="mm", text=None, max_error=None):
    """Read a per-axis error file (either layout).

    Parameters
    ----------
    path : str
        The file (also used in error messages when ``text`` is given).
    units : str
        Unit of columns without a suffix (``mm``, ``um``, ``in``).
    text : str, optional
        The file's content (then ``path`` is only a name).
    max_error : float, optional
        Largest accepted error value (mm); default no limit.

    Returns
    -------
    AxisErrorTable

    Raises
    ------
    MeasurementFileError
        Unreadable file, unknown header, bad value, or no data rows.
    """
    if text is None:
        raw = read_bytes(path, "the axis error file")
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise MeasurementFileError("not UTF-8 text (byte %d)" % exc.start, file=path) from exc
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    first = next((k for k, s in enumerate(lines) if not _is_comment(s)), None)
    if first is None:
        raise MeasurementFileError("no header found (expected 'axis,position,ex,ey,ez' or "
                                   "per-axis tables 'X EXX EYX EZX')", file=path)
    sep = _separator(lines[first])
    names = [_split_name(f)[0].lower() for f in _split(lines[first], sep)]
    if "axis" in names:
        return _read_long(path, lines, first, units, max_error)
    if names and names[0] in AXES:
        return _read_tables(path, lines, first, units, max_error)
    raise MeasurementFileError("unknown header %r (expected 'axis,position,ex,ey,ez' or "
                               "per-axis tables starting 'X EXX EYX EZX')"
                               % lines[first].strip(), file=path, line=first + 1)


def _read_long(path, lines, first, units, max_error=None):
    lineno = first + 1
    sep = _separator(lines[first])
    header = _split(lines[first], sep)
    role, factor = {}, {}
    for c, name in enumerate(header, start=1):
        base, unit = _split_name(name)
        key = base.strip().strip('"').lower()
        if key not in LONG_COLUMNS:
            raise MeasurementFileError("unknown column %r (expected exactly the columns "
                                       "axis, position, ex, ey, ez, with optional unit "
                                       "suffixes such as ex[um])" % name, file=path,
                                       line=lineno, column=c)
        if key in role:
            raise MeasurementFileError("column %r appears twice" % key, file=path,
                                       line=lineno, column=c)
        if key == "axis" and unit:
            raise MeasurementFileError("the axis column takes no unit", file=path,
                                       line=lineno, column=c)
        role[key] = c - 1
        factor[key] = _factor(unit or units, path, lineno, c)
    missing = [k for k in LONG_COLUMNS if k not in role]
    if missing:
        raise MeasurementFileError("missing column(s) %s (expected axis,position,ex,ey,ez)"
                                   % ", ".join(missing), file=path, line=lineno)
    rows = {a: ([], [], []) for a in AXES}
    for k in range(first + 1, len(lines)):
        s = lines[k]
        if _is_comment(s):
            continue
        fields = _split(s, sep)
        if sep is not None and all(not f for f in fields):
            continue
        if len(fields) != len(header):
            raise MeasurementFileError("%d fields, expected %d like the header"
                                       % (len(fields), len(header)), file=path, line=k + 1)
        ax = fields[role["axis"]].strip().strip('"').lower()
        if ax not in AXES:
            raise MeasurementFileError("axis %r (expected X, Y or Z)" % fields[role["axis"]],
                                       file=path, line=k + 1, column=role["axis"] + 1)
        vals = [_position(fields[role["position"]], path, k + 1, role["position"] + 1,
                          "position", factor["position"])]
        # an empty error field: not measured in this row (what format_axis_errors writes
        # for NaN, a column a table left out)
        vals += [math.nan if not fields[role[c]].strip().strip('"') else
                 _error(fields[role[c]], path, k + 1, role[c] + 1, c, factor[c], max_error)
                 for c in ("ex", "ey", "ez")]
        if all(math.isnan(v) for v in vals[1:]):
            raise MeasurementFileError("no error in this row (expected a value in at least "
                                       "one of ex, ey, ez; an empty field is not measured)",
                                       file=path, line=k + 1)
        rows[ax][0].append(vals[0])
        rows[ax][1].append(vals[1:])
        rows[ax][2].append(k + 1)
    return _finish(path, rows, "long", lines)


def _read_tables(path, lines, first, units, max_error=None):
    rows = {a: ([], [], []) for a in AXES}
    cur = None  # (axis, sep, ncols, pos_factor, [(component, factor, col)])
    for k in range(first, len(lines)):
        s = lines[k]
        if _is_comment(s):
            continue
        own = _split(s, _separator(s))
        if own and _split_name(own[0])[0].strip().lower() in AXES:
            cur = _table_header(path, k + 1, s, units)
            continue
        if cur is None:
            raise MeasurementFileError("data before any table header (expected e.g. "
                                       "'X EXX EYX EZX')", file=path, line=k + 1)
        ax, sep, ncols, pfac, comps = cur
        fields = _split(s, sep)
        if sep is not None and all(not f for f in fields):
            continue
        if len(fields) != ncols:
            raise MeasurementFileError("%d fields, expected %d like the table header"
                                       % (len(fields), ncols), file=path, line=k + 1)
        pos = _position(fields[0], path, k + 1, 1, ax.upper(), pfac)
        err = [math.nan, math.nan, math.nan]      # a column the table leaves out: not measured
        for comp, fac, col in comps:
            err[comp] = _error(fields[col], path, k + 1, col + 1,
                               "E%s%s" % (AXES[comp].upper(), ax.upper()), fac, max_error)
        rows[ax][0].append(pos)
        rows[ax][1].append(err)
        rows[ax][2].append(k + 1)
    return _finish(path, rows, "tables", lines)


def _table_header(path, lineno, text, units):
    sep = _separator(text)
    fields = _split(text, sep)
    base, unit = _split_name(fields[0])
    ax = base.strip().lower()
    pfac = _factor(unit or units, path, lineno, 1)
    comps, seen = [], set()
    expect = "'%s EX%s EY%s EZ%s'" % ((ax.upper(),) * 4)
    for c, name in enumerate(fields[1:], start=2):
        b, u = _split_name(name)
        m = _TABLE_ERR.match(b.strip().lower())
        if not m:
            raise MeasurementFileError("table header column %r is not an error column "
                                       "(expected %s, optionally with unit suffixes)"
                                       % (name, expect), file=path, line=lineno, column=c)
        comp, moving = m.group(1), m.group(2)
        if moving != ax:
            raise MeasurementFileError("column %r belongs to slide %s but the table is for "
                                       "slide %s (expected %s)" % (name, moving.upper(),
                                                                     ax.upper(), expect),
                                       file=path, line=lineno, column=c)
        if comp in seen:
            raise MeasurementFileError("column %r appears twice" % name, file=path,
                                       line=lineno, column=c)
        seen.add(comp)
        comps.append((AXES.index(comp), _factor(u or units, path, lineno, c), c - 1))
    if not comps:
        raise MeasurementFileError("table header without error columns (expected %s)"
                                   % expect, file=path, line=lineno)
    return ax, sep, len(fields), pfac, comps


def _finish(path, rows, layout, lines):
    data, where, unmeasured = {}, {}, []
    for ax in AXES:
        pos, err, ln = rows[ax]
        if pos:
            err = np.array(err, dtype=float).reshape(-1, 3)
            for i in np.flatnonzero(np.isnan(err).all(axis=0)):
                err[:, i] = 0.0                   # in no table of the slide: no error
                unmeasured.append("E%s%s" % (AXES[i].upper(), ax.upper()))
            data[ax] = (np.array(pos, dtype=float), err)
            where[ax] = np.array(ln, dtype=int)
    if not data:
        last = max((k + 1 for k, t in enumerate(lines) if t.strip()), default=1)
        raise MeasurementFileError("no data rows (expected at least two positions of one "
                                   "slide)", file=path, line=last)
    warnings = ["%s: %s in no %s, taken as 0 (no error measured, none compensated)"
                % (path, ", ".join(unmeasured), "table" if layout == "tables" else "row")
                ] if unmeasured else []
    return AxisErrorTable(data, where, path=path, layout=layout, warnings=warnings)


def format_axis_errors(data, units="mm"):
    """Text of a long-form file (``axis,position,ex,ey,ez``) for ``data`` (mm), which
    :func:`read_axis_errors` reads back to the same data.

    Parameters
    ----------
    data : mapping
        ``{'x': (positions (n,), errors (n, 3))}`` in mm; NaN where a component was not
        measured (a column a table left out), written as an empty field.
    units : {'mm', 'um'}
        Unit of the error columns (positions are always written in mm).

    Raises
    ------
    InputError
        A position that is not finite, an infinite error, or a row with no error at all:
        no file could say it.
    """
    f = unit_factor(units)
    head = "axis,position[mm],ex[%s],ey[%s],ez[%s]" % (units, units, units)
    out = [head]
    for ax in AXES:
        if ax not in data:
            continue
        pos, err = data[ax]
        pos, err = np.asarray(pos, dtype=float), np.asarray(err, dtype=float).reshape(-1, 3)
        for k, (p, e) in enumerate(zip(pos, err)):
            if not np.isfinite(p) or np.isinf(e).any() or np.isnan(e).all():
                raise InputError("axis %s, row %d: position %r, errors %s: a file holds a "
                                 "finite position and at least one finite error per row "
                                 "(NaN: not measured)" % (ax.upper(), k + 1, float(p),
                                                          e.tolist()))
            out.append("%s,%.6f,%s" % (ax.upper(), p, ",".join(
                "" if np.isnan(v) else "%.9g" % (v / f) for v in e)))
    return "\n".join(out) + "\n"


def write_axis_errors(path, data, units="mm"):
    """Write ``data`` as a long-form file, atomically (see :func:`format_axis_errors`)."""
    write_text(os.fspath(path), format_axis_errors(data, units))
