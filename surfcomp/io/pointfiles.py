# SPDX-License-Identifier: LGPL-2.1-or-later
"""Readers for measurement files that carry measured points only (no FreeCAD).

Formats
-------
``xyz``
    Plain text, one point a line: ``x y z`` or ``x y z i j k`` (``i j k`` = probing
    direction). Optional header line naming the columns (``x y z``, ``x[mm],y[mm],z[mm]``,
    unknown columns are ignored with a warning). Separator: comma, semicolon, tab or
    spaces (one for the whole file); a decimal comma is accepted with ``;``/tab/space
    separators. ``#`` and ``//`` start comments (whole line or trailing).
``xyzijk``
    PC-DMIS "XYZIJK" text file: line 1 holds ``XYZIJK`` in columns 1-6 (capitals) and
    optionally ``METRIC`` in columns 11-16, the rest blank; without ``METRIC`` the
    values are inches. Every further line holds 3 to 8 comma-separated numbers
    ``X,Y,Z[,I,J,K[,...]]``: 3 or 6 are used, a 7th and 8th are ignored with a
    warning. (PC-DMIS itself reads this layout as nominal points to measure; here
    the points are taken as measured points.)
``probe``
    LinuxCNC probe log written between ``(PROBEOPEN file)`` and ``(PROBECLOSE)``: one
    line per ``G38.x`` probe move with nine space-separated numbers ``X Y Z A B C U V
    W``. The numbers are in the program's units (G20/G21), which the file does not
    record: ``units`` decides (default mm). They are stylus tip CENTRE positions,
    see :func:`is_tip_centre`.
``qif``
    QIF 3.0 measurement results, read by :mod:`surfcomp.io.qif`.

Every reader returns a :class:`surfcomp.io.measurements.MeasurementSet` in mm. For the
point-only formats ``measured`` is set, ``nominal`` and ``deviation`` are None (the
projection engine computes them) and ``normal`` is the probing direction from the
file (unit length), or None.

Bad input raises :class:`surfcomp.errors.MeasurementFileError` with the file, the
1-based line and the 1-based character column.
"""

import hashlib
import re

import numpy as np

from ..errors import InputError, MeasurementFileError, note
from .files import read_bytes
from .measurement_set import (
    NORMAL_LENGTH_TOL,
    NORMAL_ZERO,
    MeasurementSet,
    check_coordinates,
    check_duplicates,
    decode_utf8,
)
from .pointfile_rows import (
    _field_counts,
    _fields,
    _is_number,
    _parse_rows,
    _raise_field_count,
    _Rows,
    _split_lines,
    _strip_comment,
)
from .units import split_unit_suffix, unit_factor

#: formats :func:`read_point_file` reads
FORMATS = ("xyz", "xyzijk", "probe", "qif")

#: header names (lower case, unit suffix removed) -> column role of plain XYZ files
_HEADER_ROLES = {
    "x": "x", "y": "y", "z": "z",
    "i": "i", "j": "j", "k": "k",
    "nx": "i", "ny": "j", "nz": "k",
}


#: internal column roles -> roles of ``MeasurementSet.columns``
_ROLE_NAMES = {"x": "x_meas", "y": "y_meas", "z": "z_meas", "i": "i", "j": "j", "k": "k"}

_PROBE_AXES = ("x", "y", "z", "a", "b", "c", "u", "v", "w")

#: factor to mm -> unit name stored in ``MeasurementSet.units``
_UNIT_NAMES = {1.0: "mm", 1e-3: "um", 25.4: "in", 10.0: "cm", 1000.0: "m"}


# --------------------------------------------------------------------------- text input

