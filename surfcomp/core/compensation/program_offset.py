# SPDX-License-Identifier: LGPL-2.1-or-later
"""Direct program compensation: move a ball-end finishing program by the surface correction.

Instead of regenerating the tool path on the corrected face (CAM), each cutter-location
point of the existing program is moved (issue 27):

* the program gives the tool tip, the ball's lowest point; the centre ``C`` is ``R`` above
  it (3-axis, tool along +Z);
* the contact point ``F`` on the nominal face is the centre's closest point
  (:class:`surfcomp.core.surface.projection.Projector`); a ball touching the face has its centre
  on the face's normal at ``F``, one radius away;
* the corrected face is ``S - t n`` (``t`` the correction realised by it at ``F`` along the
  outward normal ``n``, :func:`surfcomp.core.compensation.corrected.realised_correction`), so the
  ball touching it has its centre at ``C - t n``: the tip moves by ``-t n`` as well. Moving the
  contact along the normal keeps the ball tangent to first order; what is left is
  ``R (1 - cos a)`` with ``a`` the tilt of the normal between nominal and corrected face
  (slopes of the correction of ~1e-3: ~1e-6 R);
* beyond the face (centres farther than ``R`` from it: the tool has left the face or is
  above it) the correction fades out with the clearance ``e = |C - F| - R`` over the
  blend length (:func:`blend_weight`, a cubic with zero slope at both ends: no step);
* moves are subdivided where the moved path would leave the straight line between moved
  points by more than the tolerance (:func:`plan_offset`); moves that nothing moves are
  kept as programmed.

Flat and bull-nose cutters touch a face along their flat bottom or torus, whose contact
point is not the centre's projection; they are refused (:func:`parse_tool`).
"""

import math
from dataclasses import dataclass

import numpy as np

from ...errors import GCodeError, InputError
from ..axis.arcs import PLANES, arc_params, arc_steps
from ..axis.moves import MovePlan
from ..surface import bspline
from ..surface.projection import Projector
from ..surface.projection_chain import project_chain

#: tool shapes :func:`parse_tool` knows
TOOL_KINDS = ("ball", "flat", "bull")
#: deepest accepted cut of a cutting point into the nominal, and the largest stock or
#: radius effect accepted at the contact points (mm): a finishing program made with the
#: right ball radius sits on the ball's offset surface within its CAM tolerance (a few um)
CONTACT_TOL = 0.01
#: most bisections of one piece of a move
MAX_DEPTH = 24
#: a piece is halved when its midpoint is off by more than this share of the tolerance
#: (the largest deviation lies near, not exactly at, the midpoint)
SPLIT_SHARE = 0.9


def parse_tool(text, option="tool"):
    """``(kind, radius)`` of a tool given as ``ball:R`` (mm).

    Raises
    ------
    InputError
        Anything but a ball end of finite positive radius; flat (``flat:R``) and
        bull-nose (``bull:R:r``) cutters are refused with the reason.
    """
    parts = [p.strip() for p in str(text).split(":")]
    kind = parts[0].lower()
    if kind in ("flat", "bull"):
        raise InputError("%s %s: only ball-end cutters can be compensated directly (a %s "
                         "cutter touches the face on its %s, not at the centre's closest "
                         "point); regenerate its program on the corrected face instead"
                         % (option, text, "flat" if kind == "flat" else "bull-nose",
                            "flat bottom" if kind == "flat" else "corner torus"),
                         options=(option,))
    try:
        radius = float(parts[1]) if kind == "ball" and len(parts) == 2 else math.nan
    except ValueError:
        radius = math.nan
    if not (math.isfinite(radius) and 0 < radius <= 500):
        raise InputError("%s %s: expected ball:R, the ball radius R in mm (0 < R <= 500), "
                         "e.g. ball:3 for a 6 mm ball end mill" % (option, text),
                         options=(option,))
    return "ball", radius


