# SPDX-License-Identifier: LGPL-2.1-or-later
"""The corrected faces of a region: one displacement for every face (issue 30; numpy only).

Each corrected surface is ``S_c(u, v) = S(u, v) + D(S(u, v))`` fitted on the nominal's knots
refined to the field's length scale. The displacement ``D`` is one function of the 3D
position for the whole region, so two faces that share an edge move the edge's points
alike and the corrected edges coincide up to the fit (:func:`corrected_surface`):

* away from sharp edges ``D = -delta(x) n_F(x)`` (``n_F`` the outward unit normal): where two
  faces meet tangentially (G1) their normals agree along the edge, so D does too, and the
  corrected faces meet G1 again;
* near an edge where two corrected faces meet at an angle (:class:`SharpEdges`) a normal
  move would open the edge (the two normals differ), so the displacement turns, within a
  band around the edge, towards the edge's miter vector ``m = (n_A + n_B) / (1 + n_A.n_B)``:
  ``D = -delta (n_F + w (e - (e.n_F) n_F))``, ``e = m - n_F(edge)`` the miter less the
  face's own normal at the edge (:meth:`SharpEdges.for_face`), ``w`` 1 on the edge and 0
  beyond the band. Its normal component is ``-delta`` on every face (the correction is
  realised; the rest slides the face along itself, which is how the intersection of two
  offset faces moves), and on the edge it is ``-delta m`` from both sides. Edges sharper than
  :data:`MITER_ANGLE` (a blade's knife edges) get a shortened miter along their bisector:
  there the edge stays closed and the realised correction falls short of ``delta`` within
  half the band (reported per point). Between 90 degrees and that angle the share of the
  band that keeps the normal component falls smoothly; vertices where several sharp edges
  end get one vector, and every edge within the band counts
  (:mod:`surfcomp.core.compensation.region_edges`).
"""

import math
from dataclasses import dataclass

import numpy as np

from ..surface.bspline import Surface, evaluate_grid, fit_grid_lsq, insert_knots
from .region_edges import SharpEdges, knife_limit, smoothstep  # noqa: F401 (SharpEdges: API)
from .region_fit import fit_ends_held
from .region_second import normal_term

#: largest angle (degrees) between the two normals of an edge that gets its full miter
MITER_ANGLE = 120.0
#: weight of the in-face directions in a sharp edge's bisector (they take over where the
#: normals are opposite)
KNIFE_SHARE = 0.05
#: below this angle (degrees) between the normals an edge's miter is taken exactly
EXACT_ANGLE = 90.0
#: samples of the fit per knot span, each direction
PER_SPAN = 3
#: directions with more knot spans than this keep those finer than a quarter step whole
HALVED_SPANS = 128
#: the fewest knot spans of a corrected face in each direction
MIN_SPANS = 8
#: the pole budget of a corrected face: at most this many times the nominal's poles (with 4
#: times, 42 spanwise poles, the BladeX sides' fit missed the correction by up to 0.31 um;
#: CAM's time on the corrected faces against the nominal's: bench/bench_region_cam.py and
#: docs/regions.md: the 3D Surface operation's time follows the triangles of its mesh of the
#: whole model, which the poles add little to; a smaller budget does not meet its bound)
POLE_FACTOR = 8.0
#: the smallest pole budget of a corrected face (64 x 64)
MIN_BUDGET = 64 * 64
#: a boundary curve missing the displacement by more than this (mm) halfway between two
#: fit samples gets that knot span halved (within the pole budget)
EDGE_TOL = 2e-5
#: rounds of that refinement
REFINE_ROUNDS = 4


def _unit(a):
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    return a / np.where(n > 0, n, 1.0)