def _unit_directions(path, ijk, line_numbers, warnings):
    """Normalise probing directions (N, 3); zero vectors raise, others warn if not unit."""
    length = np.linalg.norm(ijk, axis=1)
    zero = length < NORMAL_ZERO
    if zero.any():
        k = int(np.argmax(zero))
        raise MeasurementFileError("the direction vector i j k is zero; expected a unit vector",
                                   file=str(path), line=int(line_numbers[k]))
    huge = ~np.isfinite(length)
    if huge.any():
        k = int(np.argmax(huge))
        raise MeasurementFileError("the direction vector i j k is too long to be normalised; "
                                   "expected a unit vector", file=str(path),
                                   line=int(line_numbers[k]))
    off = np.abs(length - 1.0)
    if off.max() > NORMAL_LENGTH_TOL:
        k = int(np.argmax(off > NORMAL_LENGTH_TOL))
        warnings.append((int(line_numbers[k]),
                         "%d direction vector(s) i j k are not of unit length (this line first; "
                         "largest |length - 1| = %.3g); used normalised"
                         % (int((off > NORMAL_LENGTH_TOL).sum()), off.max())))
    return ijk / length[:, None]


def _resolve_units(units, file_units, warnings=None, line=0):
    """Unit name and factor to mm: the file's own units win, else ``units``, else mm.

    As for the unit suffixes of :mod:`surfcomp.io.measurements`, ``units`` is the unit
    of values that carry none of their own; a different explicit ``units`` is reported
    in ``warnings`` (a list of (line, message)) rather than silently dropped.
    """
    if (warnings is not None and units is not None and file_units is not None
            and unit_factor(units) != unit_factor(file_units)):
        warnings.append((line, note("the file states its units (%s); " % file_units,
                                    ("units",), " %s applies only to values without units of "
                                    "their own, so the file's units are used" % units)))
    name = file_units if file_units is not None else ("mm" if units is None else units)
    factor = unit_factor(name)
    return _UNIT_NAMES.get(factor, name.strip().lower()), factor


# --------------------------------------------------------------------------- detection

def detect_format(path):
    """Tell the format of a measured-points file from its content.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    str
        ``"qif"`` if the file starts with XML markup, ``"xyzijk"`` if line 1 starts
        with ``XYZIJK`` (any case, so that the reader can say what is wrong),
        ``"probe"`` if the first non-blank line holds nine numbers separated by white
        space (plain XYZ files have 3 or 6 fields), else ``"xyz"``.

    Raises
    ------
    MeasurementFileError
        If the file cannot be read or is empty.
    """
    with_path = str(path)
    head = read_bytes(path, limit=1 << 16)
    text = head.decode("utf-8-sig", errors="replace")
    if not text.strip():
        raise MeasurementFileError("the file is empty; expected measured points",
                                   file=with_path)
    if text.lstrip().startswith("<"):
        return "qif"
    lines = _split_lines(text)
    if len(head) == (1 << 16) and len(lines) > 1:
        lines = lines[:-1]      # the last line may be cut
    if lines[0][:6].upper() == "XYZIJK":
        return "xyzijk"
    first = next((t for t in lines if t.strip()), "")
    toks = first.split()
    if len(toks) == 9 and all(_is_number(x) for x in toks):
        return "probe"
    return "xyz"


def is_tip_centre(fmt):
    """True if points of format ``fmt`` are stylus tip centres, not contact points.

    LinuxCNC probe logs record the controlled point (the tip centre of a calibrated
    ball stylus) at the moment the probe triggered; the core's tip-radius
    compensation offsets them by the tip radius along the surface normal. CMM
    exports (XYZIJK, QIF) and plain XYZ files are taken as compensated surface
    points.

    Parameters
    ----------
    fmt : str
        One of :data:`FORMATS`.
    """
    if fmt not in FORMATS:
        raise InputError("unknown point file format %r (expected one of %s)"
                         % (fmt, ", ".join(FORMATS)))
    return fmt == "probe"


# --------------------------------------------------------------------------- readers