def blend_weight(e, blend):
    """Share of the correction at clearance ``e`` (mm) beyond the ball's contact.

    1 where ``e <= 0`` (the ball touches the face), 0 from ``e >= blend`` on, and
    ``1 - 3 s^2 + 2 s^3`` with ``s = e / blend`` between: continuous with its slope.
    """
    s = np.clip(np.asarray(e, dtype=float) / blend, 0.0, 1.0)
    return np.where(np.isfinite(e), 1.0 - s * s * (3.0 - 2.0 * s), 0.0)


@dataclass
class Displacement:
    """What :meth:`BallOffset.displace` found for N tool-tip points.

    ``move`` (N, 3): the tip's displacement (mm); ``gap`` (N,): ``|C - F| - R`` (mm;
    negative: the ball cuts into the nominal; inf beyond the search distance); ``weight``
    (N,): :func:`blend_weight`; ``tilt`` (N,): ``1 - n_z`` of the outward normal at the
    contact; ``interior`` (N,): the contact lies inside the face (not on its border).
    """

    move: np.ndarray
    gap: np.ndarray
    weight: np.ndarray
    tilt: np.ndarray
    interior: np.ndarray


class BallOffset:
    """The displacement of ball-end tool tips by a surface correction.

    Parameters
    ----------
    surface : surfcomp.core.surface.bspline.Surface
        The nominal face (its work area is the face).
    outward : {1, -1}
        Sign turning ``Su x Sv`` into the outward normal (the tool's side).
    radius : float
        Ball radius R (mm).
    correction : callable
        ``correction(u, v) -> t`` (mm, arrays (k,)): the correction at the contact points,
        positive inwards (the corrected face is ``S - t n``).
    blend : float
        Clearance (mm) over which the correction fades out beyond the face (> 0).
    warm : bool
        Project the points of a call, which follow the path, from nearby feet
        (:func:`surfcomp.core.surface.projection_chain.project_chain`; the full engine's
        results to ~1e-10 mm); False: every point through the full engine. A ``correction``
        with an ``at(u, v, foot, normal)`` method
        (:class:`surfcomp.core.compensation.realised_feet.RealisedAt`) is given the feet too.
    trim : surfcomp.core.compensation.program_trim.Trim, optional
        The trimmed face's boundary: a centre whose foot lies outside the trimmed face
        (beyond its outer boundary or in a hole) is measured from the boundary's closest
        point, and the correction there fades out over the blend as beyond the surface's
        edge. None: the face is its whole surface.
    """

    def __init__(self, surface, outward, radius, correction, blend, warm=True, trim=None):
        if not (math.isfinite(blend) and blend > 0):
            raise InputError("blend %r: expected a positive length in mm" % blend,
                             options=("blend",))
        self.surface = surface
        self.outward = int(outward)
        self.radius = float(radius)
        self.correction = correction
        self.blend = float(blend)
        #: centres farther than this from the face are not projected (moved by nothing)
        self.reach = self.radius + self.blend + 1.0
        self.projector = Projector(surface)
        self.warm = bool(warm)
        self.trim = trim
        #: points projected from a nearby foot (``'warm'``) and by the full engine
        self.counts = {"warm": 0, "full": 0}

    def displace(self, tips):
        """The :class:`Displacement` of tool tips ``tips`` (N, 3) (mm)."""
        tips = np.asarray(tips, dtype=float).reshape(-1, 3)
        n = tips.shape[0]
        move = np.zeros((n, 3))
        gap = np.full(n, np.inf)
        weight = np.zeros(n)
        tilt = np.zeros(n)
        interior = np.zeros(n, dtype=bool)
        if n == 0:
            return Displacement(move, gap, weight, tilt, interior)
        centre = tips.copy()
        centre[:, 2] += self.radius
        if self.warm:
            pr = project_chain(self.projector, centre, self.reach, counts=self.counts)
        else:
            pr = self.projector.project(centre, max_distance=self.reach)
            self.counts["full"] += n
        ok = pr.converged & np.isfinite(pr.u)
        u, v, foot, normal = pr.u.copy(), pr.v.copy(), pr.foot.copy(), pr.normal.copy()
        side = np.sign(pr.distance * self.outward)
        dist = np.linalg.norm(centre - foot, axis=1)
        interior[ok] = ~pr.outside[ok]
        if self.trim is not None and ok.any():
            # feet outside the trimmed face: the ball touches it, if at all, on its boundary
            k = np.flatnonzero(ok)
            k = k[self.trim.outside(u[k], v[k])]
            if k.size:
                _x, u[k], v[k], dist[k] = self.trim.closest(centre[k])
                foot[k], Su, Sv = bspline.derivatives(self.surface, u[k], v[k], order=1)
                normal[k] = bspline.unit_normals(self.surface, u[k], v[k], Su, Sv)
                side[k], interior[k] = 1.0, False
        normal = normal * self.outward
        # a centre on the material side is inside the nominal by its distance plus R
        gap[ok] = np.where(side[ok] >= 0, dist[ok], -dist[ok]) - self.radius
        weight[ok] = blend_weight(gap[ok], self.blend)
        tilt[ok] = 1.0 - normal[ok, 2]
        act = np.flatnonzero(ok & (weight > 0))
        if act.size:
            at = getattr(self.correction, "at", None)
            t = np.asarray(self.correction(u[act], v[act]) if at is None
                           else at(u[act], v[act], foot[act], normal[act] * self.outward),
                           dtype=float)
            move[act] = -(weight[act] * t)[:, None] * normal[act]
        return Displacement(move, gap, weight, tilt, interior)