def miters(n_a, n_b, inward_a, inward_b):
    """Miter vectors of edge samples and their exactness.

    ``n_a``, ``n_b``: outward unit normals of the two faces (K, 3); ``inward_a``, ``inward_b``:
    unit directions in each face, normal to the edge, pointing into the face (for knife
    edges, whose normals are opposite, the bisector is ``-(inward_a + inward_b)``).

    Returns ``(m, exact)``: ``exact`` is 1 up to :data:`EXACT_ANGLE` between the normals
    and falls smoothly to 0 at :data:`MITER_ANGLE`, beyond which the miter is shortened
    (an edge's angle varies along it: a step in ``exact`` from one sample to the next is a
    step in the displacement no fit follows).
    """
    c = np.einsum("ij,ij->i", n_a, n_b)
    limit = knife_limit(MITER_ANGLE)
    clamped = 1.0 + c < 2.0 / limit ** 2         # |m|^2 = 2 / (1 + c)
    m = (n_a + n_b) / np.where(clamped, 1.0, 1.0 + c)[:, None]
    s = n_a + n_b
    # the bisector; at a knife edge (s near 0) the in-face directions give it, with no
    # switch from one to the other along an edge whose angle varies. Where a face folds
    # back over the other (the normals' sum points into the faces, as where the BladeX
    # pressure side curls over its tip cap) the two terms cancel where the angle passes
    # about 175 degrees: there the vector shrinks through zero instead of turning round
    # from one sample to the next (a step of twice the correction no fit follows)
    b = s - KNIFE_SHARE * (inward_a + inward_b)
    b = b / np.maximum(np.linalg.norm(b, axis=-1, keepdims=True), 2.0 * KNIFE_SHARE)
    m[clamped] = limit * b[clamped]
    angle = np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))
    exact = 1.0 - smoothstep((angle - EXACT_ANGLE) / (MITER_ANGLE - EXACT_ANGLE))
    return m, exact


def displacement(x, n, delta, sharp=None):
    """``D`` at points ``x`` (M, 3) of one face with outward unit normals ``n`` and
    corrections ``delta`` (M,) in mm (see the module docstring)."""
    return -delta[:, None] * direction(x, n, sharp)


def direction(x, n, sharp=None):
    """``D / -delta``: the unit normal away from sharp edges, turned towards the edges'
    vectors within their band (see the module docstring)."""
    if sharp is None or len(sharp.points) == 0:
        return np.array(n, dtype=float)
    return _turn(x, n, sharp)[0]


def displacement_second(x, derivs, n, field, sharp=None, delta=None, slope=None):
    """:func:`displacement` of points ``x`` of one face (``derivs``: ``(Su, Sv, Suu, Suv,
    Svv)`` there) with its second-order term where it slides the face along itself
    (:mod:`surfcomp.core.compensation.region_second`): ``q n`` plus, within the band, the
    part of the edges' second-order vector along the face, both in the share ``lam`` that
    keeps the normal component, so that on an edge both faces add the edge's vector.
    ``delta``: ``field(x)`` when known; ``slope``: see
    :func:`~surfcomp.core.compensation.region_second.normal_term`."""
    delta = field(x) if delta is None else delta
    if sharp is None or len(sharp.points) == 0:
        return -delta[:, None] * np.asarray(n, dtype=float)
    turned, w, lam, second = _turn(x, n, sharp)
    D = -delta[:, None] * turned
    q = normal_term(x, *derivs, n, D, field, here=delta, slope=slope)
    along = second - np.einsum("ij,ij->i", second, n)[:, None] * n
    return D + lam[:, None] * (q[:, None] * n + w[:, None] * along)


def _turn(x, n, sharp):
    """:func:`direction`, the band's weight ``w``, the share ``lam`` that keeps the normal
    component and the blended second-order edge vector at ``x``."""
    d, m, exact, excess, second = sharp.blend(x)
    s = d / sharp.band
    w = 1.0 - smoothstep((s - 0.1) / 0.9)
    lam = exact + (1.0 - exact) * smoothstep(s / 0.5)
    mn = np.einsum("ij,ij->i", m, n)
    # lam = 1: n plus the excess's part along the face (the normal component kept); on
    # the edge the face's normal is its own there and this is m; lam = 0: m alone
    along = (excess - m) - np.einsum("ij,ij->i", excess - m, n)[:, None] * n
    turned = m + lam[:, None] * ((1.0 - mn)[:, None] * n + along)
    return (1.0 - w)[:, None] * n + w[:, None] * turned, w, lam, second


def designed_share(x, n, sharp=None):
    """The share of the correction the displacement puts along the normal at ``x``: 1
    except near knife edges and vertices, where the edge is moved by one vector."""
    return np.einsum("ij,ij->i", direction(x, n, sharp), n)