def read_point_file(path, fmt="auto", units=None, sample=None):
    """Read a file of measured points (plain XYZ, PC-DMIS XYZIJK, LinuxCNC probe log, QIF).

    Parameters
    ----------
    path : str or os.PathLike
    fmt : {"auto", "xyz", "xyzijk", "probe", "qif"}
        ``auto`` uses :func:`detect_format`.
    units : str, optional
        Length unit of values that carry no unit of their own (``mm``, ``in``,
        ``um``...; default mm): probe logs of G20 programs need ``in``. Units a file
        states win: the XYZIJK header (METRIC or inch), QIF FileUnits, unit suffixes
        in a plain XYZ header (``x[in]``).
    sample : int or str, optional
        QIF only: which MeasurementResults to read (0-based index, serial number or
        MeasurementResults id); default the first.

    Returns
    -------
    MeasurementSet
        Coordinates in mm. Point-only formats: ``measured`` (N, 3), ``normal`` (N, 3)
        unit probing direction or None, ``nominal``/``deviation`` None. QIF: nominal,
        measured, normal and deviation (see :func:`surfcomp.io.qif.read_qif`).

    Raises
    ------
    MeasurementFileError
        Empty file, malformed numbers, wrong field counts, NaN/inf, malformed
        XYZIJK header, bad QIF (file, line, column).
    InputError
        Unknown ``fmt`` or ``units``, ``sample`` for a format without samples.
    """
    if fmt == "auto":
        fmt = detect_format(path)
    if fmt not in FORMATS:
        raise InputError("unknown point file format %r (expected auto or one of %s)"
                         % (fmt, ", ".join(FORMATS)))
    if units is not None:
        unit_factor(units)
    if fmt == "qif":
        from .qif import read_qif
        return read_qif(path, sample=sample, units=units)
    if sample is not None:
        raise InputError("sample=%r applies to QIF files only, this is a %s file" % (sample, fmt),
                         file=str(path))
    data = read_bytes(path)
    warnings = []
    text = decode_utf8(data, str(path))
    if not text.strip():
        raise MeasurementFileError("the file is empty; expected measured points",
                                   file=str(path))
    lines = _split_lines(text)
    reader = {"xyz": _read_xyz, "xyzijk": _read_xyzijk, "probe": _read_probe}[fmt]
    with np.errstate(over="ignore"):    # overflowing values are refused by the checks
        fields = reader(path, lines, units, warnings)
    check_coordinates(fields["measured"], fields["lines"], str(path))
    check_duplicates(fields["measured"], fields["lines"], str(path), "measured point")
    fields["columns"] = {_ROLE_NAMES[r]: name for r, name in fields["columns"].items()}
    source = str(path)
    texts = [("%s:%d: " % (source, line) if line is not None else "%s: " % source) + text
             for line, text in warnings]       # (a Note stays one)
    return MeasurementSet(nominal=None, deviation=None, row=None, col=None, ids=None,
                          source=source, sha256=hashlib.sha256(data).hexdigest(),
                          warnings=texts, tip_centres=is_tip_centre(fmt), **fields)


def _plain_columns(path, rows, sep):
    """Columns of a headerless XYZ file: x y z or x y z i j k by the field count."""
    nf = len(_fields(rows[0][1], sep))
    if nf not in (3, 6):
        raise MeasurementFileError(
            "wrong field count: %d fields, expected 3 (x y z) or 6 (x y z i j k); "
            "add a header line naming the columns to read other layouts" % nf,
            file=str(path), line=rows[0][0])
    names = list("xyz" if nf == 3 else "xyzijk")
    roles = {r: k for k, r in enumerate(names)}
    columns = {r: "column %d" % (k + 1) for k, r in enumerate(names)}
    return names, roles, columns, None


