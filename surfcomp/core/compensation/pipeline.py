# SPDX-License-Identifier: LGPL-2.1-or-later
"""The compensation pipeline on core arrays (no FreeCAD): measurement set + nominal surface
-> deviations, statistics, filtered components, intended corrections, corrected surface.

The app layer loads faces and writes files around it; the CLI, the document objects
and the GUI all call :func:`prepare` and :func:`compensate`.
"""

import functools
from dataclasses import dataclass, field

import numpy as np

from ...errors import ComputationError, GridError, InputError, MeasurementFileError, note
from ..choices import LAYOUTS  # noqa: F401  (re-exported: Options.layout's choices)
from ..limits import ACCEPT_TOL, NORMAL_WARNING_DEG, OVERSHOOT_TOL, SMOOTH_MATCH
from ..memory import return_free_memory
from ..options import DOMAINS as _DOMAINS
from ..options import OPTIONS
from ..progress import report, sub
from ..surface.grid import Scattered, grid_from_indices, grid_from_uv
from ..surface.kdtree import cKDTree
from ..surface.projection import project, tangent_lengths
from . import plausibility
from .corrected import construct, construct_smooth, meets_limits
from .deviations import deviation_components, statistics
from .filters import make_mask
from .folds import find_fold, fold_warning
from .grid_check import as_scattered, unlocatable
from .methods import compute_correction
from .spline_field import ConstantField

#: the median nearest-neighbour distance of a scattered layout and the median tangent
#: lengths are taken over about this many points at most (sampling error well under 1 %)
SPACING_SAMPLE = 50000


@dataclass
class Options:
    """User choices of a compensation (defaults as in Werner 2022 where it applies).

    Lengths in mm. ``mask_size``/``weights``/``mask_kind``/``sigma``/``edge`` define the
    filter (:mod:`surfcomp.core.compensation.filters`); ``stock`` is the mirror method's
    semi-finishing allowance; ``max_offset`` the largest accepted distance of a point from the face;
    ``refine`` the knot spans per measurement grid step of the corrected surface at most
    (grids along the parameter lines first get one, kept when it meets the limits; see
    :func:`surfcomp.core.compensation.corrected.construct`; ``lean`` False: ``refine`` spans per
    step as before, for documents made before);
    ``tip_radius`` the stylus ball radius when the measured points are tip centres
    (the contact point is the centre moved by it against the outward normal);
    ``layout`` one of :data:`LAYOUTS`; ``smoothing`` the smoothing length (mm) of the
    scattered layouts' fit (None: chosen by generalized cross-validation, see
    :func:`surfcomp.core.compensation.scattered.smooth`), their counterpart of the mask filter;
    ``accept_stock`` True uses a mirror stock that
    :func:`surfcomp.core.compensation.plausibility.stock_check` finds inconsistent with the measured
    mean (else it is refused).
    """

    method: str = OPTIONS["method"].default
    mask_size: int = OPTIONS["mask_size"].default
    weights: object = OPTIONS["weights"].default
    mask_kind: str = OPTIONS["mask_kind"].default
    sigma: float = OPTIONS["sigma"].default
    edge: str = OPTIONS["edge"].default
    stock: float = OPTIONS["stock"].default
    max_offset: float = OPTIONS["max_offset"].default
    flip_normals: bool = OPTIONS["flip_normals"].default
    refine: int = OPTIONS["refine"].default
    tip_radius: float = OPTIONS["tip_radius"].default
    layout: str = OPTIONS["layout"].default
    smoothing: float = OPTIONS["smoothing"].default
    lean: bool = OPTIONS["lean"].default
    accept_stock: bool = OPTIONS["accept_stock"].default
    #: who reads the messages: ``'api'`` (options named as ``max_offset``; the command line
    #: shows its flags, :mod:`surfcomp.cli.option_flags`) or ``'document'`` (as the
    #: compensation's properties, ``MaxOffset``, for the GUI)
    context: str = "api"

    def mask(self):
        return make_mask(self.mask_size, self.weights, self.mask_kind, self.sigma)

    def validate(self):
        """Refuse values outside their domain (NaN included), naming the option.

        Every route (command line, document objects, simulation) checks its options here
        before it reads a file. Returns ``self``.

        Raises
        ------
        InputError
            ``option value: expected ...`` (the document property in parentheses).
        """
        for name, (_flag, prop, lo, hi, optional, what) in _DOMAINS.items():
            value = getattr(self, name)
            if value is None and optional:
                continue
            try:
                ok = lo <= float(value) <= hi           # False for NaN
            except (TypeError, ValueError):
                ok = False
            if ok and OPTIONS[name].type is int:
                ok = float(value).is_integer()
            if not ok:
                raise InputError("%s %r: expected %s from %g to %g (%s in the document)"
                                 % (name, value, what, lo, hi, prop), options=(name,))
        for o in OPTIONS.values():
            if o.choices is not None and getattr(self, o.name) not in o.choices:
                raise InputError("%s %r: expected one of %s" % (
                    o.name, getattr(self, o.name), ", ".join(o.choices)), options=(o.name,))
        for name, prop in (("lean", "Lean"), ("accept_stock", "StockOk")):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise InputError("%s %r: expected true or false (%s in the document)"
                                 % (name, getattr(self, name), prop), options=(name,))
        if self.method == "mirror" and self.stock is None:
            raise InputError("method 'mirror' needs stock (the semi-finishing allowance in "
                             "mm; the mirror surface lies at half of it)",
                             options=("method", "stock"))
        self.mask()                                      # odd size, custom weights
        return self


