# SPDX-License-Identifier: LGPL-2.1-or-later
"""The corrected B-spline surface and its check figures (no FreeCAD).

Construction (why not the papers' interpolation through the corrected points:
on coarse grids such as 7 x 10 points on a bicubic face with interior knots that
misses the nominal shape by ~100 um between points): the nominal's knot vectors
are refined, for a grid along the parameter lines first by knots on its node lines
(one span per grid step, see :func:`construct`), else or where that misses the limits
until every knot span is at most ``1/refine`` of the measurement grid spacing; the
nominal is sampled at the Greville abscissae of the refined space,
each sample is displaced by the correction field along the nominal's outward
normal, ``S_c(u, v) = S(u, v) - delta(u, v) n(u, v)``, and the refined space
interpolates these samples. The refined space contains the nominal exactly
(knot insertion), so a zero field gives the nominal back to rounding error; the
degrees, parametrisation, u/v directions and (for rational nominals) weights are
the nominal's.
"""

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ..limits import ACCEPT_TOL, MATCH_ITERATIONS, MATCH_TOL, OVERSHOOT_TOL, POLE_LIMIT
from ..options import OPTIONS
from ..progress import report, sub
from ..surface import bspline
from .corrected_check import NodeFrame, check_figures, realised_correction
from .field import GridField

#: knot spans per measurement grid step at most (the option registry's default)
DEFAULT_REFINE = OPTIONS["refine"].default
#: poles of the finer space a dense grid across the parameter lines falls back to (two
#: spans per grid step, fewer (at least 1.25) where that would exceed this)
POLE_BUDGET = 4.5e6
#: knot spans per direction at least (coarse grids), see _span
MIN_SPANS = 120
#: knot spans per direction beyond which dense grids get fewer spans per grid step
#: (down to two), so the pole net grows like the number of points, not 16 times it
MAX_SPANS = 1000


def refinement_knots(knots, degree, lo, hi, spacing):
    """Knots to insert so that no span inside [lo, hi] is longer than ``spacing``.

    Each existing span is split into equal parts, so the nominal's own knots stay.
    """
    distinct = np.unique(np.asarray(knots, dtype=float))
    new = []
    for a, b in zip(distinct[:-1], distinct[1:]):
        if b <= lo or a >= hi or b - a <= spacing:
            continue
        parts = int(np.ceil((b - a) / spacing - 1e-9))
        new.extend(a + (b - a) * np.arange(1, parts) / parts)
    return np.asarray(new, dtype=float)


def node_line_knots(knots, lo, hi, lines, keep_off=0.5):
    """Knots at the measurement grid's node lines (one span per grid step), for grids
    whose rows and columns run along parameter lines: the space's Greville samples then
    lie near the nodes, where the correction must be met exactly.

    Each of the nominal's own knots (which stay, so the space still contains the
    nominal) takes the place of the node line nearest to it (beyond the outermost lines
    when that is at most ``keep_off`` of a step away), so the spans stay about one step
    long; lines within 1/20 of a step of the border are left out. Beyond the outermost
    lines, where the field levels off within about a grid step (see
    :mod:`surfcomp.core.compensation.field`), the first span is one step and the next ones grow
    fourfold (1, 4, 16, ... steps out, none within half a step of the border).
    """
    lines = np.sort(np.asarray(lines, dtype=float))
    step = np.median(np.diff(lines))
    own = np.unique(np.asarray(knots, dtype=float))
    first, last = lines[0], lines[-1]
    lines = np.concatenate([first - _strip(first - lo, step)[::-1], lines,
                            last + _strip(hi - last, step)])
    near = np.zeros(lines.size, dtype=bool)
    for k in own[(own > lo) & (own < hi)]:
        i = np.argmin(np.abs(lines - k))
        # between the outermost lines the nearest is at most half a (local) step away; a
        # knot halfway between two lines replaces one of them whatever the rounding
        near[i] |= first <= k <= last or abs(lines[i] - k) <= keep_off * step
    # a line on the border (up to rounding) would make a span of almost no length
    inside = (lines > lo + 0.05 * step) & (lines < hi - 0.05 * step)
    return lines[inside & ~near]


