# SPDX-License-Identifier: LGPL-2.1-or-later
"""Plausibility of measured deviations before they reach a compensation (no FreeCAD).

Two checks, shared by the command line (through :func:`surfcomp.core.compensation.pipeline.prepare`)
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
- **length unit** (an error): points that cover only a small part of the face (under
  :data:`SMALL_SPAN` of its extent) but lie on it once multiplied by 25.4, 10 or 1000 are
  in inches, centimetres or metres, not millimetres: near the origin such points still
  pass the on-face check, and compensating them would build the face from a corner
  (:func:`unit_mistake`).
- **nominal points on the face** (an error, or a warning for small offsets): a file's nominal
  points are the CAD face's own, so one farther than
  :data:`surfcomp.core.limits.NOMINAL_OFF_FACE` from the face belongs to another face,
  model revision or frame, and the deviations against it are not deviations of this face
  (:func:`nominal_off_face`).
- **pairs** (an error, or a warning for a few points): a CMM probes each point along its
  nominal normal, so the measured point lies on that normal; one farther beside it than
  :data:`surfcomp.core.limits.PAIRING_SHARE` of the distance to the next nominal point
  (or than ``max_offset``) lies nearer another nominal point: the file's measured column
  is shifted or sorted apart from its nominal column (:func:`unpaired`).
- **mirror stock** (refused unless confirmed): the mirror method measures the part after
  a semi-finishing pass that left the stock ``s``, so in surfcomp's sign convention
  (deviation along the outward normal, + = material left) every measured deviation is
  ``d = s + e`` with ``e`` the semi-finishing error (Huang et al. 2019, Sec. 2.4; the
  mirror surface lies at ``s/2``, half-way between the ideal semi-finished and finished
  surfaces). The measured mean is therefore expected near ``s``, not near ``s/2``
  (``mean - s/2`` is the mean distance from the mirror surface, ``s/2 + mean(e)`` for a
  right stock). :func:`stock_check` calls a stock *inconsistent* when the mean deviation
  lies farther from ``s`` than the larger of ``s/2`` (beyond the mirror surface: nearer
  the finished than the semi-finished surface, or as far on the other side) and
  :data:`STOCK_SPREADS` times the spread (sample standard deviation) of the
  deviations (small stocks, where the error is as large as the stock). The paper's
  semi-finished parts (stock 0.2 mm, mean error 15.1-17.2 um, spread 3.1-6.2 um, Tab. 3)
  pass; a finished part (mean 15.7 um, spread 19.1 um) with the default stock 0.1 mm
  does not: its face would move out by up to 0.13 mm.
"""

from dataclasses import dataclass

import numpy as np

from ...errors import MeasurementFileError, note
from ..limits import NOMINAL_OFF_FACE, NOMINAL_OFF_FACE_WARNING, PAIRING_SHARE
from ..option_tables import INPUTS
from ..options import OPTIONS
from ..surface.kdtree import cKDTree

#: ISO 2768-1 class f: (largest dimension up to, mm) -> permissible deviation (+- mm)
ISO2768_FINE = ((6.0, 0.05), (30.0, 0.1), (120.0, 0.15), (400.0, 0.2), (1000.0, 0.3),
                (np.inf, 0.5))
#: deviations all larger than this many size tolerances: flagged as a units mistake
UNITS_FACTOR = 100.0
#: deviations all smaller than this (mm) are below what a CMM or a probe resolves: flagged
#: as deviations in mm read as um
TINY_DEVIATION = 5e-4
#: default largest accepted deviation (mm): the option registry's ``max_offset``
DEFAULT_MAX_OFFSET = OPTIONS["max_offset"].default
#: lines named one by one before "and N more"
MAX_LISTED = 20
#: a stock is consistent while the mean deviation is within this many spreads of it
#: (or within half the stock, whichever is larger)
STOCK_SPREADS = 3.0


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


#: length units a file's coordinates can be in: name -> (factor to mm, name in messages)
LENGTH_UNITS = {"mm": (1.0, "mm"), "um": (1e-3, "um"), "in": (25.4, "inches"),
                "cm": (10.0, "cm"), "m": (1000.0, "metres")}