def option_name(options, name):
    """How a message names option ``name`` (a field of :class:`Options`) for its reader:
    as itself, ``max_offset`` (the command line shows its flag), or as the compensation's
    property (``the compensation's MaxOffset``) when ``options.context`` is ``document``."""
    if getattr(options, "context", "api") == "document":
        return "the compensation's %s" % OPTIONS[name].prop
    return name


@dataclass
class Prepared:
    """Measured points located on the face, with deviations, arranged on their grid.

    Per-point arrays have shape (N,) or (N, 3) in file order; ``grid.index`` maps
    grid nodes to point numbers.
    """

    u: np.ndarray
    v: np.ndarray
    nominal: np.ndarray
    normal: np.ndarray
    deviation: np.ndarray
    grid: object
    lines: np.ndarray
    source: str
    warnings: list = field(default_factory=list)

    @property
    def scattered(self):
        """True when the points are not a grid (:class:`surfcomp.core.surface.grid.Scattered`)."""
        return isinstance(self.grid, Scattered)

    def row_col(self):
        """Grid row and column of every point, in file order: two int arrays (N,)
        (None, None for a scattered layout)."""
        g = self.grid
        if self.scattered:
            return None, None
        row = np.empty(self.u.size, dtype=int)
        col = np.empty(self.u.size, dtype=int)
        ii, jj = np.indices(g.shape)
        row[g.index.ravel()] = ii.ravel()
        col[g.index.ravel()] = jj.ravel()
        return row, col


def _err(ms, k, message, options=()):
    return MeasurementFileError(message, file=ms.source, line=int(ms.lines[k]), options=options)