def _strip(width, step):
    """Offsets of the knots in a strip ``width`` wide beyond the outermost node line."""
    out = step * 4.0 ** np.arange(max(0, int(np.log(max(width, step) / step) / np.log(4)) + 2))
    return out[out <= width - 0.5 * step]


def grid_lines(U, V, tol=0.02):
    """The grid's u per row and v per column when its nodes lie on parameter lines
    within ``tol`` of a grid step; else None."""
    if U.ndim != 2 or min(U.shape) < 2:
        return None
    lu, lv = np.median(U, axis=1), np.median(V, axis=0)
    du, dv = np.diff(lu), np.diff(lv)
    if min(np.min(np.abs(du)), np.min(np.abs(dv))) <= 0:
        return None
    if (np.max(np.abs(U - lu[:, None])) > tol * np.min(np.abs(du))
            or np.max(np.abs(V - lv[None, :])) > tol * np.min(np.abs(dv))):
        return None
    return lu, lv


def aligned_lines(U, V, refine, tol=0.02):
    """:func:`grid_lines` for grids dense enough that :data:`MAX_SPANS` caps the
    refinement (their only space is the node-line one); else None."""
    if U.ndim != 2 or min(U.shape) < 4 or refine * (max(U.shape) - 1) <= MAX_SPANS:
        return None
    return grid_lines(U, V, tol)


def _span(width, spacing, refine, per_step=2, min_spans=MIN_SPANS):
    """Largest knot span: ``spacing / refine``, and on coarse grids at most
    ``width / min_spans`` (more spans damp the ringing of the fit between nodes;
    coarse grids have few poles, so this is cheap). Dense grids, whose ``refine``
    spans per step would exceed ``MAX_SPANS``, get ``MAX_SPANS`` spans but never fewer
    than ``per_step`` per grid step: one is enough for smooth (filtered) corrections,
    raw noisy ones need two (with one the residual iteration at the nodes does not
    converge: 3 um left on a noisy 81 x 81 grid; with two, 1-2 steps)."""
    span = min(spacing / refine, width / min_spans)
    return max(span, min(spacing / per_step, width / MAX_SPANS))


def _added_knots(nominal, spacing_u, spacing_v, refine, lines=None, per_step=2,
                 min_spans=MIN_SPANS):
    """The knots the refined space adds to the nominal's, along u and along v: only knots
    strictly inside both the work area and the spline's domain (a surface made
    non-periodic keeps knots beyond its domain, and a face range read from a file can end
    a rounding error beyond it: a full sphere's 6.28318530717959 against 2 pi)."""
    (u0, u1), (v0, v1) = nominal.u_range, nominal.v_range
    if lines is not None:
        added = (node_line_knots(nominal.knots_u, u0, u1, lines[0]),
                 node_line_knots(nominal.knots_v, v0, v1, lines[1]))
    else:
        added = (refinement_knots(nominal.knots_u, nominal.degree_u, u0, u1,
                                  _span(u1 - u0, spacing_u, refine, per_step, min_spans))
                 if spacing_u else (),
                 refinement_knots(nominal.knots_v, nominal.degree_v, v0, v1,
                                  _span(v1 - v0, spacing_v, refine, per_step, min_spans))
                 if spacing_v else ())
    return tuple(_inside_domain(np.asarray(k, dtype=float), knots, p, lo, hi)
                 for k, knots, p, (lo, hi) in zip(
                     added, (nominal.knots_u, nominal.knots_v),
                     (nominal.degree_u, nominal.degree_v), (nominal.u_range, nominal.v_range)))


def _inside_domain(new, knots, degree, lo, hi):
    lo, hi = max(lo, knots[degree]), min(hi, knots[knots.size - degree - 1])
    return new[(new > lo) & (new < hi)]


