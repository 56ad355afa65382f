# SPDX-License-Identifier: LGPL-2.1-or-later
"""Measurement files: nominal points, measured points, normals and deviations (no FreeCAD).

A measurement file is a text table with one row per measured point, as CMM software
exports it (Werner 2022, section 2: "coordinates of nominal and observed points,
deviations observed and directional cosines").

File format
-----------
- Text in UTF-8, with or without a byte order mark; LF, CRLF (or CR-only) line ends.
- Lines whose first non-blank characters are ``#`` or ``//`` are comments; blank lines
  are skipped. With a ``,``, ``;`` or tab separator a line of separators only (``;;;``,
  as spreadsheets write empty rows) counts as blank. There are no trailing comments.
- The first line that is neither blank nor a comment is the header; it names the
  columns. Every later line is one point.
- Separator, detected on the header: tab if it has a tab, else ``;`` if it has one, else
  ``,`` if it has one, else runs of blanks (spaces and tabs). ``MeasurementSet.separator``
  is ``"\\t"``, ``";"``, ``","`` or ``" "`` (runs of blanks).
- Decimal comma: accepted with every separator but ``,``. A file is read with a
  decimal comma when any number in it has a comma; then no number may have a decimal
  point (``1.5`` next to ``2,5`` is an error: thousands separators are not accepted).
- Header names and id/name fields may be enclosed in double quotes (removed);
  numbers must not be, and no field may contain the separator.
- Numbers: ``[+-]digits[.digits][e[+-]digits]``. Empty fields, text, NaN and inf are
  errors.

Column names
------------
Matched case-insensitively after every run of characters other than ``a-z`` and
``0-9`` became one ``_`` (``X Nom``, ``x-nom``, ``X.NOM`` all read as ``x_nom``).
The y and z rows follow the x rows with ``b``/``beta``/``j`` and ``c``/``gamma``/``k``
for ``a``/``alpha``/``i``.

Alias table
~~~~~~~~~~~
- ``x_nom``: x_nom, nom_x, x_nominal, nominal_x, xnom, nomx, xn
- ``y_nom``: y_nom, nom_y, y_nominal, nominal_y, ynom, nomy, yn
- ``z_nom``: z_nom, nom_z, z_nominal, nominal_z, znom, nomz, zn
- ``x_meas``: x_meas, meas_x, x_measured, measured_x, x_mes, mes_x, x_act, act_x,
  x_actual, actual_x, xmeas, measx, xact, actx, xm
- ``y_meas``: y_meas, meas_y, y_measured, measured_y, y_mes, mes_y, y_act, act_y,
  y_actual, actual_y, ymeas, measy, yact, acty, ym
- ``z_meas``: z_meas, meas_z, z_measured, measured_z, z_mes, mes_z, z_act, act_z,
  z_actual, actual_z, zmeas, measz, zact, actz, zm
- ``i``: i, nx, n_x, normal_x, cosx, cos_x, cosa, cos_a, cosalpha, cos_alpha
- ``j``: j, ny, n_y, normal_y, cosy, cos_y, cosb, cos_b, cosbeta, cos_beta
- ``k``: k, nz, n_z, normal_z, cosz, cos_z, cosc, cos_c, cosgamma, cos_gamma
- ``dev``: dev, deviation, d, t, error, err
- ``row``: row, row_index, row_idx
- ``col``: col, column, col_index, col_idx, column_index
- ``id``: id, name, point, point_id, point_name, pt, label

``x``, ``y``, ``z`` alone are not accepted (nominal or measured?), nor are deviation
components ``dx``, ``dy``, ``dz``; the error messages say so. Any other column is
ignored and reported in ``MeasurementSet.warnings``.

Units
-----
A length column (nominal, measured, deviation) may carry a unit suffix: ``dev[um]``,
``dev(um)``, ``dev_um``, ``x_nom[mm]``, ``x_nom_in`` (units: ``mm``, ``um``/``µm``/
``micron``, ``in``/``inch``, ``cm``, ``m``; see :mod:`surfcomp.io.units`). Columns without
a suffix are in the ``units`` argument (the CLI's ``--units``, default ``mm``). Normals,
row/col and id take no unit. Every array of the result is in mm.

Accepted combinations (:meth:`MeasurementSet.kind`)
---------------------------------------------------
- ``nominal+normal+deviation``: nominal point, normal and deviation along it (CMM
  reports as in Werner 2022, eq. 1).
- ``nominal+measured``: the normal and deviation are left None (the pipeline takes the
  face normal). A deviation column without a normal is then ignored (with a warning).
- ``nominal+measured+normal``: ``deviation = (measured - nominal) . normal``.
- ``all``: the file's deviation is kept and cross-checked against
  ``(measured - nominal) . normal``; a difference over 1 um is a warning per point.
Optional: ``row`` and ``col`` (both or neither) and ``id``.

Errors
------
Every problem with the file raises :class:`surfcomp.errors.MeasurementFileError`
(CLI exit code 2) with the file, 1-based line and, where it is about one field, the
1-based column: ``file:line[:column]: what is wrong (expected ...)``.
"""

