# SPDX-License-Identifier: LGPL-2.1-or-later
"""Plausibility of measured deviations before they reach a compensation (no FreeCAD).

Two checks, shared by the command line (through :func:`surfcomp.core.pipeline.prepare`)
and the GUI's import preview:

- **max offset** (an error): a deviation larger than ``max_offset`` (default 1 mm, the
  ``--max-offset`` option and the compensation's ``MaxOffset``) is a unit or file
  mistake, not a machining error. :func:`offset_errors` names every such line.
- **size tolerance** (a warning): the *size tolerance* of a face is the general
  tolerance of ISO 2768-1, class *fine* (f), for its largest dimension (the longest
  edge of its axis-aligned bounding box): +-0.05 mm up to 6 mm, +-0.1 mm up to 30 mm,
  +-0.15 mm up to 120 mm, +-0.2 mm up to 400 mm, +-0.3 mm up to 1000 mm, +-0.5 mm
  beyond (ISO 2768-1:1989, table 1; the class stops at 2000 mm, larger faces keep
  +-0.5 mm). A file whose deviations are *all* larger than :data:`UNITS_FACTOR` times
  that tolerance describes no part that passed a machining process: its deviations are
  almost certainly in another unit. :func:`units_warning` says so.
"""

import numpy as np

#: ISO 2768-1 class f: (largest dimension up to, mm) -> permissible deviation (+- mm)
ISO2768_FINE = ((6.0, 0.05), (30.0, 0.1), (120.0, 0.15), (400.0, 0.2), (1000.0, 0.3),
                (np.inf, 0.5))
#: deviations all larger than this many size tolerances: flagged as a units mistake
UNITS_FACTOR = 100.0
#: default largest accepted deviation (mm), as ``--max-offset``
DEFAULT_MAX_OFFSET = 1.0
#: lines named one by one before "and N more"
MAX_LISTED = 20


def size_tolerance(largest_dimension):
    """ISO 2768-1 fine general tolerance (+- mm) for a dimension (mm), see module doc."""
    size = float(largest_dimension)
    for upto, tol in ISO2768_FINE:
        if size <= upto:
            return tol
    return ISO2768_FINE[-1][1]


def largest_dimension(points):
    """Longest edge (mm) of the axis-aligned bounding box of ``points`` (N, 3); NaN
    rows are ignored; 0 for no finite point."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    p = p[np.all(np.isfinite(p), axis=1)]
    if not len(p):
        return 0.0
    return float(np.max(p.max(axis=0) - p.min(axis=0)))


def offset_errors(deviation, lines=None, max_offset=DEFAULT_MAX_OFFSET, source="",
                  limit=MAX_LISTED):
    """Messages for every deviation larger than ``max_offset`` (NaN and inf too).

    Parameters
    ----------
    deviation : array_like, shape (N,)
        Deviations along the normal (mm).
    lines : array_like of int, shape (N,), optional
        Line of every point in its file (1-based); else the point number.
    max_offset : float
        Largest accepted deviation (mm).
    source : str
        File name put in front of every message (``file:line: ...``).
    limit : int
        Lines named one by one; one more message counts the rest.

    Returns
    -------
    list of str
        Empty when every deviation is plausible. The first message carries the units
        hint.
    """
    d = np.asarray(deviation, dtype=float).ravel()
    bad = np.flatnonzero(~(np.abs(d) <= max_offset))
    if not bad.size:
        return []
    where = np.asarray(lines, dtype=int).ravel() if lines is not None else np.arange(d.size) + 1
    prefix = (source + ":") if source else "line "
    out = []
    for k in bad[:limit]:
        out.append("%s%d: deviation %s mm is larger than the max offset %g mm"
                   % (prefix, where[k], "%+.4f" % d[k] if np.isfinite(d[k]) else d[k],
                      max_offset))
    if bad.size > limit:
        out.append("... and %d more point(s) larger than %g mm" % (bad.size - limit, max_offset))
    finite = np.isfinite(d[bad])
    if finite.any() and np.max(np.abs(d[bad][finite])) < 1e5 * max_offset:
        out[0] += " (%d of %d points): are the deviations in um? Choose the file's unit, or " \
                  "name the column like 'dev [um]'" % (bad.size, d.size)
    return out


def units_warning(deviation, dimension, factor=UNITS_FACTOR):
    """A warning when every finite deviation is larger than ``factor`` times the size
    tolerance of a face of ``dimension`` mm (see module doc), else None."""
    d = np.abs(np.asarray(deviation, dtype=float).ravel())
    d = d[np.isfinite(d)]
    if not d.size or dimension <= 0:
        return None
    tol = size_tolerance(dimension)
    if float(d.min()) <= factor * tol:
        return None
    return ("every deviation is larger than %g x the size tolerance of the face (ISO 2768-1 "
            "fine: +-%g mm for its largest dimension %.1f mm; smallest |deviation| %.4g mm): "
            "check the units of the file" % (factor, tol, dimension, float(d.min())))


def value_ranges(columns):
    """``{name: (min, max)}`` of the finite values of each named array (mm), for a
    preview; names whose array is None or has no finite value are left out."""
    out = {}
    for name, values in columns.items():
        if values is None:
            continue
        a = np.asarray(values, dtype=float)
        a = a[np.isfinite(a)]
        if a.size:
            out[name] = (float(a.min()), float(a.max()))
    return out