class _Sampling:
    """The refined space of the nominal and its samples (computed once per construction)."""

    def __init__(self, nominal, outward, spacing_u, spacing_v, refine, lines=None, per_step=2,
                 added=None):
        new_u, new_v = added or _added_knots(nominal, spacing_u, spacing_v, refine, lines,
                                             per_step)
        shape = tuple(len(knots) + len(new) - p - 1 for knots, new, p in zip(
            (nominal.knots_u, nominal.knots_v), (new_u, new_v),
            (nominal.degree_u, nominal.degree_v)))
        if shape[0] * shape[1] > POLE_LIMIT:
            # its sampling alone would take tens of GiB
            raise InputError("carrying the correction at the points' spacing needs a corrected "
                             "face of %d x %d poles (at most %d in all): the points cover a "
                             "tiny part of the face, or lie very close together (a file in "
                             "another unit?)" % (shape + (POLE_LIMIT,)))
        self.nominal = nominal
        self.fine = bspline.insert_knots(nominal, new_u, new_v)
        self.us = bspline.greville(self.fine.knots_u, self.fine.degree_u)
        self.vs = bspline.greville(self.fine.knots_v, self.fine.degree_v)
        self.S, Su, Sv = bspline.evaluate_grid(self.fine, self.us, self.vs, order=1)
        # unit normals, a collapsed edge (a cone's apex, a sphere's pole) taking the limit
        # of its neighbours' as everywhere else (:func:`bspline.normals`)
        uu, vv = np.meshgrid(self.us, self.vs, indexing="ij")
        self.n = outward * bspline.unit_normals(self.fine, uu, vv, Su, Sv)

    def build(self, delta):
        """The surface through ``S - delta n`` at the samples; ``delta`` shape
        (len(us), len(vs))."""
        f = self.fine
        target = self.S - np.asarray(delta, dtype=float)[..., None] * self.n
        poles = bspline.interpolate_grid(self.us, self.vs, target, f.knots_u, f.knots_v,
                                         f.degree_u, f.degree_v, f.weights)
        return bspline.Surface(poles, f.knots_u, f.knots_v, f.degree_u, f.degree_v, f.weights,
                               self.nominal.u_range, self.nominal.v_range)


@dataclass
class Construction:
    """A corrected surface with what was built alongside it (see :func:`construct`)."""

    corrected: object     # Surface
    zero: object          # Surface built the same way with a zero field
    field: object         # the field through the intended values (maps, report)
    iterations: int       # residual iterations at the nodes
    checks: object        # CheckFigures


def construct(nominal, U, V, delta, outward=1, spacing_u=None, spacing_v=None,
              refine=DEFAULT_REFINE, field_factory=GridField, grid_shape=None, progress=None,
              lean=True):
    """Build the corrected surface for node corrections ``delta`` and check it.

    The one entry point for the pipeline and the document objects. A grid along the
    parameter lines first gets the lean space (:func:`node_line_knots`: the nominal's
    knots and one span per grid step); it is kept when it meets the limits
    (:func:`meets_limits`). Otherwise, and for other layouts, the spaces of
    :data:`LADDER` spans per grid step are tried in turn (:func:`_ladder`), and when none
    meets the limits the space has ``refine`` spans per grid step (see :func:`_span`;
    dense grids fewer); when nothing meets the limits the one closest to them is kept.
    Each space is sampled once and serves the
    matching surface (:func:`build_matching_surface`), the zero-field surface (the
    construction's self-check) and the check figures.

    Parameters
    ----------
    U, V, delta : array_like, shape (n, m) (grids) or (N,) (scattered ``field_factory``)
        Node parameters and intended corrections (mm).
    refine : int
        Knot spans per grid step at most (the space the lean one falls back to).
    grid_shape : tuple, optional
        Shape of the measurement grid for the density of the dense check grid
        (default ``U.shape``; give a shape for scattered nodes).
    lean : bool
        False: no lean space below the dense limit and no ladder, ``refine`` spans per step
        as before them (documents made before them recompute to the face they saved).

    Returns
    -------
    Construction
    """
    U, V = np.asarray(U, dtype=float), np.asarray(V, dtype=float)
    report(progress, 0.0, "sampling the nominal")
    args = (nominal, U, V, delta, outward, grid_shape or U.shape)
    lines = grid_lines(U, V) if field_factory is GridField else None
    if not lean:
        lines = aligned_lines(U, V, refine) if lines is not None else None
    first = None    # the lean construction
    if lines is not None:
        smp = _Sampling(nominal, outward, spacing_u, spacing_v, refine, lines)
        first = _checked(smp, *_match(smp, U, V, delta, outward, MATCH_TOL, MATCH_ITERATIONS,
                                      field_factory, sub(progress, 0.05, 0.4)), *args)
        # a dense grid has no finer space within MAX_SPANS
        if meets_limits(first.checks) or aligned_lines(U, V, refine) is not None:
            report(progress, 1.0, "corrected surface checked")
            return first
    capped = [len(k) for k in _added_knots(nominal, spacing_u, spacing_v, refine)] != \
        [len(k) for k in _added_knots(nominal, spacing_u, spacing_v, refine, per_step=1)]
    part = sub(progress, 0.0 if first is None else 0.4, 1.0)
    tried = [] if first is None else [first]
    if lean:
        tried += _ladder(nominal, outward, spacing_u, spacing_v, refine, field_factory, args,
                         sub(part, 0.0, 0.5))
        if tried and meets_limits(tried[-1].checks):
            report(progress, 1.0, "corrected surface checked")
            return tried[-1]
        part = sub(part, 0.5, 1.0)
    if not capped:
        smp = _Sampling(nominal, outward, spacing_u, spacing_v, refine)
        fine = _match(smp, U, V, delta, outward, MATCH_TOL, MATCH_ITERATIONS,
                      field_factory, sub(part, 0.1, 0.75))
    else:
        smp, *fine = _dense_across(nominal, outward, U, V, delta, spacing_u, spacing_v,
                                   refine, field_factory, part)
    report(part, 0.75, "checking the corrected surface")
    built = _checked(smp, *fine, *args)
    report(progress, 1.0, "corrected surface checked")
    return min(tried + [built], key=lambda c: _excess(c.checks))