import hashlib
import operator
import os
import re

import numpy as np

from ..errors import InputError, MeasurementFileError
from .columns import ALIASES, GROUP_TEXT, GROUPS, HINTS, LENGTH_ROLES, norm, role_of
from .files import clip, read_bytes
from .measurement_set import (  # noqa: F401  (MeasurementSet: the readers' result)
    _EXPECTED_COMBOS,
    DEV_CHECK_TOL,
    DUPLICATE_TOL,
    MAX_COORDINATE,
    MAX_POINT_WARNINGS,
    NORMAL_LENGTH_TOL,
    NORMAL_ZERO,
    MeasurementSet,
    check_coordinates,
    check_duplicates,
    decode_utf8,
    ignored_column_warnings,
    listed_names,
)
from .pointfile_rows import _NONFINITE, _NUMBER
from .units import UNIT_FACTORS, unit_factor

#: white space other than blanks, tabs and newlines (ASCII; str.isspace's others)
_OTHER_SPACE = "\r\x0b\x0c\x1c\x1d\x1e\x1f"
_EXPECTED_PLAN = "expected a plan: id, nominal x_nom y_nom z_nom and normal i j k"
_SEP_NAMES = {",": "','", ";": "';'", "\t": "tabs", None: "blanks"}
_UNIT_NAMES = {1.0: "mm", 1e-3: "um", 25.4: "in", 10.0: "cm", 1000.0: "m"}


def read_measurements(path, units="mm", plan=False):
    """Read a measurement file (``plan``: a measurement plan, nominal points and normals
    without deviations or measured points, as ``python3 -m surfcomp plan`` writes it).

    Parameters
    ----------
    path : str or os.PathLike
        The file (format: see the module docstring).
    units : str or None
        Unit of the length columns without a unit suffix (``mm``, ``um``, ``in``; None
        means ``mm``).

    Returns
    -------
    MeasurementSet
        Every length in mm.

    Raises
    ------
    MeasurementFileError
        The file cannot be read or is not a valid measurement file (file, line, column
        and what was expected in the message).
    """
    source = os.fspath(path)
    return parse_measurements(read_bytes(source), source=source, units=units, plan=plan)


def parse_measurements(text_or_bytes, source="<text>", units="mm", plan=False):
    """Parse the text of a measurement file.

    Parameters
    ----------
    text_or_bytes : str or bytes
        The file contents; bytes must be UTF-8 (a byte order mark is skipped). For a
        ``str``, ``sha256`` is that of its UTF-8 encoding.
    source : str
        Name used in messages and stored as ``MeasurementSet.source``.
    units : str or None
        As for :func:`read_measurements`.
    plan : bool
        Read a measurement plan: nominal points and normals are enough (no measured
        point, no deviation); :func:`surfcomp.io.plan_join.read_plan`.

    Returns a :class:`MeasurementSet` (every length in mm; formats and checks: see the
    module docstring) or raises :class:`MeasurementFileError` on the first problem, with
    file, line and (for a field) column.
    """
    try:
        default_factor = unit_factor("mm" if units is None else str(units))
    except InputError as exc:
        raise MeasurementFileError("units %r is not a known unit (expected mm, um or in)"
                                   % (units,), file=source, options=("units",)) from exc
    if isinstance(text_or_bytes, str):
        text = text_or_bytes
        raw = text.encode("utf-8", "surrogatepass")
    else:
        raw = bytes(text_or_bytes)
        text = decode_utf8(raw, source)
    if text.startswith("\ufeff"):
        text = text[1:]
    with np.errstate(over="ignore"):    # overflowing values are refused by the checks
        parser = _Parser(text, source, default_factor)
        parser.plan = plan
        return parser.run(hashlib.sha256(raw).hexdigest())