@dataclass
class OffsetPlan:
    """A :class:`surfcomp.core.axis.moves.MovePlan` of moved points, and what the contact check
    needs of the move ends: per move ``gap``, ``tilt``, ``interior`` (see
    :class:`Displacement`), ``checked``, the number of points whose displacement was
    computed (moved or not), ``largest`` the largest displacement (mm) and ``moved`` (m,)
    bool the moves written moved."""

    plan: MovePlan
    gap: np.ndarray
    tilt: np.ndarray
    interior: np.ndarray
    checked: int
    largest: float
    moved: np.ndarray


class _Arcs:
    """Points on the arcs of a block at any fractions of their sweep."""

    def __init__(self, prog, idx):
        self.row = {int(j): k for k, j in enumerate(idx)}
        n = len(idx)
        self.a0, self.theta, self.r0, self.r1 = (np.zeros(n) for _ in range(4))
        self.axes = np.zeros((n, 3), dtype=int)
        for k, j in enumerate(idx):
            th, r0, r1, a0 = arc_params(prog.start[j], prog.end[j], prog.centre[j],
                                        prog.plane[j], prog.kind[j] == 2, prog.turns[j])
            self.a0[k], self.theta[k], self.r0[k], self.r1[k] = a0, th, r0, r1
            self.axes[k] = PLANES[int(prog.plane[j])]
        self.prog = prog

    def at(self, moves, f):
        """Points (k, 3) of arc moves ``moves`` (block indices) at sweep fractions ``f``."""
        rows = np.array([self.row[int(j)] for j in moves], dtype=int)
        prog = self.prog
        s, e, c = prog.start[moves], prog.end[moves], prog.centre[moves]
        ang = self.a0[rows] + self.theta[rows] * f
        r = self.r0[rows] + (self.r1[rows] - self.r0[rows]) * f
        ax = self.axes[rows]
        out = np.empty((len(moves), 3))
        k = np.arange(len(moves))
        p, q, w = ax[:, 0], ax[:, 1], ax[:, 2]
        out[k, p] = c[k, p] + r * np.cos(ang)
        out[k, q] = c[k, q] + r * np.sin(ang)
        out[k, w] = s[k, w] + (e[k, w] - s[k, w]) * f
        end = f >= 1.0
        out[end] = e[end]
        return out