#: knot spans of the smooth route's space per span of the union of the nominal's and the
#: field's knots, tried in turn until the limits are met
SMOOTH_PARTS = (1, 2, 4, 8)
#: the smooth route stops refining beyond this many poles
SMOOTH_POLE_BUDGET = 1.1e6


def smooth_knots(knots, lo, hi, field_knots, parts):
    """Knots to add to the nominal's (flat ``knots``) within [lo, hi]: the field's knots
    (those within 1/10 of a field span of one of the nominal's knots left out, the
    nominal's knot stands in), then every span of the union split into ``parts`` (spans
    up to 1.2 field spans long count as one; without field knots, the nominal's longest
    span in [lo, hi] stands for a field span)."""
    own = np.unique(np.asarray(knots, dtype=float))
    field_knots = np.asarray(field_knots, dtype=float)
    if field_knots.size > 1:
        h = float(np.median(np.diff(field_knots)))
    else:   # a field without knots (a constant): the nominal's longest span in [lo, hi]
        h = float(np.max(np.diff(np.clip(own, lo, hi))))
    inside = field_knots[(field_knots > lo + 0.1 * h) & (field_knots < hi - 0.1 * h)]
    gap = np.min(np.abs(inside[:, None] - own[None, :]), axis=1) if inside.size else inside
    first = inside[gap > 0.1 * h]
    union = np.union1d(own, first)
    # (a span that lost a field knot to a nominal one is up to 1.1 field spans long)
    return np.sort(np.concatenate([first, refinement_knots(union, 0, lo, hi, h / parts * 1.2)]))