def _splits(knots, degree, step):
    """Parts each knot span of ``knots`` is split into so no span is wider than ``step``
    and every span is split at least once."""
    br = np.unique(knots[degree:len(knots) - degree])
    # a narrow face (a blade's tip cap, a few mm across) still gets MIN_SPANS spans: the
    # displacement turns from one edge's vector to the other's across it
    step = min(step, (br[-1] - br[0]) / MIN_SPANS)
    fine = len(br) > HALVED_SPANS
    # every span at least halved (the nominal's own spans leave no room for the field)
    # unless there are many, already finer than a quarter step: a blade side's 523
    # chordwise spans would take the budget its few spanwise ones need
    return np.array([max(1 if fine and b - a <= 0.25 * step else 2,
                         int(math.ceil((b - a) / step - 1e-9)))
                     for a, b in zip(br[:-1], br[1:])], dtype=int)


def _inserted(knots, degree, splits):
    """The knots splitting each span of ``knots`` into ``splits`` equal parts."""
    br = np.unique(knots[degree:len(knots) - degree])
    new = [a + (b - a) * np.arange(1, k) / k for a, b, k in zip(br[:-1], br[1:], splits)]
    return np.concatenate(new) if new else np.array([])


def knot_plans(surfaces, knot_step, max_factor=POLE_FACTOR):
    """How :func:`corrected_surface` refines each of ``surfaces``: per surface
    ``(splits_u, splits_v, step)``, the parts each knot span is split into and the knot
    step (mm) that holds the pole budget. Surfaces with the same degrees and numbers of
    knot spans (a blade's two sides, made alike) split each span into as many parts (the
    most any of them needs, the step growing until every budget holds): their knots then
    correspond, and along an edge they share their fits miss its displacement alike
    (split by their own lengths, at 8 times the nominal's poles, the sides took 79 and 80
    spanwise poles and the trailing edge opened by 0.29 um)."""
    ups = [elevated(s) for s in surfaces]

    def key(s):
        return (s.degree_u, s.degree_v, len(np.unique(s.knots_u)), len(np.unique(s.knots_v)))

    out = [None] * len(ups)
    for k in {key(s) for s in ups}:
        group = [i for i, s in enumerate(ups) if key(s) == k]
        sizes = [face_lengths(ups[i]) for i in group]
        budgets = [max(max_factor * np.prod(surfaces[i].poles.shape[:2]), MIN_BUDGET)
                   for i in group]
        step = float(knot_step)
        while True:
            su = np.max([_splits(ups[i].knots_u, ups[i].degree_u, step / max(lu, 1e-12))
                         for i, (lu, _) in zip(group, sizes)], axis=0)
            sv = np.max([_splits(ups[i].knots_v, ups[i].degree_v, step / max(lv, 1e-12))
                         for i, (_, lv) in zip(group, sizes)], axis=0)
            if all((ups[i].poles.shape[0] + np.sum(su - 1)) * (ups[i].poles.shape[1]
                                                              + np.sum(sv - 1)) <= b
                   for i, b in zip(group, budgets)):
                break
            step *= 1.25
        for i in group:
            out[i] = (su, sv, step)
    return out


def face_lengths(surf):
    """Largest length (mm) of the surface per unit of u and of v."""
    us = np.linspace(surf.knots_u[surf.degree_u], surf.knots_u[-surf.degree_u - 1], 41)
    vs = np.linspace(surf.knots_v[surf.degree_v], surf.knots_v[-surf.degree_v - 1], 41)
    P = evaluate_grid(surf, us, vs)
    lu = np.max(np.sum(np.linalg.norm(np.diff(P, axis=0), axis=2), axis=0)) / (us[-1] - us[0])
    lv = np.max(np.sum(np.linalg.norm(np.diff(P, axis=1), axis=2), axis=1)) / (vs[-1] - vs[0])
    return lu, lv


def _elevated_knots(knots, degree, to):
    br, mult = np.unique(knots, return_counts=True)
    mult[1:-1] += to - degree
    mult[[0, -1]] = to + 1
    return np.repeat(br, mult)