def _points(prog, arcs, moves, f):
    """Programmed points of ``moves`` at fractions ``f`` (lines straight, arcs swept)."""
    pts = prog.start[moves] + (prog.end[moves] - prog.start[moves]) * f[:, None]
    isarc = prog.kind[moves] >= 2
    if isarc.any():
        pts[isarc] = arcs.at(moves[isarc], f[isarc])
    return pts


def _seg_dist(p, a, b):
    """Distance of points ``p`` from the segments ``a``-``b`` (all (k, 3))."""
    ab = b - a
    den = np.einsum("ij,ij->i", ab, ab)
    s = np.where(den > 0, np.einsum("ij,ij->i", p - a, ab) / np.where(den > 0, den, 1), 0.0)
    s = np.clip(s, 0.0, 1.0)
    return np.linalg.norm(p - (a + s[:, None] * ab), axis=1)


def plan_offset(prog, offset, tolerance, segment_length, still, start_move=None, count=None):
    """Moved points of every move of a block (:class:`OffsetPlan`).

    Parameters
    ----------
    prog : surfcomp.io.gcode.Program
        The block's moves (mm, absolute).
    offset : BallOffset
    tolerance : float
        Largest distance (mm) of the written straight pieces from the exactly moved path,
        checked at the midpoint of every piece where the displacement's curvature
        (estimated from its second differences between neighbouring points) could put it
        beyond half the tolerance; a piece that fails is halved until it passes.
    segment_length : float
        Longest piece (mm) at which a long move is first sampled, so that nothing near the
        face between its ends is missed.
    still : float
        A displacement at most this (mm; below half the output resolution) moves nothing:
        a move moved nowhere by more is kept as programmed (arcs stay arcs).
    start_move : ndarray (3,), optional
        Displacement of the block's first start point (the previous block's last end).
    count : surfcomp.core.compensation.program_limit.PieceCount, optional
        The pieces of the program's blocks so far: a block that would take the program
        past its limit is refused before its pieces are made.

    Returns
    -------
    OffsetPlan
    """
    m = prog.n_moves
    kind = prog.kind
    arcs = _Arcs(prog, np.flatnonzero(kind >= 2))
    known = prog.known.all(axis=1)
    end_d = offset.displace(np.where(known[:, None], prog.end, np.nan))
    checked = m
    start_d = np.zeros((m, 3))
    if m:
        start_d[1:] = end_d.move[:-1]
        start_d[0] = 0.0 if start_move is None else start_move
    length = np.linalg.norm(prog.end - prog.start, axis=1)
    nseg = np.ones(m, dtype=int)
    long_lines = np.flatnonzero((kind == 1) & (length > segment_length))
    nseg[long_lines] = np.ceil(length[long_lines] / segment_length - 1e-9).astype(int)
    for j in np.flatnonzero(kind >= 2):
        nseg[j] = arc_steps(prog.start[j], prog.end[j], prog.centre[j], prog.plane[j],
                            kind[j] == 2, prog.turns[j], segment_length, tolerance)
    # moves whose every point is farther than the blend from the face move nowhere
    gap_start = np.r_[np.inf, end_d.gap[:-1]] if m else np.zeros(0)
    reach = np.minimum(np.where(np.isfinite(gap_start), gap_start, offset.reach),
                       np.where(np.isfinite(end_d.gap), end_d.gap, offset.reach))
    # every point of a line is within half its length of an end, of an arc within its
    # diameter
    bound = 0.5 * length
    if arcs.row:
        idx = np.fromiter(arcs.row, dtype=int)
        bound[idx] = 2.0 * np.maximum(arcs.r0, arcs.r1)
    near = (kind >= 1) & known & (reach - bound < offset.blend)
    if count is not None:
        count.admit(prog, near, nseg, length)
    # pieces: owner move, fractions fa < fb, displacements at both ends
    owner = np.repeat(np.flatnonzero(near), nseg[near])
    step = np.arange(owner.size) - np.repeat(np.cumsum(nseg[near]) - nseg[near], nseg[near])
    fa = step / nseg[owner]
    fb = (step + 1) / nseg[owner]
    inner = fb < 1.0
    da = np.empty((owner.size, 3))
    db = np.empty((owner.size, 3))
    if inner.any():
        d_in = offset.displace(_points(prog, arcs, owner[inner], fb[inner])).move
        checked += int(inner.sum())
        db[inner] = d_in
    db[~inner] = end_d.move[owner[~inner]]
    first = fa == 0.0
    da[first] = start_d[owner[first]]
    da[~first] = db[np.flatnonzero(~first) - 1]
    sampled = owner.size
    owner, fa, fb, da, db, n_new = _refine(prog, arcs, offset, owner, fa, fb, da, db,
                                           tolerance)
    if count is not None:
        count.refined(owner.size - sampled)
    return _assemble(prog, owner, fb, db, end_d, start_d, still, checked + n_new, arcs)