#: the factors by which coordinates read in the wrong unit are too small (inches, cm or
#: metres read as mm; mm read as um ...)
UNIT_SCALES = (25.4, 10.0, 1000.0)
#: points spanning less than this share of the face's extent are checked for another unit
SMALL_SPAN = 0.1
#: the share of the points that must lie on the face once scaled to call it a unit mistake
ON_FACE_SHARE = 0.9


def face_samples(surface, n=9):
    """Points of the face on an ``n`` x ``n`` grid of its parameters, (n * n, 3): its extent
    for the checks here."""
    from ..surface import bspline

    return bspline.evaluate_grid(surface, np.linspace(*surface.u_range, n),
                                 np.linspace(*surface.v_range, n)).reshape(-1, 3)


def unit_mistake(surface, points, max_offset, project, read_as="mm", column="x"):
    """Why the ``points`` (N, 3, mm as read in the unit ``read_as``) are in another length
    unit than the one they were read in, or None. ``column``: the name of their x column
    the message shows with a unit (``x_nom`` in a table: ``x`` alone is refused there).

    Only points that span less than :data:`SMALL_SPAN` of the face's extent (the diagonal
    of the bounding boxes) are tried: scaled by each factor of :data:`UNIT_SCALES`, at
    least :data:`ON_FACE_SHARE` of them must lie within ``max_offset`` of the face and
    inside its border (``project(surface, points)``, the projection engine), and span
    between :data:`SMALL_SPAN` and 1.5 times the face. A small patch measured on purpose
    fails that: scaled, it lands off the face."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    pts = pts[np.isfinite(pts).all(axis=1)]
    if len(pts) < 3:
        return None
    grid = face_samples(surface)
    face = float(np.linalg.norm(grid.max(axis=0) - grid.min(axis=0)))
    span = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    if not span < SMALL_SPAN * face:
        return None
    read_factor, read_name = LENGTH_UNITS.get(read_as, LENGTH_UNITS["mm"])
    for factor in UNIT_SCALES:
        if not SMALL_SPAN * face <= span * factor <= 1.5 * face:
            continue    # scaled, they would still cover a corner, or more than the face
        r = project(surface, pts * factor)
        on = (np.abs(r.distance) <= max_offset) & ~np.asarray(r.outside, dtype=bool)
        if on.mean() < ON_FACE_SHARE:
            continue
        unit = next((u for u, (f, _n) in LENGTH_UNITS.items()
                     if abs(f / (read_factor * factor) - 1.0) < 1e-9), None)
        if unit is None:
            give = "give the coordinates' unit"
        else:
            give = "give the unit: %sa column name like '%s [%s]'" % (
                "units %s, or " % unit if unit in INPUTS["units"].choices else "", column, unit)
        return ("the %d points span %.4g mm where the face spans %.4g mm, and multiplied "
                "by %g they lie on it: the file's coordinates are in %s, not %s (%s)"
                % (len(pts), span, face, factor,
                   LENGTH_UNITS[unit][1] if unit else "a %g times larger unit" % factor,
                   read_name, give))
    return None


def nominal_off_face(dist):
    """The file's nominal points against the face, from their distances ``dist`` (mm):
    None when every one lies within :data:`surfcomp.core.limits.NOMINAL_OFF_FACE_WARNING`
    of it, else ``(k, message, refused)``: the farthest point's index, what to say about
    it (the caller adds the file and line) and whether it is refused (farther than
    :data:`surfcomp.core.limits.NOMINAL_OFF_FACE`)."""
    off = np.abs(np.asarray(dist, dtype=float))
    k = int(np.argmax(off))
    if not off[k] > NOMINAL_OFF_FACE_WARNING:
        return None
    limit = NOMINAL_OFF_FACE if off[k] > NOMINAL_OFF_FACE else NOMINAL_OFF_FACE_WARNING
    count = "%d of %d nominal points are more than %g um from it" % (
        np.count_nonzero(off > limit), off.size, limit * 1e3)
    if limit == NOMINAL_OFF_FACE:
        return k, ("the nominal point of this line is %.4f mm from the face (%s): the file's "
                   "nominal points are not on this face; expected the nominal points of this "
                   "face (is it another face, another revision of the model, or another "
                   "frame?)" % (off[k], count)), True
    return k, ("the file's nominal points lie up to %.2f um off the face (this line; %s): "
               "the deviations are taken against them, so they are off by as much"
               % (off[k] * 1e3, count)), False


def unpaired(nominal, measured, normal, max_offset):
    """The measured points that do not lie on their own nominal point's normal: an index
    array of those farther beside it (across ``normal``) than
    :data:`surfcomp.core.limits.PAIRING_SHARE` of the distance from their nominal point to
    the next one, or than ``max_offset``; and ``(beside, spacing)`` of every point (mm)."""
    delta = np.asarray(measured, dtype=float) - nominal
    along = np.einsum("ij,ij->i", delta, normal)
    beside = np.linalg.norm(delta - along[:, None] * normal, axis=1)
    spacing = np.full(beside.size, np.inf)
    if beside.size > 1:
        spacing = cKDTree(nominal).query(nominal, k=2)[0][:, 1]
    bad = np.flatnonzero(~(beside <= np.minimum(PAIRING_SHARE * spacing, max_offset)))
    return bad, (beside, spacing)


def check_file_points(ms, dist, normal, max_offset, warnings):
    """Refuse a file whose nominal points are not on the face (:func:`nominal_off_face`,
    ``dist`` their distances from it) or whose measured points do not pair with them
    (:func:`unpaired`, half of them or more); warn of smaller offsets and of a few unpaired
    points (appended to ``warnings``). ``normal``: the normals the deviations are taken
    along."""
    if ms.nominal is None:
        return
    got = nominal_off_face(dist)
    if got is not None:
        k, message, refused = got
        if refused:
            raise MeasurementFileError(message, file=ms.source, line=int(ms.lines[k]))
        warnings.append("%s:%d: %s" % (ms.source, ms.lines[k], message))
    if ms.measured is None:
        return
    bad, (beside, spacing) = unpaired(ms.nominal, ms.measured, normal, max_offset)
    if not bad.size:
        return
    k = int(bad[0])
    head = ("%d of %d measured points lie beside their own nominal point rather than on its "
            "normal (this line: %.4f mm beside it, the next nominal point %.4f mm away; "
            "expected at most half that, and at most " % (bad.size, beside.size, beside[k],
                                                          spacing[k]))
    tail = " %g mm)" % max_offset
    if 2 * bad.size >= beside.size:
        raise MeasurementFileError(
            head + "max_offset" + tail + ": the measured points do not pair with the nominal "
            "points of their rows; expected each row's measured point probed along its "
            "nominal normal (is the measured column shifted or sorted apart?)",
            file=ms.source, line=int(ms.lines[k]), options=("max_offset",))
    warnings.append(note("%s:%d: " % (ms.source, ms.lines[k]), head, ("max_offset",), tail,
                         "; their deviations are taken along the normal of the nominal point"))


def mask_warning(source, mask_size, shape, option="mask_size"):
    """``[note]`` when the mask is larger than the grid of ``shape`` in both directions:
    the determined part is then nearly the grid's mean; else ``[]``."""
    if mask_size <= max(shape):
        return []
    return [note("%s: the %d x %d mask is larger than the %d x %d grid, the determined part "
                 "is nearly the mean: a smaller " % ((source, mask_size, mask_size) + tuple(shape)),
                 ("mask_size", option), " keeps its shape")]