def elevated(surf, to=2):
    """The polynomial surface ``surf`` with its degrees raised to ``to`` where lower (a
    ruled cap of degree 1 cannot follow a correction that varies across it); the same
    surface, its poles fitted exactly (least squares on the elevated basis, which holds
    the nominal). Rational surfaces are kept as they are."""
    if surf.weights is not None or (surf.degree_u >= to and surf.degree_v >= to):
        return surf
    pu, pv = max(surf.degree_u, to), max(surf.degree_v, to)
    ku = _elevated_knots(surf.knots_u, surf.degree_u, pu)
    kv = _elevated_knots(surf.knots_v, surf.degree_v, pv)
    us, vs = _samples(ku, pu, pu + 2), _samples(kv, pv, pv + 2)
    poles = fit_grid_lsq(us, vs, evaluate_grid(surf, us, vs), ku, kv, pu, pv)
    return Surface(poles, ku, kv, pu, pv, None, surf.u_range, surf.v_range)


def _samples(knots, degree, per_span):
    br = np.unique(knots[degree:len(knots) - degree])
    t = [np.linspace(a, b, per_span + 1)[:-1] for a, b in zip(br[:-1], br[1:])]
    return np.concatenate(t + [br[-1:]])


@dataclass
class Built:
    """A corrected surface and its pole count beside the nominal's."""

    surface: Surface
    poles: tuple
    nominal_poles: tuple
    knot_step: float


def corrected_surface(surf, outward, field, sharp=None, knot_step=1.0, max_factor=POLE_FACTOR,
                      plan=None):
    """The corrected surface of one face of a region.

    The nominal's knots refined to ``knot_step`` within the pole budget; then, for up to
    :data:`REFINE_ROUNDS` rounds while the budget holds, the knot spans along a boundary
    where the boundary curve misses the displacement by more than :data:`EDGE_TOL`
    halfway between two fit samples are halved and the face fitted again.

    Parameters
    ----------
    surf : Surface
        The face's nominal (work) surface (rational: the corrected surface keeps the
        weights of the refined nominal and its poles are fitted to the moved points).
    outward : {1, -1}
        Sign turning ``Su x Sv`` into the outward normal.
    field : callable
        ``field(x)`` -> corrections (mm, positive inwards) at points (M, 3).
    sharp : SharpEdges, optional
    knot_step : float
        Largest knot span (mm) of the corrected surface (the field's length scale / 3).
    max_factor : float
        Pole budget: at most this many times the nominal's poles (at least MIN_BUDGET);
        the knot step grows until the budget holds.
    plan : tuple, optional
        The surface's :func:`knot_plans` (default its own alone).

    Returns
    -------
    Built
    """
    nominal = surf.poles.shape[:2]
    original = surf
    surf = elevated(surf)       # degree 1 (a ruled cap) to 2; the sides keep theirs
    budget = max(max_factor * nominal[0] * nominal[1], MIN_BUDGET)
    su, sv, step = plan if plan is not None else knot_plans([original], knot_step,
                                                           max_factor)[0]
    ref = insert_knots(surf, _inserted(surf.knots_u, surf.degree_u, su),
                       _inserted(surf.knots_v, surf.degree_v, sv))
    surf = original     # the zero correction returns it
    grid = _Grid(ref, outward, field, sharp)
    poles = grid.fit()
    if poles is None:       # zero correction: the nominal itself, not a refined copy
        return Built(surf, nominal, nominal, step)
    # spans along a boundary where the boundary curve misses the displacement get halved
    # while the budget holds: two faces meet along a shared edge as closely as both follow
    # it, and the displacement varies fastest along an edge (a fold's vector)
    for _ in range(REFINE_ROUNDS):
        nu, nv = grid.misfit_spans(poles)
        if not (len(nu) or len(nv)) or (grid.ref.poles.shape[0] + len(nu)) * (
                grid.ref.poles.shape[1] + len(nv)) > budget:
            break
        grid.refine(nu, nv)
        poles = grid.fit()
    ref = grid.ref
    out = Surface(poles, ref.knots_u, ref.knots_v, ref.degree_u, ref.degree_v, ref.weights,
                  surf.u_range, surf.v_range)
    return Built(out, poles.shape[:2], nominal, step)