def prepare(surface, outward, ms, options=None, progress=None):
    """Locate the measured points on the nominal face and compute their deviations.

    Parameters
    ----------
    surface : Surface
        Nominal (work area = ``u_range`` x ``v_range``).
    outward : {1, -1}
        Sign that turns ``Su x Sv`` into the face's outward normal.
    ms : surfcomp.io.measurements.MeasurementSet
    options : Options

    Returns
    -------
    Prepared

    Raises
    ------
    MeasurementFileError
        A point farther than ``max_offset`` from the face, beyond its border, or a
        given normal on the other side of the face (unless ``flip_normals``).
    GridError
        The points do not form a complete grid.
    """
    options = (options or Options()).validate()
    warnings = list(getattr(ms, "warnings", []) or [])
    base = ms.nominal if ms.nominal is not None else ms.measured
    if base is None:
        raise InputError("the measurement set has neither nominal nor measured points",
                         file=ms.source)
    tip = _tip_radius(ms, options, warnings)
    report(progress, 0.0, "locating %d points on the face" % len(base))
    proj = project(surface, base, progress=sub(progress, 0.0, 0.8))
    # a tip centre lies one tip radius outside its contact point (along the normal)
    dist = proj.distance * outward - (tip if ms.nominal is None else 0.0)
    # first: points in inches or metres near the origin can pass as on the face, or fail
    # as beyond its border, which would not say why
    mistake = plausibility.unit_mistake(surface, base, options.max_offset, project,
                                        getattr(ms, "units", None) or "mm",
                                        "x" if ms.nominal is None else "x_nom")
    if mistake:
        raise InputError(mistake, file=ms.source, options=("units",))
    _check_on_face(ms, base, proj, dist, options)
    normal = _normals(ms, proj.normal * outward, options, warnings)
    plausibility.check_file_points(ms, dist, normal, options.max_offset, warnings)
    if ms.deviation is not None:
        d = np.asarray(ms.deviation, dtype=float) * (-1.0 if options.flip_normals else 1.0)
    elif ms.nominal is not None and ms.measured is not None:
        d = np.einsum("ij,ij->i", ms.measured - ms.nominal, normal) - tip
    else:
        d = dist
    _check_deviations(ms, d, options)
    _check_units(surface, d, warnings, ms.source)
    nominal = ms.nominal if ms.nominal is not None else proj.foot
    report(progress, 0.85, "arranging the points on their grid")
    grid = _arrange(ms, proj, options, warnings, surface)
    report(progress, 1.0, "%s layout" % ("scattered" if isinstance(grid, Scattered)
                                         else "%d x %d grid" % grid.shape))
    return Prepared(u=proj.u, v=proj.v, nominal=np.asarray(nominal, dtype=float), normal=normal,
                    deviation=d, grid=grid, lines=ms.lines, source=ms.source, warnings=warnings)


def _tip_radius(ms, options, warnings):
    tip = float(options.tip_radius or 0.0)
    if tip and ms.deviation is not None:
        raise InputError("tip_radius applies to measured points (tip centres); this file "
                         "gives deviations, which the CMM has already compensated",
                         file=ms.source, options=("tip_radius",))
    if tip and ms.measured is None:
        raise InputError("tip_radius needs measured points (tip centres) in the file",
                         file=ms.source, options=("tip_radius",))
    if getattr(ms, "tip_centres", False) and not tip:
        warnings.append(note("%s: the points are stylus tip centres (probe log); without "
                             % ms.source, ("tip_radius", option_name(options, "tip_radius")),
                             " every deviation is off by the tip radius"))
    return tip


def _check_on_face(ms, base, proj, dist, options):
    """Every point within ``max_offset`` of the face (NaN is not) and inside its border.
    A point beyond the border is far from the face because it lies beyond it (a face
    trimmed to part of the measured area): that is what the message says then."""
    far = np.nonzero(~(np.abs(dist) <= options.max_offset))[0]
    outside = np.nonzero(proj.outside)[0]
    if far.size and outside.size and np.isin(far, outside).all():
        k = outside[np.argmax(np.where(np.isfinite(dist[outside]), np.abs(dist[outside]), 0))]
        raise _err(ms, k, "point (%.4f, %.4f, %.4f) lies beyond the border of the face, "
                   "%.4f mm from it (%d point(s) do; expected points on the face: is the face "
                   "smaller than the measured area, or is it the wrong face?)"
                   % (tuple(base[k]) + (abs(dist[k]), outside.size)))
    if far.size:
        size = np.where(np.isfinite(dist[far]), np.abs(dist[far]), np.inf)
        k = far[np.argmax(size)]
        what = "nominal point" if ms.nominal is not None else "measured point"
        raise _err(ms, k, "%s (%.4f, %.4f, %.4f) is %.4f mm from the face (expected at most "
                   "%s %g mm; %d point(s) are farther: wrong face, units or alignment?)"
                   % ((what,) + tuple(base[k]) + (abs(dist[k]),
                                                  option_name(options, "max_offset"),
                                                  options.max_offset, far.size)),
                   ("max_offset",))
    if outside.size:
        k = outside[0]
        raise _err(ms, k, "point (%.4f, %.4f, %.4f) lies beyond the border of the face "
                   "(%d point(s) do; expected points on the face)"
                   % (tuple(base[k]) + (outside.size,)))