def _unquote(text):
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] == '"':
        text = text[1:-1].strip()
    return text


def _detect_separator(header):
    for sep in ("\t", ";", ","):
        if sep in header:
            return sep
    return None


def _splitter(sep):
    return str.split if sep is None else operator.methodcaller("split", sep)


def _is_number(text):
    """Whether ``text`` is a number with a decimal point or comma."""
    return bool(_NUMBER.fullmatch(text.strip().replace(",", ".")))


class _Parser:
    """One parse of one file: keeps the source lines for messages."""

    #: a measurement plan: nominal points and normals suffice
    plan = False

    def __init__(self, text, source, default_factor):
        self.source = source
        self.default_factor = default_factor
        if "\r" in text:
            text = text.replace("\r\n", "\n")
            if "\n" not in text:
                text = text.replace("\r", "\n")
        self.text = text
        self.lines = text.split("\n")
        self.warnings = []
        self.plan = False

    def error(self, message, index=None, column=None):
        """MeasurementFileError at the 0-based line ``index`` (1-based ``column``)."""
        return MeasurementFileError(message, file=self.source,
                                    line=None if index is None else index + 1, column=column)

    # -- the parse and the header ------------------------------------------------------------

    def run(self, sha256):
        lines = self.lines
        # the header first (the first line that is no comment): a file whose header
        # names no known column fails before its data rows are looked at
        h = next((k for k, ln in enumerate(lines)
                  if (s := ln.lstrip()) and not s.startswith(("#", "//"))), None)
        if h is None:
            if not any(ln.strip() for ln in lines):
                raise self.error("the file is empty (expected a header row naming the columns, "
                                 "then one row per point)")
            last = max(k for k, ln in enumerate(lines) if ln.strip())
            raise self.error("the file holds only comments and blank lines (expected a header "
                             "row naming the columns, then one row per point)", last)
        self.sep = sep = _detect_separator(lines[h])
        self.split = split = _splitter(sep)
        names = [_unquote(f) for f in split(lines[h])]
        if all(_is_number(f) for f in names):
            raise self.error("this row holds only numbers but no header came before it "
                             "(expected a header row naming the columns, e.g. "
                             "x_nom,y_nom,z_nom,i,j,k,dev)%s" % self._commented_header_hint(h), h)
        roles, factors, ignored = self._header(names, h)
        numeric = [c for c, r in roles.items() if r != "id"]
        data = self._data_rows(h)
        if not data:
            raise self.error("the header is not followed by any data row (expected one row "
                             "per point)", h)
        rows = lines[data.start:data.stop] if isinstance(data, range) else \
            [lines[k] for k in data]
        self._check_field_counts(rows, data, len(names), h)
        decimal_comma = self._decimal_comma(rows, data, numeric, names)
        values = self._numbers(rows, data, numeric, names, decimal_comma)
        col_of = {r: c for c, r in roles.items()}
        pos = {c: p for p, c in enumerate(numeric)}

        def take(role_group):
            return values[:, [pos[col_of[r]] for r in role_group]] * np.array(
                [factors[col_of[r]] for r in role_group])

        line_numbers = np.asarray(data, dtype=np.int64) + 1
        ms = MeasurementSet(lines=line_numbers, source=self.source, sha256=sha256,
                            separator=" " if sep is None else sep, decimal_comma=decimal_comma,
                            columns={r: names[col_of[r]] for r in ALIASES if r in col_of},
                            ignored_columns=[names[c] for c in ignored],
                            warnings=self.warnings)
        have = {g for g, rs in GROUPS.items() if rs[0] in col_of}
        ms.nominal = take(GROUPS["nominal"])
        check_coordinates(ms.nominal, line_numbers, self.source,
                          [col_of[r] + 1 for r in GROUPS["nominal"]])
        check_duplicates(ms.nominal, line_numbers, self.source)
        if "measured" in have:
            ms.measured = take(GROUPS["measured"])
            check_coordinates(ms.measured, line_numbers, self.source,
                              [col_of[r] + 1 for r in GROUPS["measured"]])
        if "normal" in have:
            ms.normal = self._unit_normals(values[:, [pos[col_of[r]] for r in "ijk"]], data,
                                           [col_of[r] + 1 for r in "ijk"])
        if "deviation" in have:
            ms.deviation = take(("dev",))[:, 0]
            check_coordinates(ms.deviation[:, None], line_numbers, self.source,
                              [col_of["dev"] + 1], limit=np.inf, what="deviation")
        if "grid" in have:
            ms.row = self._integers(values[:, pos[col_of["row"]]], data, col_of["row"], names)
            ms.col = self._integers(values[:, pos[col_of["col"]]], data, col_of["col"], names)
        if "id" in col_of:
            c = col_of["id"]
            ms.ids = [_unquote(split(r)[c]) for r in rows]
        if ms.measured is not None and ms.normal is not None:
            computed = np.einsum("ij,ij->i", ms.measured - ms.nominal, ms.normal)
            if ms.deviation is None:
                ms.deviation = computed
            else:
                self._check_deviation(ms.deviation, computed, data)
        used = [factors[col_of[r]] for r in LENGTH_ROLES if r in col_of]
        ms.units = _UNIT_NAMES.get(used[0], "mixed") if len(set(used)) == 1 else "mixed"
        return ms

    def _commented_header_hint(self, h):
        """Hint when the last comment line before line ``h`` names known columns."""
        for k in range(h - 1, -1, -1):
            s = self.lines[k].strip()
            if not s:
                continue
            body = s[2:] if s.startswith("//") else s.lstrip("#")
            names = [_unquote(f) for f in _splitter(_detect_separator(body))(body)]
            if any(role_of(n)[0] for n in names):
                return "; line %d looks like the header but is a comment" % (k + 1)
            return ""
        return ""

    def _header(self, names, h):
        roles, factors, ignored, first = {}, {}, [], {}
        for c, name in enumerate(names):
            role, unit, bad_unit = role_of(name)
            if role is None:
                ignored.append(c)
                continue
            if bad_unit is not None:
                raise self.error("column '%s' has the unit %r, which is not known (expected a "
                                 "suffix [mm], [um] or [in], or none)" % (name, bad_unit), h, c + 1)
            if unit is not None and role not in LENGTH_ROLES:
                raise self.error("column '%s' (%s) takes no unit (expected the name without "
                                 "the [%s] suffix)" % (name, role, unit), h, c + 1)
            if role in first:
                raise self.error("column '%s' is %s again, already given by '%s' in column %d "
                                 "(expected each column once)"
                                 % (name, role, names[first[role]], first[role] + 1), h, c + 1)
            first[role] = c
            roles[c] = role
            factors[c] = UNIT_FACTORS[unit] if unit is not None else self.default_factor
        hints = sorted({HINTS[norm(names[c])] for c in ignored if norm(names[c]) in HINTS})
        hint = "".join("; " + t for t in hints)
        if not roles:
            shown = listed_names(names)
            raise self.error("the header names no known column: %s (expected names such as "
                             "x_nom y_nom z_nom, i j k, dev, x_meas y_meas z_meas; see the alias "
                             "table)%s" % (shown, hint), h)
        for _group, rs in GROUPS.items():
            present = [r for r in rs if r in first]
            if present and len(present) < len(rs):
                missing = [r for r in rs if r not in first]
                raise self.error("the header has %s but no %s (expected all of %s, or none)"
                                 % (" ".join(present), " ".join(missing), " ".join(rs)), h)
        have = {g for g, rs in GROUPS.items() if rs[0] in first}
        need = [g for g in ("nominal", "normal", "deviation", "measured")
                if g not in have and not (g == "measured" and have >= {"normal", "deviation"})
                and not (g in ("normal", "deviation") and "measured" in have)
                and not (self.plan and g in ("deviation", "measured"))]
        if need:
            got = " and ".join(" ".join(GROUPS[g]) for g in ("nominal", "measured", "normal",
                                                             "deviation") if g in have)
            lost = listed_names([names[c] for c in ignored])
            raise self.error("the header has %sno %s (%s)%s%s"
                             % (got + " but " if got else "",
                                " and no ".join(GROUP_TEXT[g] for g in need),
                                _EXPECTED_PLAN if self.plan else _EXPECTED_COMBOS,
                                "; ignored columns: " + lost if lost else "", hint), h)
        self.warnings.extend(ignored_column_warnings(self.source, h + 1, [
            (c + 1, names[c], HINTS.get(norm(names[c]), "not a known column name")
             if names[c] else "it has no name") for c in ignored]))
        if "deviation" in have and "measured" in have and "normal" not in have:
            c = first["dev"]
            del roles[c]
            ignored = sorted(ignored + [c])
            self.warnings.append("%s:%d: column %d '%s' is ignored (without a normal i j k the "
                                 "deviation is computed from the face)"
                                 % (self.source, h + 1, c + 1, names[c]))
        return roles, factors, ignored

    # -- data -------------------------------------------------------------------------------

    def _data_rows(self, h):
        """0-based indices of the rows after the header line ``h`` that are neither blank
        (blanks and separators only) nor comments (``#``, ``//``): a ``range`` when the
        rows after the header hold neither a comment mark nor a blank row before the
        trailing ones (one scan of the text instead of a test per row, which matters for
        a million rows)."""
        lines, sep = self.lines, self.sep
        blank = " \t" + (sep or "")
        # the text after the header line (self.lines is self.text split at newlines)
        body = self.text[sum(len(ln) + 1 for ln in lines[:h + 1]):]
        # (only blanks, tabs and newlines as white space: a row of other white space,
        # such as a CR left by doubled line ends, is blank to the row by row test)
        if ("#" not in body and "//" not in body and body.isascii()
                and not any(ch in body for ch in _OTHER_SPACE)):
            body = body.rstrip(blank + "\n")
            if not body:
                return range(h + 1, h + 1)
            if lines[h + 1].strip(blank) and not re.search(r"\n[%s]*\n" % re.escape(blank),
                                                          body):
                # the last data row may end with separators that rstrip took
                return range(h + 1, h + 2 + body.count("\n"))
        data = [k for k in range(h + 1, len(lines))
                if (s := lines[k].lstrip()) and not s.startswith(("#", "//"))]
        if sep is not None:
            data = [k for k in data if lines[k].strip(blank)]
        return data

    def _check_field_counts(self, rows, data, expected, h):
        sep = self.sep
        if sep is None:
            counts = np.fromiter(map(len, map(str.split, rows)), dtype=np.int64, count=len(rows))
        else:
            counts = np.fromiter(map(operator.methodcaller("count", sep), rows), dtype=np.int64,
                                 count=len(rows)) + 1
        bad = np.flatnonzero(counts != expected)
        if bad.size:
            k = int(bad[0])
            ends = sep is not None and rows[k].rstrip().endswith(sep) and counts[k] > expected
            # 1,5 in a comma-separated row: decimal commas split each number in two
            decimal = sep == "," and 1.5 * expected <= counts[k] <= 2 * expected and not ends
            raise self.error("the row has %d fields but the header on line %d has %d (expected %d "
                             "fields separated by %s%s)"
                             % (counts[k], h + 1, expected, expected, _SEP_NAMES[sep],
                                "; the row ends with a separator" if ends else
                                "; decimal commas? between comma-separated fields numbers need "
                                "a decimal point (or separate the fields by ';' or tabs)"
                                if decimal else ""), data[k])

    def _first_row_with(self, char, rows, numeric):
        """(row index, column, field) of the first numeric field containing ``char``, or None."""
        for k, row in enumerate(rows):
            if char in row:
                fields = self.split(row)
                for c in numeric:
                    if char in fields[c]:
                        return k, c, fields[c].strip()
        return None

    def _decimal_comma(self, rows, data, numeric, names):
        if self.sep == ",":
            return False
        comma = self._first_row_with(",", rows, numeric)
        if comma is None:
            return False
        dot = self._first_row_with(".", rows, numeric)
        if dot is not None:
            k, c, text = dot
            raise self.error("'%s' in column '%s' has a decimal point but line %d has a decimal "
                             "comma ('%s') (expected one decimal mark in the whole file; "
                             "thousands separators are not accepted)"
                             % (text, names[c], data[comma[0]] + 1, comma[2]), data[k], c + 1)
        return True

    def _numbers(self, rows, data, numeric, names, decimal_comma):
        """Float array (len(rows), len(numeric)); the first bad field raises."""
        conv = [r.replace(",", ".") for r in rows] if decimal_comma else rows
        try:
            values = np.loadtxt(conv, dtype=float, delimiter=self.sep, usecols=numeric,
                                comments=None, ndmin=2)
        except ValueError as exc:
            self._locate_bad_number(conv, rows, data, numeric, names)
            raise self.error("the numbers cannot be read: %s (expected numbers)" % exc) from exc
        finite = np.isfinite(values)
        if not finite.all():
            k, p = np.argwhere(~finite)[0]
            self._locate_bad_number(conv[k:k + 1], rows[k:k + 1], data[k:k + 1],
                                    numeric[p:p + 1], names)
        return values

    def _locate_bad_number(self, conv, rows, data, numeric, names):
        """Raise for the first field of ``numeric`` columns that is not a finite number."""
        split = self.split
        for k, row in enumerate(conv):
            fields = split(row)
            for c in numeric:
                text = fields[c].strip()
                if _NUMBER.fullmatch(text):
                    continue
                shown = clip(split(rows[k])[c].strip())
                if not text:
                    what = "column '%s' is empty (expected a number)" % names[c]
                elif _NONFINITE.fullmatch(text):
                    what = ("column '%s' holds '%s' (expected a finite number; leave the row out "
                            "for a point not measured)" % (names[c], shown))
                else:
                    what = "column '%s' holds '%s' (expected a number)" % (names[c], shown)
                raise self.error(what, data[k], c + 1)
        for k, row in enumerate(conv):   # finite check: 1e999 parses as inf
            fields = split(row)
            for c in numeric:
                if not np.isfinite(float(fields[c])):
                    raise self.error("column '%s' holds '%s', which is not a finite number "
                                     "(expected a finite number)"
                                     % (names[c], clip(split(rows[k])[c].strip())), data[k],
                                     c + 1)

    def _integers(self, values, data, c, names):
        whole = np.floor(values) == values
        if not whole.all():
            k = int(np.flatnonzero(~whole)[0])
            raise self.error("column '%s' holds %r (expected a whole number: a grid index)"
                             % (names[c], float(values[k])), data[k], c + 1)
        return values.astype(np.int64)


    def _unit_normals(self, n, data, columns):
        length = np.linalg.norm(n, axis=1)
        zero = np.flatnonzero(length < NORMAL_ZERO)
        if zero.size:
            k = int(zero[0])
            raise self.error("the normal (%g, %g, %g) has zero length (expected a unit vector "
                             "i j k; %d such row(s))" % (tuple(n[k]) + (zero.size,)), data[k],
                             columns[0])
        huge = np.flatnonzero(~np.isfinite(length))
        if huge.size:
            k = int(huge[0])
            raise self.error("the normal (%g, %g, %g) is too long to be normalised (expected a "
                             "unit vector i j k)" % tuple(n[k]), data[k], columns[0])
        off = np.flatnonzero(np.abs(length - 1.0) > NORMAL_LENGTH_TOL)
        self._point_warnings(off, data, lambda k: "the normal (%g, %g, %g) has length %.6g "
                             "(expected a unit vector; used renormalised)"
                             % (tuple(n[k]) + (length[k],)),
                             "normals are not of unit length (renormalised)")
        return n / length[:, None]

    def _check_deviation(self, dev, computed, data):
        diff = np.abs(dev - computed)
        bad = np.flatnonzero(diff > DEV_CHECK_TOL)
        self._point_warnings(bad, data, lambda k: "dev %.6f mm differs from (measured - nominal) . "
                             "normal = %.6f mm by %.1f um (expected at most %g um)"
                             % (dev[k], computed[k], diff[k] * 1e3, DEV_CHECK_TOL * 1e3),
                             "deviations differ from (measured - nominal) . normal by more than "
                             "%g um" % (DEV_CHECK_TOL * 1e3))
        flipped = bad.size and np.all(np.abs(dev[bad] + computed[bad]) <= DEV_CHECK_TOL)
        if flipped and 2 * bad.size >= dev.size:
            # most rows say the opposite of their own points: whichever is right, the
            # correction would go the wrong way for one of them
            k = int(bad[0])
            raise self.error("dev %.6f mm has the opposite sign of (measured - nominal) . "
                             "normal = %.6f mm, as on %d of the %d rows (expected them to "
                             "agree within %g um: does the dev column measure along the "
                             "inward normal? Correct the file, or leave out the dev column or "
                             "the measured points)"
                             % (dev[k], computed[k], bad.size, dev.size, DEV_CHECK_TOL * 1e3),
                             data[k])
        if flipped:
            self.warnings.append("%s: the %d differing deviation(s) have the opposite sign of "
                                 "(measured - nominal) . normal: does the file measure along "
                                 "the inward normal?" % (self.source, bad.size))

    def _point_warnings(self, idx, data, text, summary):
        for k in idx[:MAX_POINT_WARNINGS]:
            self.warnings.append("%s:%d: %s" % (self.source, data[k] + 1, text(k)))
        if idx.size > MAX_POINT_WARNINGS:
            self.warnings.append("%s: %d more %s" % (self.source, idx.size - MAX_POINT_WARNINGS,
                                                     summary))