def units_warning(deviation, dimension, factor=UNITS_FACTOR):
    """A warning when every finite deviation is larger than ``factor`` times the size
    tolerance of a face of ``dimension`` mm (see module doc), or when (three or more) all lie
    below :data:`TINY_DEVIATION`; else None."""
    d = np.abs(np.asarray(deviation, dtype=float).ravel())
    d = d[np.isfinite(d)]
    if not d.size or dimension <= 0:
        return None
    if d.size >= 3 and float(d.max()) < TINY_DEVIATION:
        return ("every deviation is below %g um (largest %.3g um), under what a CMM or a probe "
                "resolves: deviations in mm read as um? Check the units of the file"
                % (TINY_DEVIATION * 1e3, float(d.max()) * 1e3))
    tol = size_tolerance(dimension)
    if float(d.min()) <= factor * tol:
        return None
    return ("every deviation is larger than %g x the size tolerance of the face (ISO 2768-1 "
            "fine: +-%g mm for its largest dimension %.1f mm; smallest |deviation| %.4g mm): "
            "check the units of the file" % (factor, tol, dimension, float(d.min())))


def spread_warning(deviation, dimension):
    """A warning when the deviations spread (sample standard deviation, three or more)
    by more than the size tolerance of a face of ``dimension`` mm (see module doc): a
    machined face that far from its own mean is not what a machining error leaves, but
    points of another part or frame, or columns in another order; else None."""
    d = np.asarray(deviation, dtype=float).ravel()
    d = d[np.isfinite(d)]
    if d.size < 3 or dimension <= 0:
        return None
    spread, tol = float(np.std(d, ddof=1)), size_tolerance(dimension)
    if spread <= tol:
        return None
    return ("the deviations spread by %.0f um (standard deviation), more than the face's size "
            "tolerance (ISO 2768-1 fine: +-%g mm for its largest dimension %.1f mm): more than "
            "a machining error leaves; is this the measurement of this face, in its frame, with "
            "the columns in the right order?" % (spread * 1e3, tol, dimension))


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