def _normals(ms, n_face, options, warnings):
    """The normals the deviations are measured along: the file's (checked against the
    face's outward normal) or the face's."""
    if ms.normal is None:
        return n_face
    given = np.asarray(ms.normal, dtype=float)
    if options.flip_normals:
        given = -given
    cosang = np.einsum("ij,ij->i", given, n_face)
    opposite = np.nonzero(cosang < 0)[0]
    if opposite.size:
        raise _err(ms, opposite[0], "the given normal points to the other side of the face "
                   "than the face's outward normal (%d point(s)); use %s if the "
                   "file's normals point into the material"
                   % (opposite.size, option_name(options, "flip_normals")), ("flip_normals",))
    ang = np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))
    off = np.nonzero(ang > NORMAL_WARNING_DEG)[0]
    for k in off[:10]:
        warnings.append("%s:%d: the given normal is %.1f degrees off the face normal (more "
                        "than %g)" % (ms.source, ms.lines[k], ang[k], NORMAL_WARNING_DEG))
    if off.size > 10:
        warnings.append("%s: %d more normals are more than %g degrees off the face normal"
                        % (ms.source, off.size - 10, NORMAL_WARNING_DEG))
    return given


def _check_deviations(ms, d, options):
    """Every deviation finite and at most ``max_offset`` (the mirror method's measurement
    carries the stock on top): a larger one is a unit or file mistake, not a machining
    error, and would move the corrected face by as much."""
    allowed = options.max_offset + (options.stock or 0.0 if options.method == "mirror" else 0.0)
    bad = np.nonzero(~(np.abs(d) <= allowed))[0]
    if not bad.size:
        return
    size = np.where(np.isfinite(d[bad]), np.abs(d[bad]), np.inf)
    k = bad[np.argmax(size)]
    # a dev column's own unit is deviation_units: units would scale the coordinates too
    unit = "deviation_units" if "dev" in (ms.columns or {}) else "units"
    hint = ("are the deviations in um? Give the unit (%s um, or a column name like "
            "'dev [um]')" % unit if np.isfinite(d[k]) and np.abs(d[k]) < 1e5 * allowed
            else "is this the right file?")
    # 4 decimals as the other messages, but no 300-digit number for 1e308
    shown = "%.4f" % d[k] if np.abs(d[k]) < 1e6 else "%.6g" % d[k]
    raise _err(ms, k, "deviation %s mm (expected at most %s %g mm%s; %d point(s) "
               "exceed it): %s" % (shown, option_name(options, "max_offset"), options.max_offset,
                                    " + stock" if options.method == "mirror" else "",
                                    bad.size, hint), ("max_offset", unit))


def _check_units(surface, d, warnings, source):
    """Warn when every deviation is far beyond the face's size tolerance, or they spread by
    more than it (see :mod:`surfcomp.core.compensation.plausibility`): plausible against
    max-offset, but not for a part."""
    size = plausibility.largest_dimension(plausibility.face_samples(surface))
    for message in (plausibility.units_warning(d, size), plausibility.spread_warning(d, size)):
        if message:
            warnings.append("%s: %s" % (source, message))


#: fewest points of a scattered layout (its smoothing fit needs them off one line)
MIN_SCATTERED = 4