def _curvature_suspects(owner, fa, fb, pa, pb, da, db):
    """Pieces whose moved path may leave its chord by more than a quarter of the
    tolerance: ``K L^2 / 8`` with ``K`` twice the largest second divided difference of the
    displacement at the piece's ends (over the pieces joined to it: the next piece of the
    same move, or the first piece of the next move), and the pieces joined to none."""
    n = owner.size
    L = np.linalg.norm(pb - pa, axis=1)
    slope = (db - da) / np.where(L > 0, L, 1.0)[:, None]
    K = np.zeros(n)
    joined = np.zeros(max(n - 1, 0), dtype=bool)
    if n > 1:
        joined = (owner[1:] == owner[:-1]) | ((owner[1:] == owner[:-1] + 1)
                                              & (fb[:-1] == 1.0) & (fa[1:] == 0.0))
        h = 0.5 * (L[1:] + L[:-1])
        dd = np.linalg.norm(slope[1:] - slope[:-1], axis=1) / np.where(h > 0, h, np.inf)
        dd = np.where(joined, dd, 0.0)
        K[1:] = np.maximum(K[1:], dd)
        K[:-1] = np.maximum(K[:-1], dd)
    alone = np.ones(n, dtype=bool)
    alone[1:] &= ~joined
    alone[:-1] &= ~joined
    return 2.0 * K * L * L / 8.0, alone


def _refine(prog, arcs, offset, owner, fa, fb, da, db, tolerance):
    """Halve the pieces whose moved midpoint leaves the moved chord by more than the
    tolerance, until none does; returns the pieces and the number of points whose
    displacement was computed."""
    added = 0
    pa = _points(prog, arcs, owner, fa)
    pb = _points(prog, arcs, owner, fb)
    est, alone = _curvature_suspects(owner, fa, fb, pa, pb, da, db)
    moving = (np.abs(da).max(axis=1, initial=0) > 0) | (np.abs(db).max(axis=1, initial=0) > 0)
    # a moved piece is checked where the curvature estimate allows more than a quarter of
    # the tolerance, on arcs, and alone; an unmoved piece of a move near the face is
    # checked once (the face may lie between its ends)
    check = moving & ((est > 0.25 * tolerance) | (prog.kind[owner] >= 2) | alone)
    check |= ~moving & (np.linalg.norm(pb - pa, axis=1) > 0)
    for depth in range(MAX_DEPTH + 1):
        idx = np.flatnonzero(check)
        if idx.size == 0:
            break
        if depth == MAX_DEPTH:
            raise GCodeError("a move cannot be followed within tolerance %g mm after %d "
                             "halvings: the correction changes too abruptly along it"
                             % (tolerance, MAX_DEPTH), file=prog.source,
                             line=int(prog.line[owner[idx[0]]]) + 1, options=("tolerance",))
        fm = 0.5 * (fa[idx] + fb[idx])
        pm = _points(prog, arcs, owner[idx], fm)
        dm = offset.displace(pm).move
        added += idx.size
        dev = _seg_dist(pm + dm, pa[idx] + da[idx], pb[idx] + db[idx])
        ends_moved = (np.abs(da[idx]).max(axis=1) > 0) | (np.abs(db[idx]).max(axis=1) > 0)
        # an unmoved piece with a moved midpoint is halved too: its chord is the programmed
        # line, but the path near the face must be followed
        bad = (dev > SPLIT_SHARE * tolerance) | ((np.abs(dm).max(axis=1) > 0) & ~ends_moved)
        if not bad.any():               # every piece checked passes: nothing to halve
            break
        split = np.zeros(owner.size, dtype=bool)
        split[idx[bad]] = True
        mid_of = np.full(owner.size, -1)
        mid_of[idx] = np.arange(idx.size)
        reps = np.where(split, 2, 1)
        new = np.repeat(np.arange(owner.size), reps)
        ends = np.cumsum(reps)
        left = np.zeros(new.size, dtype=bool)
        left[(ends - reps)[split]] = True
        right = np.zeros(new.size, dtype=bool)
        right[ends[split] - 1] = True
        k_mid = mid_of[new]
        fa, fb, da, db, pa, pb = (a[new] for a in (fa, fb, da, db, pa, pb))
        owner = owner[new]
        fb[left], db[left], pb[left] = fm[k_mid[left]], dm[k_mid[left]], pm[k_mid[left]]
        fa[right], da[right], pa[right] = fm[k_mid[right]], dm[k_mid[right]], pm[k_mid[right]]
        check = left | right            # the halves are checked again; the rest are done
    return owner, fa, fb, da, db, added