@dataclass
class StockCheck:
    """The mirror method's stock against the measured deviations (mm), see module doc.

    ``mean`` and ``spread`` (sample standard deviation, ddof=1; 0 for one point) of the
    finite deviations; a part measured with ``stock`` should have its mean within
    ``tolerance`` = max(stock/2, :data:`STOCK_SPREADS` x spread) of ``stock``.
    """

    stock: float
    mean: float
    spread: float
    tolerance: float
    consistent: bool

    def describe(self):
        """One line: the measured mean and spread against what the stock expects (um)."""
        return ("measured mean deviation %.1f um (spread %.1f um); a part measured with the "
                "stock %g mm should have a mean of %g mm +- %.1f um (the larger of stock/2 and "
                "%g x the spread)" % (1e3 * self.mean, 1e3 * self.spread, self.stock,
                                      self.stock, 1e3 * self.tolerance, STOCK_SPREADS))


def stock_check(deviation, stock, spreads=STOCK_SPREADS):
    """Is ``stock`` (mm) consistent with the measured ``deviation`` (mm, NaN ignored)?

    Returns
    -------
    StockCheck
        ``consistent`` is False when ``|mean(d) - stock| > max(stock / 2, spreads *
        std(d))`` (module doc: a semi-finished part measures ``d = stock + e``); True
        when there is no finite deviation.
    """
    d = np.asarray(deviation, dtype=float).ravel()
    d = d[np.isfinite(d)]
    s = float(stock)
    if not d.size:
        return StockCheck(stock=s, mean=float("nan"), spread=float("nan"), tolerance=s / 2,
                          consistent=True)
    mean = float(d.mean())
    spread = float(d.std(ddof=1)) if d.size > 1 else 0.0
    tol = max(s / 2.0, spreads * spread)
    return StockCheck(stock=s, mean=mean, spread=spread, tolerance=tol,
                      consistent=bool(abs(mean - s) <= tol))


def residual_assumption(method, stock=None):
    """What the predicted residual ``d_f - stock - delta`` of ``method`` assumes (one
    sentence), or "" where it assumes nothing beyond the method."""
    if method != "mirror":
        return ""
    return ("the mirror method's predicted residual assumes the measured part carries the "
            "stock %g mm (d = stock + e): it is -(the random part) whatever the stock, so "
            "it cannot show a wrong stock; the stock check against the measured mean can"
            % float(stock or 0.0))