def _arrange(ms, proj, options, warnings, surface=None):
    """The points' grid (from row/col columns or the (u, v) pattern) or a scattered layout."""
    grid = _grid_or_scattered(ms, proj, options, warnings)
    why = None if isinstance(grid, Scattered) or surface is None else unlocatable(
        grid, proj.u, proj.v, surface.u_range, surface.v_range)
    if why is not None:
        if options.layout == "grid":
            raise GridError("%s (expected a grid whose map to the face can be inverted; "
                            "layout 'scattered' uses the points as they are)" % why,
                            file=ms.source, options=("layout",))
        warnings.append("%s%s; the points are used as a scattered layout"
                        % ("%s: " % ms.source if ms.source else "", why))
        grid = Scattered(np.arange(proj.u.size), "scattered (grid too distorted)")
    if isinstance(grid, Scattered) and proj.u.size < MIN_SCATTERED:
        raise InputError("%d measured point(s): too few to compensate (expected a grid of at "
                         "least 2 x 2 points or at least %d scattered points)"
                         % (proj.u.size, MIN_SCATTERED), file=ms.source)
    return grid


def _grid_or_scattered(ms, proj, options, warnings):
    if options.layout == "scattered":
        return Scattered(np.arange(proj.u.size), "scattered (as asked)")
    if ms.row is not None and ms.col is not None:
        return grid_from_indices(ms.row, ms.col, proj.u, proj.v, ms.lines, ms.source)
    try:
        return grid_from_uv(proj.u, proj.v, ms.lines, ms.source)
    except GridError as exc:
        if options.layout == "grid":
            raise
        warnings.append(note("%s; the points are used as a scattered layout (the determined "
                             "component comes from a smoothing fit instead of the mask filter; "
                             % exc, ("layout", option_name(options, "layout")),
                             " grid refuses such files)"))
        return Scattered(np.arange(proj.u.size), "scattered (not a complete grid)")


@dataclass
class Compensation:
    """Everything a compensation produced (grids (n, m) in mm; surfaces as core arrays)."""

    prepared: Prepared
    options: Options
    correction: object          # methods.CorrectionResult on the grid
    statistics: dict            # name -> deviations.Statistics
    corrected: object = None    # Surface
    zero: object = None         # Surface built with a zero field (construction check)
    checks: object = None       # corrected.CheckFigures
    spacing: tuple = None
    field: object = None        # the field of the intended correction (GridField, ...)
    iterations: int = 0         # residual iterations of the construction
    fit: object = None          # scattered.SmoothFit (scattered layouts only)
    scale: tuple = None         # mm per unit parameter along u and v at the points

    def per_point(self, name):
        """A grid quantity back in file order (N,)."""
        out = np.empty(self.prepared.u.size)
        out[self.prepared.grid.index.ravel()] = getattr(self.correction, name).ravel()
        return out

    def corrected_points(self):
        """Corrected points at the measured points (Werner eq. 2/3), (N, 3)."""
        p = self.prepared
        return p.nominal - deviation_components(self.per_point("delta"), p.normal)


def grid_spacing(prepared):
    """Median parameter step of the measurement grid along its two directions."""
    g = prepared.grid
    U, V = g.take(prepared.u), g.take(prepared.v)
    step_s = np.hypot(np.diff(U, axis=0), np.diff(V, axis=0))
    step_t = np.hypot(np.diff(U, axis=1), np.diff(V, axis=1))
    # a parameter spacing in u and in v: the smallest grid steps projected on each axis
    du = np.median(np.abs(np.diff(U, axis=0))) if U.shape[0] > 1 else np.median(step_s)
    dv = np.median(np.abs(np.diff(V, axis=1))) if V.shape[1] > 1 else np.median(step_t)
    return float(du or np.median(step_s)), float(dv or np.median(step_t))