def construct_smooth(nominal, U, V, delta, field, outward=1, progress=None):
    """The corrected surface for a correction that is a smooth field known everywhere
    (the scattered layouts' P-spline fit,
    :class:`surfcomp.core.compensation.spline_field.SplineField`, whose values at the points are
    ``delta``): the space holds the nominal's knots and the field's (:func:`smooth_knots`), split
    into 1, 2, 4, 8 parts until the limits are
    met (:func:`meets_limits`) and the field is met within MATCH_TOL at the points and
    on a 101 x 101 grid between them (:func:`_field_miss`); no residual iteration. The
    check grid has four points per knot span (at least 201 x 201).

    Returns
    -------
    Construction
        The first that meets the limits, else the one closest to them.
    """
    U, V, delta = np.ravel(U).astype(float), np.ravel(V).astype(float), np.ravel(delta)
    (u0, u1), (v0, v1) = nominal.u_range, nominal.v_range
    best = None
    for k, parts in enumerate(SMOOTH_PARTS):
        added = (smooth_knots(nominal.knots_u, u0, u1, field.knots(0), parts),
                 smooth_knots(nominal.knots_v, v0, v1, field.knots(1), parts))
        poles = np.prod([len(a) + len(own) - d - 1 for a, own, d in
                         zip(added, (nominal.knots_u, nominal.knots_v),
                             (nominal.degree_u, nominal.degree_v))])
        if best is not None and poles > SMOOTH_POLE_BUDGET:
            break
        report(progress, k / len(SMOOTH_PARTS), "building the corrected surface (%d poles)"
               % poles)
        smp = _Sampling(nominal, outward, None, None, 1, added=added)
        uu, vv = np.meshgrid(smp.us, smp.vs, indexing="ij")
        surf = smp.build(field(uu, vv))
        real = realised_correction(nominal, surf, U, V, outward, guess=delta)
        built = _checked(smp, surf, field, 0, real, nominal, U, V, delta, outward,
                         (max(smp.us.size, 51), max(smp.vs.size, 51)))
        if best is None or _excess(built.checks) < _excess(best.checks):
            best = built
        if meets_limits(built.checks) and _field_miss(nominal, surf, field, outward,
                                                       real - delta) <= MATCH_TOL:
            break
    report(progress, 1.0, "corrected surface checked")
    return best


def _field_miss(nominal, surf, field, outward, at_points, size=101):
    """How far (mm) the surface's realised correction misses a field known everywhere: at
    the points (``at_points``, realised - intended) and on a ``size`` x ``size`` grid
    over the field's ``box`` (where it is smooth: a spline field is only C1 beyond its
    knots, and the check figures' overshoot limit holds there), else the work area."""
    (u0, u1), (v0, v1) = field.box or (nominal.u_range, nominal.v_range)
    uu, vv = (a.ravel() for a in np.meshgrid(np.linspace(u0, u1, size),
                                             np.linspace(v0, v1, size), indexing="ij"))
    want = field(uu, vv)
    real = realised_correction(nominal, surf, uu, vv, outward, guess=want)
    return max(float(np.max(np.abs(at_points))), float(np.max(np.abs(real - want))))


#: spans per grid step tried in turn (lean faces) before ``refine`` per step: the first
#: space that meets the limits is kept. One is enough for smooth (filtered) corrections
#: also on grids across the parameter lines (a 100 x 100 grid turned by 20 degrees: 163 x
#: 163 poles, 0.05 um at the points, against 639 x 639 with four); raw noisy ones need two
LADDER = (1.0, 1.5, 2.0)
#: the residual iteration on the ladder's spaces stops at half the limit (on one span per
#: step it converges slowly: 8 steps to 0.03 um on a 200 x 200 turned grid)
LADDER_TOL = ACCEPT_TOL / 2


def _ladder(nominal, outward, spacing_u, spacing_v, refine, field_factory, args, progress):
    """The :class:`Construction` on each space of :data:`LADDER` spans per grid step
    (fewer than ``refine``, at most :data:`POLE_BUDGET` poles) up to the first that meets
    the limits (then the last of the list)."""
    _, U, V, delta, _, _ = args
    rungs = [r for r in LADDER if r < refine]
    seen, tried = set(), []
    for k, per_step in enumerate(rungs):
        added = _added_knots(nominal, spacing_u, spacing_v, per_step, per_step=per_step,
                             min_spans=1)
        size = (len(added[0]) + nominal.shape[0], len(added[1]) + nominal.shape[1])
        if size[0] * size[1] > POLE_BUDGET:
            break
        if size in seen:     # the nominal's own spans are short enough for both rungs
            continue
        seen.add(size)
        smp = _Sampling(nominal, outward, spacing_u, spacing_v, per_step, added=added)
        fine = _match(smp, U, V, delta, outward, LADDER_TOL, MATCH_ITERATIONS, field_factory,
                      sub(progress, k / len(rungs), (k + 1) / len(rungs)))
        tried.append(_checked(smp, *fine, *args))
        if meets_limits(tried[-1].checks):
            break
    return tried