def _header_columns(path, header, sep, warnings):
    """Columns named by an XYZ file's header line (with unit suffixes)."""
    hline, htext = header
    hfields = _fields(htext, sep)
    names, roles, columns, col_units, ignored = [], {}, {}, {}, []
    for k, (name, col) in enumerate(hfields):
        base, unit = split_unit_suffix(name)
        role = _HEADER_ROLES.get(base.lower())
        names.append(name)
        if role is None:
            ignored.append(name)
            continue
        if role in roles:
            raise MeasurementFileError("column %r repeats %r; each of x y z i j k may "
                                       "appear once" % (name, columns[role]),
                                       file=str(path), line=hline, column=col)
        roles[role] = k
        columns[role] = name
        if unit is not None and role in "xyz":
            col_units[name] = unit
    missing = [r for r in "xyz" if r not in roles]
    if missing:
        raise MeasurementFileError(
            "line %d is not numeric, so it was read as a header, but it names no %s "
            "column (found %s); expected a header such as 'x y z' or 'x y z i j k', or "
            "numbers only" % (hline, ", ".join(missing),
                              ", ".join(repr(f) for f, _ in hfields)),
            file=str(path), line=hline, column=1)
    dirs = [r for r in "ijk" if r in roles]
    if dirs and len(dirs) != 3:
        raise MeasurementFileError("the header names %s but not all of i, j, k"
                                   % ", ".join(dirs), file=str(path), line=hline, column=1)
    file_units = None
    if col_units:
        if len({unit_factor(u) for u in col_units.values()}) > 1:
            raise MeasurementFileError("the x, y, z columns have different units: %s"
                                       % ", ".join(col_units), file=str(path), line=hline)
        file_units = next(iter(col_units.values()))
    if ignored:
        warnings.append((hline, "columns ignored (not x y z i j k): %s" % ", ".join(ignored)))
    return names, roles, columns, file_units


def _read_xyz(path, lines, units, warnings):
    """Plain XYZ text; see the module docstring."""
    joined = "\n".join(lines)
    if "#" in joined or "//" in joined:
        lines = [_strip_comment(t) if ("#" in t or "//" in t) else t for t in lines]
    rows = _Rows.nonblank(lines)
    if not len(rows):
        raise MeasurementFileError("the file holds only comments and blank lines; expected "
                                   "measured points x y z", file=str(path))

    header = None
    first_toks = [x for x in re.split(r"[,;\s]+", rows[0][1].strip()) if x]
    if not all(_is_number(x) for x in first_toks):
        header = rows[0]
        rows = rows[1:]
        if not len(rows):
            raise MeasurementFileError("line %d is not numeric and was read as a header, "
                                       "but no points follow it; expected lines of x y z"
                                       % header[0], file=str(path), line=header[0])
    sep = _guess_separator(rows[0])
    decimal_comma = sep != "," and "," in "\n".join(rows.texts)
    sep_label = sep if sep is not None else ("\t" if "\t" in rows[0][1] else " ")

    if header is None:
        names, roles, columns, file_units = _plain_columns(path, rows, sep)
    else:
        names, roles, columns, file_units = _header_columns(path, header, sep, warnings)
    used = set(roles.values())
    ignored = [name for k, name in enumerate(names) if k not in used]
    ncols = len(names)
    expected = "%d (%s)" % (ncols, " ".join(names))
    usecols = sorted(roles.values())
    arr = _parse_rows(path, rows, sep, decimal_comma, ncols, names, expected, usecols)
    pos = {r: usecols.index(k) for r, k in roles.items()}
    unit_name, factor = _resolve_units(units, file_units, warnings, header[0] if header else 0)
    measured = arr[:, [pos["x"], pos["y"], pos["z"]]] * factor
    normal = None
    if "i" in roles:
        normal = _unit_directions(path, arr[:, [pos["i"], pos["j"], pos["k"]]],
                                  rows.numbers, warnings)
    return dict(measured=measured, normal=normal, lines=rows.numbers, units=unit_name,
                columns=columns, ignored_columns=ignored, separator=sep_label,
                decimal_comma=decimal_comma)


def _guess_separator(row):
    """Field separator of a plain XYZ file (None = white space) from its first data line.

    ``;`` wins; a comma separates fields if it splits the line into numbers, else it is
    taken as a decimal comma between white-space separated fields.
    """
    text = row[1]
    if ";" in text:
        return ";"
    if "," in text:
        parts = [p.strip() for p in text.split(",")]
        if all(p and _is_number(p) for p in parts):
            return ","
        if all(_is_number(t.replace(",", ".")) for t in text.split()):
            return None
        return ","      # the field check reports the malformed field
    return None