def compensate(surface, outward, prepared, options=None, build=True, progress=None, scale=None):
    """Filter, choose the correction and (optionally) build the corrected surface.

    Parameters
    ----------
    surface : Surface
    outward : {1, -1}
    prepared : Prepared
    options : Options
    build : bool
        False for inspection only (deviations, statistics, filtered components).
    scale : (float, float), optional
        :func:`parameter_scale` of ``prepared`` when the caller has it (a preview that
        refilters the same points); computed when None.

    Returns
    -------
    Compensation
    """
    options = (options or Options()).validate()
    check_stock(prepared.deviation, options)
    g = prepared.grid
    d = g.take(prepared.deviation)
    scale = scale or parameter_scale(surface, prepared)
    fit = None
    if prepared.scattered:
        report(progress, 0.0, "smoothing fit of %d scattered points" % d.size)
        from .scattered import smooth  # scattered layouts only: scipy.optimize

        fit = smooth(prepared.u, prepared.v, d, options.smoothing, scale=scale)
        corr = compute_correction(d, options.method, None, options.edge, options.stock,
                                  determined=fit.determined)
    else:
        corr = compute_correction(d, options.method, options.mask(), options.edge, options.stock)
    wide = [] if prepared.scattered else plausibility.mask_warning(
        prepared.source, options.mask_size, d.shape, option_name(options, "mask_size"))
    stats = {"deviation": statistics(corr.deviation),
             "determined": statistics(corr.determined),
             "random": statistics(corr.random),
             "correction": statistics(corr.delta)}
    result = Compensation(prepared=prepared, options=options, correction=corr, statistics=stats,
                          fit=fit, scale=scale)
    if not build:
        prepared.warnings.extend(wide)
        return result
    try:
        build_surface(result, surface, outward, corr.delta, progress=sub(progress, 0.05, 1.0))
    except ComputationError as exc:
        again = as_scattered(prepared, options, exc)
        if again is None:
            raise
        return compensate(surface, outward, again, options, build, progress)
    prepared.warnings.extend(wide)      # the grid route's, once it is the one taken
    report(progress, 1.0, "done")
    return result


def check_stock(deviation, options):
    """Refuse a mirror stock inconsistent with the measured deviations (mm) unless
    ``options.accept_stock`` (:func:`surfcomp.core.compensation.plausibility.stock_check`); returns
    the
    check (None for other methods).

    Raises
    ------
    InputError
        Naming the measured mean, the option and its document property.
    """
    if options.method != "mirror" or options.stock is None:
        return None
    check = plausibility.stock_check(deviation, options.stock)
    if not check.consistent and not options.accept_stock:
        raise InputError(
            "the stock %g mm (Stock in the document) does not fit the measured deviations: "
            "%s. Was the part measured after finishing, or with another stock? Give the stock "
            "the measured part carries, or use this one anyway with accept_stock (StockOk = "
            "true in the document)" % (check.stock, check.describe()), options=("accept_stock",))
    return check


def build_surface(result, surface, outward, delta, progress=None):
    """Build and check the corrected surface of ``result`` for the node corrections
    ``delta`` in mm (``result.correction.delta``, or an accumulated correction of an
    iteration; (n, m) on a grid, (N,) for scattered points); fills ``corrected``,
    ``zero``, ``field``, ``iterations``, ``checks`` and ``spacing`` and returns ``result``."""
    prepared = result.prepared
    g = prepared.grid
    U, V = g.take(prepared.u), g.take(prepared.v)
    built, (du, dv) = _construction(result, surface, outward, U, V, delta, progress)
    return_free_memory()     # the construction's temporaries, before the CAD export
    result.spacing = (du, dv)
    result.corrected, result.zero, result.field = built.corrected, built.zero, built.field
    result.iterations, result.checks = built.iterations, built.checks
    refine = ("refine", option_name(result.options, "refine"))
    if built.checks.max_error_at_points > ACCEPT_TOL:
        prepared.warnings.append(note(
            "%s: the corrected face misses the intended correction by up to %.3f um at the "
            "measured points (more than %.1f um): neighbouring points closer than the knot "
            "spacing with different corrections (raw data?); the filtered method or a larger "
            % (prepared.source, built.checks.max_error_at_points * 1e3, ACCEPT_TOL * 1e3),
            refine, " helps"))
    over = built.checks.max_realised - built.checks.max_intended
    if over > OVERSHOOT_TOL:
        prepared.warnings.append(note(
            "%s: somewhere on the face the corrected face moves %.2f um more than the largest "
            "intended correction (more than %.1f um; usually beyond the measured region, "
            "where noisy raw data are continued): the filtered method or a larger "
            % (prepared.source, over * 1e3, OVERSHOOT_TOL * 1e3), refine, " helps"))
    built.checks.fold = find_fold(surface, built.corrected, outward)
    folded = fold_warning(prepared.source, built.checks.fold)
    if folded:
        prepared.warnings.append(folded)
    return result


