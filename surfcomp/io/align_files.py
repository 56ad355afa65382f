# SPDX-License-Identifier: LGPL-2.1-or-later
"""The alignment's small input files (no FreeCAD): a known transform and a 3-2-1 set.

Transform file (``--transform``), one of:

* JSON ``{"matrix": [[r11, r12, r13, tx], [..], [..], [0, 0, 0, 1]]}`` (4 x 4, row-major,
  mapping measured points to the nominal's frame);
* JSON ``{"translation": [x, y, z], "rotation_z_deg": a}``: a machine work offset, rotation
  about Z first, then the translation (mm);
* text: 4 rows of 4 numbers (or 3 rows, the last row ``0 0 0 1`` implied), separated by
  blanks or commas; ``#`` starts a comment.

3-2-1 set (``--rps``): a JSON file ``{"primary": [3 ids], "secondary": [2 ids],
"tertiary": [1 id]}`` (a group may be ``{"points": [...], "face": "Face2"}``), or the ids
inline, groups separated by ``;``: ``"P1,P2,P3;P4,P5;P6"``. Ids are the measurement
file's point ids, or 1-based point numbers when it has none.

Face column: a plain point file (``x y z face``) may name the reference face of every
point (:func:`face_column`).
"""

import json
import os

import numpy as np

from ..errors import InputError
from .files import read_bytes

#: largest alignment file (bytes): a matrix or six ids
MAX_BYTES = 1 << 16


def _text(path):
    data = read_bytes(path, "the alignment file", InputError, MAX_BYTES + 1)
    if len(data) > MAX_BYTES:
        raise InputError("larger than %d bytes (expected a transform or a 3-2-1 set)"
                         % MAX_BYTES, file=path)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError("not UTF-8 text (expected a transform or a 3-2-1 set)",
                         file=path) from None


def read_transform(path):
    """The 4 x 4 matrix of a transform file (see the module docstring); not yet checked
    for rigidity (:func:`surfcomp.core.measurement.align.check_rigid` does that)."""
    text = _text(path)
    if text.lstrip().startswith("{"):
        try:
            data = json.loads(text)
        except ValueError as exc:
            raise InputError("not valid JSON: %s" % exc, file=path) from None
        return _from_json(data, path)
    rows = []
    for k, line in enumerate(text.splitlines(), 1):
        line = line.split("#", 1)[0].replace(",", " ").split()
        if not line:
            continue
        try:
            rows.append([float(x) for x in line])
        except ValueError:
            raise InputError("expected numbers, got %r" % " ".join(line), file=path,
                             line=k) from None
        if len(rows[-1]) != 4:
            raise InputError("a matrix row has %d numbers (expected 4)" % len(rows[-1]),
                             file=path, line=k)
    if len(rows) == 3:
        rows.append([0.0, 0.0, 0.0, 1.0])
    if len(rows) != 4:
        raise InputError("%d matrix rows (expected 4 rows of 4 numbers, or 3)" % len(rows),
                         file=path)
    return np.array(rows)


def _from_json(data, path):
    from ..core.measurement.align import work_offset

    if isinstance(data, dict) and "matrix" in data:
        M = data["matrix"]
        ok = (isinstance(M, list) and len(M) in (3, 4)
              and all(isinstance(r, list) and len(r) == 4 for r in M))
        try:
            M = np.array(M, dtype=float) if ok else None
        except (TypeError, ValueError):
            M = None
        if M is None:
            raise InputError("\"matrix\": expected 4 rows of 4 numbers", file=path)
        return M if M.shape[0] == 4 else np.vstack([M, [0.0, 0.0, 0.0, 1.0]])
    if isinstance(data, dict) and "translation" in data:
        t, a = data["translation"], data.get("rotation_z_deg", 0.0)
        try:
            t = np.array(t, dtype=float)
            a = float(a)
        except (TypeError, ValueError):
            t = None
        if t is None or t.shape != (3,) or not np.isfinite(t).all() or not np.isfinite(a):
            raise InputError("a work offset needs \"translation\": [x, y, z] and optionally "
                             "\"rotation_z_deg\": a number", file=path)
        return work_offset(t, a)
    raise InputError("expected {\"matrix\": [[...] x 4]} or {\"translation\": [x, y, z], "
                     "\"rotation_z_deg\": a}", file=path)


def read_rps(value):
    """The 3-2-1 groups of ``value``: a JSON file's object, or inline ids
    ``"a,b,c;d,e;f"``. Returns ``(groups dict, source name for messages)``."""
    if os.path.isfile(value):
        try:
            data = json.loads(_text(value))
        except ValueError as exc:
            raise InputError("not valid JSON: %s" % exc, file=value) from None
        return data, value
    parts = [p.strip() for p in str(value).split(";")]
    if len(parts) != 3 or not all(parts):
        raise InputError("rps %r: expected a JSON file or three groups of point ids "
                         "separated by ';' (3, 2 and 1 ids, e.g. P1,P2,P3;P4,P5;P6)" % value,
                         options=("rps",))
    names = ("primary", "secondary", "tertiary")
    return {n: [x.strip() for x in p.split(",")] for n, p in zip(names, parts)}, "--rps"


def face_column(ms):
    """The face each point names in a ``face`` column of a plain point file (the readers
    leave that column aside as not numeric), or None when the file has none.

    Returns
    -------
    list of str (one per point, in file order) or None
    """
    names = [c.strip().lower() for c in ms.ignored_columns]
    if "face" not in names or ms.nominal is not None:
        return None
    data = read_bytes(ms.source, "the measurement file", InputError)
    lines = data.decode("utf-8-sig", errors="replace").splitlines()
    split = _splitter(ms.separator)
    first = int(ms.lines[0]) - 1
    header = next(k for k in range(first - 1, -1, -1)
                  if lines[k].split("#", 1)[0].split("//", 1)[0].strip())
    head = [f.strip().strip('"').lower() for f in split(_bare(lines[header]))]
    col = head.index("face")
    out = []
    for line in ms.lines:
        fields = split(_bare(lines[int(line) - 1]))
        if col >= len(fields) or not fields[col].strip().strip('"'):
            raise InputError("no face named in the face column", file=ms.source,
                             line=int(line), column=col + 1)
        out.append(fields[col].strip().strip('"'))
    return out


def _bare(line):
    return line.split("#", 1)[0].split("//", 1)[0].strip()


def _splitter(sep):
    if sep in (" ", "\t", None):
        return lambda s: s.split()
    return lambda s: s.split(sep)