def _assemble(prog, owner, fb, db, end_d, start_d, still, checked, arcs):
    """The :class:`OffsetPlan` from the refined pieces of the moves near the face.

    A move is moved when a point of it moves by more than ``still`` (an arc also when
    its start did: its centre would no longer fit); the others are written as programmed.
    Of a moved move, an inner point is dropped when it and both its neighbours are unmoved
    (they lie on the programmed line)."""
    m = prog.n_moves
    big = np.abs(db).max(axis=1, initial=0) > still
    moved = np.zeros(m, dtype=bool)
    moved[owner[big]] = True            # any of its pieces (ufunc.at: 10x slower)
    moved |= np.abs(end_d.move).max(axis=1, initial=0) > still
    moved |= (prog.kind >= 2) & (np.abs(start_d).max(axis=1, initial=0) > still)
    sel = moved[owner]
    owner, fb, db, big = owner[sel], fb[sel], db[sel], big[sel]
    last = np.r_[owner[1:] != owner[:-1], True][:owner.size]
    first = np.r_[True, owner[1:] != owner[:-1]][:owner.size]
    prev_big = np.where(first, np.abs(start_d[owner]).max(axis=1, initial=0) > still,
                        np.r_[False, big[:-1]][:owner.size])
    next_big = np.r_[big[1:], False][:owner.size]
    keep_pt = last | big | prev_big | next_big
    owner, fb, db = owner[keep_pt], fb[keep_pt], db[keep_pt]
    pts = _points(prog, arcs, owner, fb)
    # every other move: its end, moved (a rapid) or as programmed
    has = np.zeros(m, dtype=bool)
    has[owner] = True
    rest = np.flatnonzero(~has)
    all_owner = np.r_[owner, rest].astype(int)
    all_pts = np.concatenate([pts, prog.end[rest]])
    all_d = np.concatenate([db, np.where(moved[rest, None], end_d.move[rest], 0.0)])
    order = np.argsort(all_owner, kind="stable")
    all_owner, all_pts, all_d = all_owner[order], all_pts[order], all_d[order]
    counts = np.bincount(all_owner, minlength=m)
    offsets = np.zeros(m + 1, dtype=int)
    np.cumsum(counts, out=offsets[1:])
    all_pts[offsets[1:] - 1] = prog.end      # exact ends
    split = moved & (counts > 1)
    keep = (prog.kind >= 2) & ~moved
    plan = MovePlan(offsets, all_pts, all_pts + all_d, split, keep, np.zeros(m))
    largest = float(np.linalg.norm(all_d, axis=1).max(initial=0.0))
    return OffsetPlan(plan, end_d.gap, end_d.tilt, end_d.interior, checked, largest, moved)