class _Grid:
    """The fit samples of a refined surface and the displacement at them (kept for the
    rows and columns a refinement leaves in place)."""

    def __init__(self, ref, outward, field, sharp):
        self.ref, self.outward, self.field, self.sharp = ref, outward, field, sharp
        self.us = _samples(ref.knots_u, ref.degree_u, PER_SPAN)
        self.vs = _samples(ref.knots_v, ref.degree_v, PER_SPAN)
        self.P, self.D = self._moved(self.us, self.vs, dense=True)

    def _moved(self, us, vs, dense=False):
        """The points and their displacement on the grid ``us x vs``; ``dense``: the fit's
        whole grid, where the correction's change along a slide is taken from its
        differences between the samples (the field evaluated once per sample)."""
        P, *derivs = evaluate_grid(self.ref, us, vs, order=2)
        n = self.outward * _unit(np.cross(derivs[0], derivs[1]))
        flat = [a.reshape(-1, 3) for a in derivs]
        x = P.reshape(-1, 3)
        delta = self.field(x)
        slope = None
        if dense and len(us) > 2 and len(vs) > 2:
            slope = [g.ravel() for g in np.gradient(delta.reshape(len(us), len(vs)), us, vs)]
        D = displacement_second(x, flat, n.reshape(-1, 3), self.field, self.sharp,
                                delta=delta, slope=slope).reshape(P.shape)
        return P, D

    def fit(self):
        """Poles of the nominal plus the displacement (None where it is nil)."""
        ref = self.ref
        if not np.any(self.D):
            return None
        # the boundary curves fitted on their own: an edge on both faces' boundaries takes
        # each face's accuracy along it (region_fit)
        if ref.weights is None:
            return ref.poles + fit_ends_held(self.us, self.vs, self.D, ref.knots_u,
                                             ref.knots_v, ref.degree_u, ref.degree_v)
        # rational: the moved points, the weights kept
        return fit_ends_held(self.us, self.vs, self.P + self.D, ref.knots_u, ref.knots_v,
                             ref.degree_u, ref.degree_v, weights=ref.weights)

    def misfit_spans(self, poles):
        """Midpoints of the knot spans along each boundary where the fitted surface misses
        the displacement by more than :data:`EDGE_TOL` halfway between two samples."""
        ref = self.ref
        fitted = Surface(poles, ref.knots_u, ref.knots_v, ref.degree_u, ref.degree_v,
                         ref.weights, ref.u_range, ref.v_range)
        out = []
        for along, ends, knots, degree in ((self.us, self.vs[[0, -1]], ref.knots_u,
                                            ref.degree_u),
                                           (self.vs, self.us[[0, -1]], ref.knots_v,
                                            ref.degree_v)):
            mid = 0.5 * (along[1:] + along[:-1])
            grid = (mid, ends) if along is self.us else (ends, mid)
            P, D = self._moved(*grid)
            miss = np.linalg.norm(evaluate_grid(fitted, *grid) - P - D, axis=2)
            bad = mid[np.max(miss, axis=1 if along is self.us else 0) > EDGE_TOL]
            br = np.unique(knots[degree:len(knots) - degree])
            k = np.unique(np.clip(np.searchsorted(br, bad) - 1, 0, len(br) - 2))
            out.append(0.5 * (br[k] + br[k + 1]))
        return out

    def refine(self, nu, nv):
        """Insert the knots; the displacement is evaluated again at new samples only."""
        self.ref = insert_knots(self.ref, nu, nv)
        us = _samples(self.ref.knots_u, self.ref.degree_u, PER_SPAN)
        vs = _samples(self.ref.knots_v, self.ref.degree_v, PER_SPAN)
        P, D = (np.empty((len(us), len(vs), 3)) for _ in range(2))
        ou, ov = np.isin(us, self.us), np.isin(vs, self.vs)
        iu, iv = np.searchsorted(self.us, us[ou]), np.searchsorted(self.vs, vs[ov])
        P[np.ix_(ou, ov)] = self.P[np.ix_(iu, iv)]
        D[np.ix_(ou, ov)] = self.D[np.ix_(iu, iv)]
        for rows, cols in ((~ou, np.ones(len(vs), bool)), (ou, ~ov)):
            if rows.any() and cols.any():
                P[np.ix_(rows, cols)], D[np.ix_(rows, cols)] = self._moved(us[rows], vs[cols])
        self.us, self.vs, self.P, self.D = us, vs, P, D