def _checked(smp, surf, field, k, real, nominal, U, V, delta, outward, shape):
    """The :class:`Construction` of a matched surface on the sampled space ``smp``."""
    zero = smp.build(np.zeros((smp.us.size, smp.vs.size)))
    checks = check_figures(nominal, surf, zero, U.ravel(), V.ravel(), np.ravel(delta), outward,
                           shape, realised=real.ravel())
    return Construction(surf, zero, field, k, checks)


# the limits a corrected surface is held to (mm, :mod:`surfcomp.core.limits`): realised -
# intended correction at the points and the zero field's deviation from the nominal at most
# ACCEPT_TOL, the largest realised correction on the dense check grid at most the largest
# intended + OVERSHOOT_TOL


def _excess(checks):
    """How far ``checks`` exceed the limits: the largest ratio figure / limit."""
    return max(checks.max_error_at_points / ACCEPT_TOL, checks.max_zero_deviation / ACCEPT_TOL,
               (checks.max_realised - checks.max_intended) / OVERSHOOT_TOL)


def meets_limits(checks):
    """True when the :class:`CheckFigures` meet the limits (see :data:`OVERSHOOT_TOL`)."""
    return _excess(checks) <= 1.0


def _dense_across(nominal, outward, U, V, delta, spacing_u, spacing_v, refine, field_factory,
                  progress):
    """A dense grid across the parameter lines (MAX_SPANS caps the refinement): the
    space with at most MAX_SPANS spans is tried first when it still has >= 1.2 spans per
    grid step (enough for smooth, filtered corrections); otherwise, or when it misses the
    points by more than ACCEPT_TOL, two spans per step (fewer, >= 1.25, within
    POLE_BUDGET). Returns ``(sampling, surface, field, iterations, realised)``."""
    (u0, u1), (v0, v1) = nominal.u_range, nominal.v_range
    steps = max((u1 - u0) / spacing_u, (v1 - v0) / spacing_v)
    if MAX_SPANS >= 1.2 * steps:
        smp = _Sampling(nominal, outward, spacing_u, spacing_v, refine, per_step=1)
        surf, field, k, real = _match(smp, U, V, delta, outward, MATCH_TOL, 4, field_factory,
                                      sub(progress, 0.1, 0.3))
        if np.max(np.abs(np.asarray(delta) - real)) <= ACCEPT_TOL:
            return smp, surf, field, k, real
    per_step = min(2.0, max(1.25, np.sqrt(POLE_BUDGET) / steps))
    smp = _Sampling(nominal, outward, spacing_u, spacing_v, refine, per_step=per_step)
    surf, field, k, real = _match(smp, U, V, delta, outward, MATCH_TOL, MATCH_ITERATIONS,
                                  field_factory, sub(progress, 0.3, 0.75))
    return smp, surf, field, k, real


def build_matching_surface(nominal, U, V, delta, outward=1, spacing_u=None, spacing_v=None,
                           refine=DEFAULT_REFINE, tol=MATCH_TOL, iterations=MATCH_ITERATIONS,
                           field_factory=GridField, progress=None):
    """Corrected surface whose realised correction equals ``delta`` at the grid nodes.

    The field through the node values (:class:`GridField`) is C1 with curvature
    jumps at the nodes, which the C2 refined space cannot follow exactly, so the
    realised correction at the nodes misses the intended one by up to a few um on
    noisy data. The miss is removed by iterating on the node values:
    ``D <- D + (delta - realised(D))``, until it is below ``tol`` (the fit is linear
    and local, so this converges in a few steps).

    Parameters
    ----------
    U, V, delta : array_like, shape (n, m)
        Grid node parameters and intended corrections (mm); for a scattered
        ``field_factory`` shape (N,).
    field_factory : callable
        ``field_factory(U, V, delta)`` -> field with ``locate(u, v)`` (or
        ``locate_grid(us, vs)``) returning a tuple ``loc``, ``at_index(*loc)`` and
        ``with_values(values)``: :class:`GridField` for grids.

    Returns
    -------
    surface : Surface
    field : GridField (or the ``field_factory``'s type)
        The field through the intended values (for maps and the report).
    iterations : int
    """
    report(progress, 0.05, "sampling the nominal")
    smp = _Sampling(nominal, outward, spacing_u, spacing_v, refine)
    surf, field, k, _ = _match(smp, np.asarray(U, dtype=float), np.asarray(V, dtype=float),
                               delta, outward, tol, iterations, field_factory,
                               sub(progress, 0.1, 1.0))
    return surf, field, k