def _read_xyzijk(path, lines, units, warnings):
    """PC-DMIS XYZIJK text; see the module docstring."""
    head = lines[0]
    if head[:6] != "XYZIJK":
        raise MeasurementFileError("line 1 must hold XYZIJK (capital letters) in columns 1-6, "
                                   "found %r" % head[:6], file=str(path), line=1, column=1)
    if not head[6:].strip():
        file_units = "in"
    elif head[10:16] == "METRIC" and not head[6:10].strip() and not head[16:].strip():
        file_units = "mm"
    else:
        found = head[6:].strip()
        col = 7 + (len(head[6:]) - len(head[6:].lstrip()))
        raise MeasurementFileError(
            "malformed XYZIJK header: found %r at column %d; expected METRIC in columns "
            "11-16 (metric data) or nothing after XYZIJK (inch data)" % (found, col),
            file=str(path), line=1, column=col)
    rows = _Rows.nonblank(lines[1:], first=2)
    if not len(rows):
        raise MeasurementFileError("the XYZIJK file holds no points after its header line",
                                   file=str(path), line=1)
    names = ["X", "Y", "Z", "I", "J", "K", "field 7", "field 8"]
    counts = _field_counts(rows, ",")
    allowed = "3 (X,Y,Z) or 6 (X,Y,Z,I,J,K) comma-separated numbers, at most 8"
    bad = (counts < 3) | (counts > 8) | (counts == 4) | (counts == 5)
    if bad.any():
        k = int(np.argmax(bad))
        _raise_field_count(path, rows[k], ",", int(counts[k]), {3, 6, 7, 8}, allowed)
    with_dir = counts >= 6
    if with_dir.any() and not with_dir.all():
        k = int(np.argmax(with_dir != with_dir[0]))
        raise MeasurementFileError(
            "wrong field count: %d numbers, but line %d has %d; all lines must have X,Y,Z or "
            "all X,Y,Z,I,J,K" % (counts[k], rows[0][0], counts[0]),
            file=str(path), line=rows[k][0])
    extra = counts > 6
    if extra.any():
        warnings.append((rows[int(np.argmax(extra))][0],
                         "%d line(s) hold more than 6 numbers (this line first); fields 7-8 "
                         "are ignored" % int(extra.sum())))
        rows = _Rows(rows.numbers, [",".join(t.split(",")[:6]) if c > 6 else t
                                    for t, c in zip(rows.texts, counts.tolist())])
    ncols = 6 if with_dir[0] else 3
    arr = _parse_rows(path, rows, ",", False, ncols, names, allowed)
    unit_name, factor = _resolve_units(units, file_units, warnings, 2)
    normal = None
    columns = {r: "column %d" % (k + 1) for k, r in enumerate("xyz")}
    if ncols == 6:
        normal = _unit_directions(path, arr[:, 3:6], rows.numbers, warnings)
        columns.update({r: "column %d" % (k + 4) for k, r in enumerate("ijk")})
    ignored = ["field 7", "field 8"][:max(0, int(counts.max()) - 6)]
    return dict(measured=arr[:, :3] * factor, normal=normal, lines=rows.numbers,
                units=unit_name, columns=columns, ignored_columns=ignored, separator=",",
                decimal_comma=False)


def _read_probe(path, lines, units, warnings):
    """LinuxCNC PROBEOPEN log; see the module docstring."""
    rows = _Rows.nonblank(lines)
    if not len(rows):
        raise MeasurementFileError("the probe log holds no points", file=str(path))
    names = [a.upper() for a in _PROBE_AXES]
    expected = "9 (X Y Z A B C U V W)"
    arr = _parse_rows(path, rows, None, False, 9, names, expected)
    if units is None:
        warnings.append((None, "probe logs do not record their units; read as mm (G21), "
                               "give units='in' for G20 programs"))
    unit_name, factor = _resolve_units(units, None)
    moved = [names[k] for k in range(3, 9) if np.any(arr[:, k] != 0.0)]
    if moved:
        warnings.append((None, "axes %s are not zero in the probe log; only X Y Z are used"
                               % " ".join(moved)))
    return dict(measured=arr[:, :3] * factor, normal=None, lines=rows.numbers,
                units=unit_name, columns={"x": "X", "y": "Y", "z": "Z"},
                ignored_columns=[a.upper() for a in _PROBE_AXES[3:]], separator=" ",
                decimal_comma=False)