@dataclass
class ContactFit:
    """How the program's cutter-location points sit on the nominal (:func:`fit_contact`).

    ``stock``: mean clearance of the contact points (mm; ~0 for a finishing program);
    ``radius_error``: the true ball radius minus the one given (mm; None when the
    contact points are too flat to tell); ``points``: contact points used; ``max_tilt``:
    largest normal tilt among them (degrees); ``deepest``: most negative clearance of any
    cutting point inside the face (mm) and ``deepest_line`` its 1-based line."""

    stock: float
    radius_error: object
    points: int
    max_tilt: float
    deepest: float
    deepest_line: int

    @property
    def radius_effect(self):
        """How far off (mm) the radius error puts the steepest contact point: ``|dR| (1 -
        cos max_tilt)``; None when the radius is not checked."""
        if self.radius_error is None:
            return None
        return abs(self.radius_error) * (1.0 - math.cos(math.radians(self.max_tilt)))


def fit_contact(gap, tilt, interior, lines, radius):
    """Fit the contact points' clearance ``gap = stock + dR (1 - n_z)``.

    A ball of true radius ``R + dR`` whose tip is programmed sits, on a face tilted by
    ``a``, at clearance ``dR (1 - cos a)`` from the offset of a ball of radius ``R``; the
    stock adds to every point. Points whose contact is inside the face with clearance
    within ``R / 4`` are used; outliers (air moves near the face, contact with other
    faces) are dropped over three robust passes.

    Parameters
    ----------
    gap, tilt : ndarray (N,)
        :class:`Displacement` fields of the cutting moves' end points.
    interior : ndarray (N,) bool
    lines : ndarray (N,) int
        1-based program line of each point.
    radius : float

    Returns
    -------
    ContactFit
    """
    inside = interior & np.isfinite(gap)
    deepest, deepest_line = 0.0, 0
    if inside.any():
        k = np.flatnonzero(inside)[np.argmin(gap[inside])]
        deepest, deepest_line = float(gap[k]), int(lines[k])
    use = inside & (np.abs(gap) <= 0.25 * radius)
    g, x = gap[use], tilt[use]
    if g.size == 0:
        return ContactFit(0.0, None, 0, 0.0, deepest, deepest_line)
    keep = np.ones(g.size, dtype=bool)
    flat = np.degrees(np.arccos(np.clip(1.0 - x.max(), -1, 1))) < 8.0
    fitted = None           # the points the last pass fitted
    for _ in range(3):
        # a pass on the points the one before fitted fits the same coefficients and keeps
        # the same points: the passes end (docs/direct_program.md, eighth round)
        if fitted is not None and np.array_equal(keep, fitted):
            break
        fitted = keep
        every = bool(keep.all())
        gk, xk = (g, x) if every else (g[keep], x[keep])
        if flat or np.ptp(xk) < 1e-3:
            coef = (float(np.median(gk)), 0.0)
        else:
            A = np.stack([np.ones(gk.size), xk], axis=1)
            sol = np.linalg.lstsq(A, gk, rcond=None)[0]
            coef = (float(sol[0]), float(sol[1]))
        res = g - coef[0] - coef[1] * x
        absres = np.abs(res)
        mad = float(np.median(absres if every else absres[keep])) * 1.4826
        keep = absres <= max(3.0 * mad, 2e-3)
        if keep.sum() < 3:
            break
    tilt_deg = float(np.degrees(np.arccos(np.clip(1.0 - x[keep].max(initial=0.0), -1, 1))))
    return ContactFit(coef[0], None if flat else coef[1], int(keep.sum()), tilt_deg, deepest,
                      deepest_line)