def _match(smp, U, V, delta, outward, tol, iterations, field_factory, progress):
    """The residual iteration of :func:`build_matching_surface` on a sampled space;
    returns ``(surface, field, iterations, realised correction at the nodes)``."""
    delta = np.asarray(delta, dtype=float)
    field = field_factory(U, V, delta)
    uu, vv = np.meshgrid(smp.us, smp.vs, indexing="ij")
    # the samples' place in the field, once
    if hasattr(field, "locate_grid"):
        loc = field.locate_grid(smp.us, smp.vs)
    else:
        loc = field.locate(uu.ravel(), vv.ravel())
    nodes = NodeFrame(smp.nominal, U.ravel(), V.ravel(), outward)
    values = delta.copy()
    base = samples = field.at_index(*loc)
    # the steps only move the node values by the misses left, so a linear interpolant of
    # the change (where the field has one) stands in for a new field through them
    linear = field.linear_at(*loc) if hasattr(field, "linear_at") else None
    if linear is not None:    # the field itself is not evaluated again here
        field.drop_caches()
    xs, fs, best = [], [], None
    exact = None    # the first surface and its realised correction by Newton
    k = 0
    while True:
        report(progress, k / (iterations + 1), "building the corrected surface")
        surf = smp.build(samples.reshape(uu.shape))
        # the later surfaces differ from the first by fractions of a um: their realised
        # corrections follow from its intersections to first order (one evaluation)
        real = None if exact is None else nodes.realised_change(exact[0], surf, exact[1])
        if real is None:
            real = nodes.realised(surf, guess=values.ravel())
            exact = (surf, real)
        real = real.reshape(delta.shape)
        miss = delta - real
        worst = float(np.max(np.abs(miss)))
        if best is None or worst < best[0]:
            best = (worst, surf, k, real)
        if worst <= tol or k >= iterations:
            _, surf, k, real = best
            if surf is not exact[0]:     # the kept surface's own intersections
                real = nodes.realised(surf, guess=real.ravel()).reshape(delta.shape)
            return surf, field, k, real
        xs, fs = (xs + [values.ravel()])[-ANDERSON - 1:], (fs + [miss.ravel()])[-ANDERSON - 1:]
        values = anderson_step(xs, fs).reshape(delta.shape)
        samples = (base + linear @ (values - delta).ravel() if linear is not None
                   else field.with_values(values).at_index(*loc))
        k += 1


#: the residual iteration mixes this many previous steps into the next (Anderson)
ANDERSON = 4


def anderson_step(xs, fs):
    """Next iterate of the fixed-point iteration ``x <- x + f(x)`` by Anderson mixing over
    the stored iterates ``xs`` and their residuals ``fs`` (lists of (N,) arrays, newest
    last; Walker & Ni 2011, "Anderson acceleration for fixed-point iterations"): the
    combination of the last steps whose residual is least, which removes the slowly
    decaying components a plain iteration leaves (one knot span per grid step across the
    parameter lines: 0.20 um to 0.085 um in 8 plain steps)."""
    x, f = xs[-1], fs[-1]
    if len(xs) < 2:
        return x + f
    dX, dF = np.diff(np.array(xs), axis=0), np.diff(np.array(fs), axis=0)
    A = dF @ dF.T
    A[np.diag_indices_from(A)] += 1e-12 * np.trace(A) + 1e-300
    gamma = np.linalg.solve(A, dF @ f)
    return x + f - (dX + dF).T @ gamma
