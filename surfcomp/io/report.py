# SPDX-License-Identifier: LGPL-2.1-or-later
"""The JSON report of a compensation or inspection (schema in README.md, "JSON report").

Pure: takes core results and plain input descriptions, returns JSON-able dicts.
"""

import datetime
import json

import numpy as np

from .. import __version__
from ..core.compensation import plausibility

SCHEMA = "surfcomp-report/1"


def _rounded(a, digits=9):
    """``a`` rounded to ``digits`` decimals (an array); values too large to round (the
    rounding multiplies by 10**digits, which overflows from about 1e296) are kept as they
    are."""
    a = np.asarray(a, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        r = np.round(a, digits)
    return np.where(np.isfinite(r) | ~np.isfinite(a), r, a)


def _list(a, digits=9):
    """:func:`_rounded` as a list."""
    return _rounded(a, digits).tolist()


def _stock_check(deviation, options):
    """The mirror stock against the measured mean (mm), None for other methods."""
    if options.method != "mirror" or options.stock is None:
        return None
    c = plausibility.stock_check(deviation, options.stock)
    return {"mean_mm": c.mean, "spread_mm": c.spread, "tolerance_mm": c.tolerance,
            "consistent": c.consistent, "accepted": bool(options.accept_stock)}


def build_report(command, inputs, comp, warnings=(), outputs=None, points=True,
                 output_shape=None):
    """Assemble the report dict.

    Parameters
    ----------
    command : {'compensate', 'inspect'}
    inputs : dict
        ``{'nominal': {...}, 'measurements': {...}}`` with paths and SHA-256.
    comp : surfcomp.core.compensation.pipeline.Compensation
    warnings : list of str
    outputs : dict, optional
        Paths of the files written.
    points : bool
        Include the per-point arrays (``points``); without them the report is the
        summary (the CLI's printout needs no more; a million points take seconds).
    output_shape : dict, optional
        What the written shape is (``kind`` face or shape, faces, solids, edge tolerance,
        the correction's integral and the solid's volume change, re-trimmed faces).
    """
    p, c, o = comp.prepared, comp.correction, comp.options
    g = p.grid
    row, col = p.row_col()
    out = {
        "schema": SCHEMA,
        "surfcomp_version": __version__,
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": command,
        "units": "mm",
        "inputs": inputs,
        "method": {
            "name": o.method,
            "mask": None if c.mask is None else _list(c.mask, 12),
            "mask_size": None if c.mask is None else int(c.mask.shape[0]),
            "mask_kind": "custom" if o.weights is not None else o.mask_kind,
            "edge": o.edge,
            "stock_mm": o.stock,
            "stock_check": _stock_check(p.deviation, o),
            "residual_assumes": plausibility.residual_assumption(o.method, o.stock) or None,
            "refine": o.refine,
            "tip_radius_mm": o.tip_radius,
        },
        "grid": {"shape": list(g.shape), "found_from": g.rows_from,
                 "layout": "scattered" if p.scattered else "grid",
                 "axes": ("points in file order" if p.scattered else
                          "row = first grid index (along u), col = second (along v)")},
        "statistics": {k: v.as_dict() for k, v in comp.statistics.items()},
        "statistics_ddof": 1,
        # numpy arrays, written in parts by :func:`write` (the lists of a million points
        # would take gigabytes, their JSON text as much again)
        "points": None if not points else {
            "line": np.asarray(p.lines, dtype=np.int64),
            "row": None if row is None else np.asarray(row, dtype=np.int64),
            "col": None if col is None else np.asarray(col, dtype=np.int64),
            "u": _rounded(p.u, 12),
            "v": _rounded(p.v, 12),
            "nominal": _rounded(p.nominal),
            "normal": _rounded(p.normal, 12),
            "deviation": _rounded(p.deviation),
            "determined": _rounded(comp.per_point("determined")),
            "random": _rounded(comp.per_point("random")),
            "correction": _rounded(comp.per_point("delta")),
            "corrected": _rounded(comp.corrected_points()),
        },
        "warnings": list(warnings),
    }
    if comp.fit is not None:
        out["scattered_fit"] = comp.fit.as_dict()
    if comp.checks is not None:
        out["corrected_face"] = comp.checks.as_dict()
        out["corrected_face"]["degree"] = [comp.corrected.degree_u, comp.corrected.degree_v]
        out["corrected_face"]["rational"] = comp.corrected.weights is not None
    if output_shape is not None:
        out["output_shape"] = output_shape
    if outputs:
        out["outputs"] = outputs
    return out


#: points per piece of an array written by :func:`write`
CHUNK = 65536
_HOLE = "\u0000surfcomp-points\u0000"


def json_values(obj):
    """``obj`` with every float that is not finite (nan, inf) as None: JSON has no such
    numbers (Python's ``NaN`` is refused by strict readers), ``null`` is "no value"."""
    if isinstance(obj, float):
        return obj if np.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: json_values(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_values(v) for v in obj]
    return obj


def _rows(a):
    """The rows of array ``a`` as lists, None where a float is not finite."""
    if a.dtype.kind == "f" and not np.isfinite(a).all():
        b = a.astype(object)
        b[~np.isfinite(a)] = None
        return b.tolist()
    return a.tolist()


def _array_json(a, fh):
    """Write array ``a`` as a JSON list (of lists for 2-D), ``CHUNK`` rows a line."""
    fh.write("[")
    for k in range(0, a.shape[0], CHUNK):
        text = json.dumps(_rows(a[k:k + CHUNK]), allow_nan=False)
        fh.write(("\n  " if k == 0 else ",\n  ") + text[1:-1])
    fh.write("\n ]" if a.shape[0] else "]")


def write(report, fh):
    """Write ``report`` as JSON text to the text stream ``fh``: the dict indented, the
    per-point arrays (numpy) in parts, so the memory needed stays that of one part
    whatever the number of points; a value that is not a finite number is ``null``."""
    pts = report.get("points")
    text = json.dumps(json_values(dict(report, points=_HOLE if pts is not None else None)),
                      indent=1, sort_keys=False, allow_nan=False)
    if pts is None:
        fh.write(text + "\n")
        return
    head, tail = text.split(json.dumps(_HOLE), 1)
    fh.write(head + "{")
    for k, (key, value) in enumerate(pts.items()):
        fh.write(("\n  " if k == 0 else ",\n  ") + json.dumps(key) + ": ")
        if value is None:
            fh.write("null")
        else:
            _array_json(np.asarray(value), fh)
    fh.write("\n }" + tail + "\n")


def write_file(report, path):
    """:func:`write` to the file ``path`` (UTF-8)."""
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        write(report, fh)


def dumps(report):
    """The report as JSON text (:func:`write`)."""
    import io

    buf = io.StringIO()
    write(report, buf)
    return buf.getvalue()