def _construction(result, surface, outward, U, V, delta, progress):
    """The :class:`~surfcomp.core.compensation.corrected.Construction` of ``build_surface`` and the
    parameter spacing it used: for a uniform ``delta`` (``offset``) on the nominal's knots
    where that meets the limits, from the smoothing fit's spline where ``delta`` is its
    values at the points (scattered layouts, ``filtered``), else through the values; the
    first two only for lean faces (``Options.lean``)."""
    prepared = result.prepared
    lean = result.options.lean      # False: a document made before these routes
    flat = np.ravel(delta)
    if lean and flat.size and np.all(flat == flat[0]):   # a uniform offset: no knots of its own
        built = construct_smooth(surface, U, V, delta, ConstantField(flat[0]), outward,
                                 sub(progress, 0.0, 0.5))
        if meets_limits(built.checks):
            spacing = grid_spacing(prepared) if not prepared.scattered else \
                scattered_spacing(prepared, result.scale or parameter_scale(surface, prepared))
            return built, spacing
        # (e.g. a rational sphere patch near its pole: its offset needs more than 8 splits)
        progress = sub(progress, 0.5, 1.0)
    if not prepared.scattered:
        du, dv = grid_spacing(prepared)
        return construct(surface, U, V, delta, outward, du, dv, result.options.refine,
                         progress=progress, lean=lean), (du, dv)
    scale = result.scale or parameter_scale(surface, prepared)
    du, dv = scattered_spacing(prepared, scale)
    fit = result.fit
    # the fit's field equals fit.determined at the points (tests/pure/test_spline_field.py)
    if lean and fit is not None and fit.field is not None and \
            np.max(np.abs(fit.determined - np.ravel(delta))) <= SMOOTH_MATCH:
        return construct_smooth(surface, U, V, delta, fit.field, outward, progress), (du, dv)
    from .scattered import ScatteredField

    factory = functools.partial(ScatteredField, scale=scale,
                                box=(surface.u_range, surface.v_range))
    (u0, u1), (v0, v1) = surface.u_range, surface.v_range
    shape = (int(np.ceil((u1 - u0) / du)) + 1, int(np.ceil((v1 - v0) / dv)) + 1)
    return construct(surface, U, V, delta, outward, du, dv, result.options.refine,
                     field_factory=factory, grid_shape=shape, progress=progress,
                     lean=lean), (du, dv)


def parameter_scale(surface, prepared):
    """Median length per unit parameter (mm) along u and along v at the measured points
    (every k-th of them on sets above :data:`SPACING_SAMPLE`), so that fits over (u, v) are
    isotropic on the face."""
    k = max(1, prepared.u.size // SPACING_SAMPLE)
    lu, lv = tangent_lengths(surface, prepared.u[::k], prepared.v[::k])
    return float(np.median(lu)) or 1.0, float(np.median(lv)) or 1.0


def scattered_spacing(prepared, scale):
    """Parameter spacing (du, dv) of a scattered layout: the median distance (mm) from
    each point to its nearest neighbour, in parameter units along u and v (estimated from
    a seeded sample of :data:`SPACING_SAMPLE` points on larger sets)."""
    x = np.stack([prepared.u * scale[0], prepared.v * scale[1]], axis=1)
    query = x
    if x.shape[0] > SPACING_SAMPLE:
        query = x[np.random.default_rng(0).choice(x.shape[0], SPACING_SAMPLE, replace=False)]
    dist, _ = cKDTree(x).query(query, k=2)
    h = float(np.median(dist[:, 1]))
    if not h > 0:
        raise InputError("the measured points coincide: no spacing between them",
                         file=prepared.source)
    return h / scale[0], h / scale[1]
