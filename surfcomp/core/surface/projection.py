# SPDX-License-Identifier: LGPL-2.1-or-later
"""Orthogonal projection of points onto a B-spline face (no FreeCAD).

Method: a dense sample grid of the face (:func:`bspline.evaluate_grid` with
second derivatives) in a ``scipy.spatial.cKDTree`` gives seeds (one query per
voxel of points); two plain Newton steps on ``(S - P) . Su = 0``,
``(S - P) . Sv = 0`` from each seed's stored derivatives finish almost every
point, the rest run safeguarded Newton iterations (second-order Hessian, shifted to
positive definite where it is not, step halving, bound constraints on the work
area). A local minimum is the global one when it is closer than half the face's
smallest radius of curvature, or when the region certificate of its part of the
face covers it (:mod:`surfcomp.core.surface.projection_regions`: curvature towards the
point and clearance to other parts of the face, per tile of the sample grid,
decided once per face). Only the other points are checked one by one: samples
within reach whose one-step prediction lands elsewhere, and (near curvature
centres or where another part of the face comes close) all parts of the face
within reach, seed further Newton runs; the best result wins. Everything is
vectorised over points, chunked and run in threads.

Evaluation and the Newton iterations are in :mod:`surfcomp.core.surface.projection_newton`.
"""

import itertools
import os
import threading
from dataclasses import dataclass

import numpy as np

from ...errors import GeometryError, InputError
from ..chunks import for_chunks
from ..progress import report
from . import bspline
from .kdtree import cKDTree
from .projection_newton import GenericEval, Newton, SpanTable, dot
from .projection_regions import Regions, principal_curvatures

#: points per vectorised Newton chunk: large enough that the two projection threads spend
#: little time in the interpreter between numpy kernels (a quarter of it was measurably
#: slower on a million blade points, bench/bench_scale.py), small enough for the
#: temporaries (~50 MB)
CHUNK = 65536
#: upper bound on the number of seed samples
MAX_SAMPLES = 250_000
#: the power-basis table is used when it has at most this many values
MAX_TABLE_VALUES = 20_000_000
#: feet up to this far from the face (mm) are certified per region of the face
#: (:mod:`surfcomp.core.surface.projection_regions`); farther ones are checked point by point
CERTIFY_DISTANCE = 1.0


@dataclass(frozen=True)
class Projection:
    """Result of :func:`project` for N points.

    Attributes
    ----------
    u, v : ndarray, shape (N,)
        Foot point parameters (inside ``surf.u_range x surf.v_range``).
    foot : ndarray, shape (N, 3)
        Closest point on the face, mm.
    normal : ndarray, shape (N, 3)
        Unit normal ``Su x Sv`` at the foot point.
    distance : ndarray, shape (N,)
        Signed distance ``(point - foot) . normal`` in mm; for ``outside``
        points ``|point - foot|`` with the sign of that dot product.
    outside : ndarray of bool, shape (N,)
        The unconstrained foot point lies outside the work area: the closest
        point is on the face boundary (u or v at a bound).
    converged : ndarray of bool, shape (N,)
        Newton converged: the last full Newton step moved the foot less than
        ``STEP_TOL`` (1e-6 mm, leaving an error ~1e-13 mm), another step less
        than 1e-10 mm, or no further decrease was possible at the rounding
        level. False also for NaN input points and points farther than
        ``max_distance``; their other fields are NaN (``outside`` False).
    derivatives : ndarray, shape (6, 3, N), or None
        ``S, Su, Sv, Suu, Suv, Svv`` at the feet, when asked for (NaN where ``u`` is).
    """

    u: np.ndarray
    v: np.ndarray
    foot: np.ndarray
    normal: np.ndarray
    distance: np.ndarray
    outside: np.ndarray
    converged: np.ndarray
    derivatives: np.ndarray = None

    def __len__(self):
        return self.u.shape[0]


# --------------------------------------------------------------------------- projector

def _sample_params(breaks, per_span, lo, hi):
    """Parameters: ``per_span`` intervals in every span, clipped to [lo, hi]."""
    f = np.linspace(0.0, 1.0, per_span + 1)[:-1]
    t = (breaks[:-1, None] + np.diff(breaks)[:, None] * f[None, :]).ravel()
    t = t[(t > lo) & (t < hi)]
    return np.unique(np.r_[lo, t, hi])


class Projector:
    """Reusable projection engine for one face (samples, KD-tree, span table).

    Parameters
    ----------
    surf : bspline.Surface
        The face; projection stays inside ``surf.u_range x surf.v_range``.
    samples_per_span : int, optional
        Seed sample density: the grid spacing (mm, equal along u and v) is the
        face length over ``spans * samples_per_span`` in the direction that gives
        the finer spacing; default ``3 * (degree + 1)``; coarsened so that the
        grid has at most ``MAX_SAMPLES`` points.
    workers : int, optional
        Threads for the Newton chunks and the KD-tree queries; default: the
        number of CPUs.
    min_samples : int, optional
        Refine the grid until it has about this many samples (at most
        ``MAX_SAMPLES``): closer seeds save Newton iterations when many points
        are projected (:func:`project` asks for one sample per 16 points).
    """

    def __init__(self, surf, samples_per_span=None, workers=None, min_samples=0):
        self.surf = surf
        self.workers = max(1, int(workers or os.cpu_count() or 1))
        if SpanTable.size(surf) <= MAX_TABLE_VALUES:
            self.ev = SpanTable(surf)
            bu, bv = self.ev.bu, self.ev.bv
        else:
            self.ev = GenericEval(surf)
            bu = SpanTable._breaks(surf.knots_u, surf.degree_u, surf.shape[0])
            bv = SpanTable._breaks(surf.knots_v, surf.degree_v, surf.shape[1])
        (u0, u1), (v0, v1) = surf.u_range, surf.v_range
        bu = np.unique(np.r_[u0, bu[(bu > u0) & (bu < u1)], u1])
        bv = np.unique(np.r_[v0, bv[(bv > v0) & (bv < v1)], v1])
        mu = samples_per_span or 3 * (surf.degree_u + 1)
        mv = samples_per_span or 3 * (surf.degree_v + 1)
        self.us, self.vs = self._sample_grid(bu, bv, mu, mv, min(int(min_samples), MAX_SAMPLES))
        D = bspline.evaluate_grid(surf, self.us, self.vs, order=2)
        # S, Su, Sv, Suu, Suv, Svv: one row per sample (seeds are gathered row by row)
        # and SoA (3, M) arrays
        self._rows = np.concatenate([d.reshape(-1, 3) for d in D], axis=1)
        self.samples = [d.reshape(-1, 3).T.copy() for d in D]
        grid = D[0]
        # covering radius: half the longest cell diagonal (plus margin)
        d1 = np.linalg.norm(grid[1:, 1:] - grid[:-1, :-1], axis=2)
        d2 = np.linalg.norm(grid[1:, :-1] - grid[:-1, 1:], axis=2)
        self.eps = 0.6 * float(max(d1.max(initial=0.0), d2.max(initial=0.0)))
        # seed lookups are shared by all points of one voxel of this size
        edges = np.r_[np.linalg.norm(np.diff(grid, axis=0), axis=2).ravel(),
                      np.linalg.norm(np.diff(grid, axis=1), axis=2).ravel()]
        edges = edges[edges > 0]
        self.voxel = float(np.median(edges)) if edges.size else 1.0
        # closed directions (a full sphere's or cylinder's seam): the first and last
        # sample lines coincide; a foot stopped at one end is pursued from the other
        tol = 1e-9 * max(1.0, float(np.abs(grid).max()))
        self._closed = (bool(np.all(np.abs(grid[0] - grid[-1]) <= tol)),
                        bool(np.all(np.abs(grid[:, 0] - grid[:, -1]) <= tol)))
        # degenerate samples (collapsed edges, poles) are no seeds: Newton cannot
        # leave them (zero gradient) and all their parameters give one point
        scale_u, scale_v = bspline._derivative_scales(surf)
        self._scale_u, self._scale_v = scale_u, scale_v
        Su, Sv = self.samples[1].T, self.samples[2].T
        regular = ~bspline._degenerate(np.cross(Su, Sv), Su, Sv, scale_u, scale_v, rel=1e-6)
        if not regular.any():
            raise GeometryError("the face is degenerate everywhere (Su x Sv = 0)")
        # points closer than this to the face have a unique closest point
        # (half the smallest radius of curvature seen at the samples)
        self._curvatures = principal_curvatures(self.samples)
        k1, k2 = self._curvatures
        kmax = np.maximum(np.abs(k1), np.abs(k2))[regular]
        kmax = kmax[np.isfinite(kmax)]
        self.safe_distance = 0.5 / kmax.max() if kmax.size and kmax.max() > 0 else np.inf
        self.tree_ids = np.flatnonzero(regular)  # tree index -> sample index
        self.tree = cKDTree(grid.reshape(-1, 3)[self.tree_ids])
        self.newton = Newton(self.ev, surf.u_range, surf.v_range)
        self._regular = regular
        self._regions = None
        self._regions_lock = threading.Lock()

    def regions(self):
        """The face's region certificate
        (:class:`~surfcomp.core.surface.projection_regions.Regions`), built on first use."""
        with self._regions_lock:
            if self._regions is None:
                self._regions = Regions(self.us, self.vs, self.samples, self._curvatures,
                                        self._regular, self.eps, 2.0 * CERTIFY_DISTANCE)
            return self._regions

    def _sample_grid(self, bu, bv, mu, mv, min_samples=0):
        """Sample parameters equally spaced in arc length (roughly square cells in mm).

        The spacing is the finer of ``length / (spans * m)`` along u and v (the
        per-span density), but no finer than what keeps the grid within
        ``MAX_SAMPLES``.
        """
        surf = self.surf
        (u0, u1), (v0, v1) = surf.u_range, surf.v_range
        fu = _sample_params(bu, 4, u0, u1)
        fv = _sample_params(bv, 4, v0, v1)
        lines = 7
        Gu = bspline.evaluate_grid(surf, fu, np.linspace(v0, v1, lines))
        Gv = bspline.evaluate_grid(surf, np.linspace(u0, u1, lines), fv)
        # cumulative chord length along u / v, the longest of a few grid lines
        Lu = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(Gu, axis=0), axis=2).max(axis=1))]
        Lv = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(Gv, axis=1), axis=2).max(axis=0))]
        lu, lv = Lu[-1], Lv[-1]
        if lu <= 0 or lv <= 0:
            raise GeometryError("the face has zero extent along u or v")
        h = min(lu / max(1, (bu.size - 1) * mu), lv / max(1, (bv.size - 1) * mv))
        if min_samples > 0:
            h = min(h, np.sqrt(lu * lv / min_samples))
        h = max(h, np.sqrt(lu * lv / MAX_SAMPLES))
        nu_s = int(min(np.ceil(lu / h), MAX_SAMPLES // 2)) + 1
        nv_s = int(min(np.ceil(lv / h), MAX_SAMPLES // 2)) + 1
        # equal arc-length steps (the inverse of the monotone length functions)
        us = np.interp(np.linspace(0.0, lu, nu_s), Lu, fu)
        vs = np.interp(np.linspace(0.0, lv, nv_s), Lv, fv)
        us[[0, -1]], vs[[0, -1]] = (u0, u1), (v0, v1)
        return np.unique(us), np.unique(vs)

    # ------------------------------------------------------------------ public
    def project(self, points, max_distance=None, progress=None, derivatives=False):
        """Project points; see :func:`project` (``derivatives``: fill
        :attr:`Projection.derivatives`)."""
        P = np.asarray(points, dtype=float)
        if P.ndim != 2 or P.shape[1] != 3:
            raise InputError("points must have shape (N, 3), got %r" % (P.shape,))
        N = P.shape[0]
        res = dict(u=np.full(N, np.nan), v=np.full(N, np.nan), foot=np.full((N, 3), np.nan),
                   normal=np.full((N, 3), np.nan), distance=np.full(N, np.nan),
                   outside=np.zeros(N, dtype=bool), converged=np.zeros(N, dtype=bool))
        if derivatives:
            res["derivatives"] = np.full((6, 3, N), np.nan)
        good = np.flatnonzero(np.all(np.isfinite(P), axis=1))
        # blocks are independent (disjoint result rows): one thread each; two per thread
        # at most (each ends with a tail of iterations on its few slow points)
        block = max(CHUNK * 2, -(-good.size // (2 * self.workers)))
        for_chunks(lambda sl: self._project_block(P[good[sl]], good[sl], res, max_distance),
                   good.size, block, workers=self.workers,
                   done=lambda k, count: report(progress, (k + 1) / count,
                                                "projecting points"))
        if not good.size:
            report(progress, 1.0, "projecting points")
        return Projection(**res)

    # ------------------------------------------------------------------ internals
    def _seeds(self, P, max_distance):
        """Nearest sample of each point's voxel centre (one KD query per voxel)."""
        h = self.voxel
        q = np.floor(P / h)
        lo = q.min(axis=0)
        q = (q - lo).astype(np.int64)
        ext = q.max(axis=0) + 1
        if float(ext[0]) * float(ext[1]) * float(ext[2]) < 2.0 ** 62:
            key = (q[:, 0] * ext[1] + q[:, 1]) * ext[2] + q[:, 2]
            uniq, first, inv = np.unique(key, return_index=True, return_inverse=True)
            centres = (q[first] + lo + 0.5) * h
        else:  # absurd extent: no sharing
            centres, inv = P, np.arange(P.shape[0])
        ub = np.inf
        if max_distance is not None:
            ub = float(max_distance) + self.eps + h
        dist, nb = self.tree.query(centres, k=1, distance_upper_bound=ub, workers=1)
        near = np.isfinite(dist)
        return self.tree_ids[np.where(near, nb, 0)][inv], near[inv]

    def _project_block(self, P, idx, res, max_distance):
        seeds, near = self._seeds(P, max_distance)
        P, idx, seeds = P[near], idx[near], seeds[near]
        if P.shape[0] == 0:
            return
        Pt = np.ascontiguousarray(P.T)
        n = P.shape[0]
        u, v = np.empty(n), np.empty(n)
        D = [np.empty((3, n)) for _ in range(6)]
        conv = np.zeros(n, dtype=bool)
        for a in range(0, n, CHUNK):
            c = slice(a, a + CHUNK)
            iu, iv = np.divmod(seeds[c], self.vs.size)
            uc, vc, Dc, conv[c] = self.newton.quick(Pt[:, c], self.us[iu], self.vs[iv],
                                                    self._sample_derivs(seeds[c]))
            u[c], v[c] = uc, vc
            for dst, src in zip(D, Dc):
                dst[:, c] = src
        # the few points that need the safeguards start again from their seeds, all
        # chunks together
        slow = np.flatnonzero(~conv)
        if slow.size:
            u2, v2, D2, c2 = self._newton_from_samples(P[slow], seeds[slow])
            u[slow], v[slow], conv[slow] = u2, v2, c2
            for a, b in zip(D, D2):
                a[:, slow] = b
        # a local minimum closer than the reach of the face is the global one, and so
        # is one that the region certificate covers; the others get checked with more
        # seeds
        r = D[0] - P.T
        check = np.flatnonzero(~(dot(r, r) < self.safe_distance ** 2))
        if check.size:
            check = check[~self._certified(u[check], v[check], r[:, check],
                                           [d[:, check] for d in D[1:3]], conv[check])]
        if check.size:
            sus, owner, seeds = self._suspicious(P[check], u[check], v[check],
                                                 [d[:, check] for d in D],
                                                 *self._nearest(P[check]))
            self._best_of(P, check[owner], seeds, u, v, D, conv)
            if sus.size:
                self._reseed(P, check[sus], u, v, D, conv)
        self._across_seams(P, u, v, D, conv)
        self._finish(P, idx, u, v, D, conv, res, max_distance)

    def _across_seams(self, P, u, v, D, conv):
        """Feet stopped at the end of a closed direction (the seam of a full sphere): Newton
        again from the other end of that direction, keeping the closer foot."""
        for axis, (lo, hi) in enumerate((self.surf.u_range, self.surf.v_range)):
            t = (u, v)[axis]
            k = np.flatnonzero((t <= lo) | (t >= hi)) if self._closed[axis] else ()
            if not len(k):
                continue
            start = [u[k].copy(), v[k].copy()]
            start[axis] = np.where(t[k] <= lo, hi, lo)
            u2, v2, D2, c2 = self.newton.run(np.ascontiguousarray(P[k].T), *start)
            ro, rn = D[0][:, k] - P[k].T, D2[0] - P[k].T
            better = dot(rn, rn) < dot(ro, ro) * (1 - 1e-12)
            i = k[better]
            u[i], v[i], conv[i] = u2[better], v2[better], c2[better]
            for a, b in zip(D, D2):
                a[:, i] = b[:, better]

    def _certified(self, u, v, r, tangents, conv):
        """Interior converged feet that the region certificate proves global."""
        (u0, u1), (v0, v1) = self.surf.u_range, self.surf.v_range
        inside = conv & (u > u0) & (u < u1) & (v > v0) & (v < v1)
        if not inside.any() or self.safe_distance >= CERTIFY_DISTANCE:
            return np.zeros(u.size, dtype=bool)
        n = np.cross(tangents[0].T, tangents[1].T).T
        d = np.copysign(np.sqrt(dot(r, r)), -dot(r, n))   # r = S - P, d along Su x Sv
        out = np.zeros(u.size, dtype=bool)
        out[inside] = self.regions().certified(u[inside], v[inside], d[inside])
        return out

    def _sample_derivs(self, seeds):
        """S, Su, Sv, Suu, Suv, Svv at samples: six (3, n) arrays."""
        g = np.take(self._rows, seeds, axis=0).T.copy()
        return [g[3 * k:3 * k + 3] for k in range(6)]

    def _newton_from_samples(self, P, seeds, maxiter=None):
        Pt = np.ascontiguousarray(P.T)
        sd = self._sample_derivs(seeds)
        iu, iv = np.divmod(seeds, self.vs.size)
        return self.newton.run(Pt, self.us[iu], self.vs[iv], sd, maxiter=maxiter)

    def _grid_index(self, u, v):
        """Indices of the nearest sample parameters."""
        out = []
        for t, ts in ((u, self.us), (v, self.vs)):
            i = np.clip(np.searchsorted(ts, t), 1, ts.size - 1)
            out.append(np.where(np.abs(t - ts[i - 1]) <= np.abs(ts[i] - t), i - 1, i))
        return out[0], out[1]

    def _nearest(self, P, k=12):
        """The ``k`` nearest samples of each point: distances and sample numbers (n, k)."""
        dist, nb = self.tree.query(P, k=min(k, self.tree.n), workers=1)
        return dist.reshape(P.shape[0], -1), self.tree_ids[nb.reshape(P.shape[0], -1)]

    def _suspicious(self, P, u, v, D, dist, nb):
        """Points whose local minimum may not be the global one (indices) and the seeds
        (owner, sample) of their neighbouring basins, from the nearest samples
        ``dist``, ``nb`` (n, k) of each point (``inf`` distance: no sample)."""
        S, Su, Sv, Suu, Suv, Svv = D
        r = S - P.T
        a, b, c = dot(Su, Su), dot(Su, Sv), dot(Sv, Sv)
        Huu, Huv, Hvv = a + dot(r, Suu), b + dot(r, Suv), c + dot(r, Svv)
        # near a curvature centre the distance Hessian degenerates
        flat = (Huu * Hvv - Huv * Huv) < 0.5 * (a * c - b * b)
        # a sample close enough to hold a better minimum (|X - P| < d + eps) that is
        # far from the foot along the face (length of the parameter offset in the
        # foot's first fundamental form > 3 |X - F| + 2 eps) although close in
        # space: another part of the face comes close (a second basin)
        ki, kj = np.divmod(nb, self.vs.size)
        i0, j0 = self._grid_index(u, v)
        i0, j0 = i0[:, None], j0[:, None]
        du_, dv_ = self.us[ki] - u[:, None], self.vs[kj] - v[:, None]
        path = np.sqrt(np.maximum(a[:, None] * du_ * du_ + 2.0 * b[:, None] * du_ * dv_
                                  + c[:, None] * dv_ * dv_, 0.0))
        X = self.samples[0][:, nb]  # (3, n, k)
        xf = np.sqrt(np.sum((X - S[:, :, None]) ** 2, axis=0))
        d = np.sqrt(dot(r, r))[:, None]
        reach = dist < d + self.eps
        far = path > 3.0 * xf + 2.0 * self.eps
        sus = np.flatnonzero(flat | np.any(reach & far, axis=1))
        # any sample within reach may sit in a neighbouring basin (near-ties, e.g.
        # two minima a cell apart, or an interior minimum next to a boundary one)
        owner, col = np.nonzero(reach)
        seeds = nb[owner, col]
        # one Newton step on the sample's stored derivatives predicts where that
        # seed leads; only seeds predicted to reach another foot (more than half a
        # grid cell away) at a distance not clearly worse get the full treatment
        lu, lv, dp = self._predict(owner, seeds, P)
        ii, jj = i0[owner, 0], j0[owner, 0]
        cell_u = self.us[np.minimum(ii + 1, self.us.size - 1)] - self.us[np.maximum(ii - 1, 0)]
        cell_v = self.vs[np.minimum(jj + 1, self.vs.size - 1)] - self.vs[np.maximum(jj - 1, 0)]
        elsewhere = ((np.abs(lu - u[owner]) > 0.25 * cell_u)
                     | (np.abs(lv - v[owner]) > 0.25 * cell_v))
        promising = elsewhere & (dp < d[owner, 0] + 0.5 * self.eps)
        owner, seeds = owner[promising], seeds[promising]
        # at most three per point, the most promising first
        order = np.lexsort((dp[promising], owner))
        owner, seeds = owner[order], seeds[order]
        rank = np.arange(owner.size) - np.searchsorted(owner, owner)
        keep = rank < 3
        return sus, owner[keep], seeds[keep]

    def _best_of(self, P, owner, seeds, u, v, D, conv):
        """Newton from extra seeds; a point keeps the best of its results."""
        if owner.size == 0:
            return
        u2, v2, D2, conv2 = self._newton_from_samples(P[owner], seeds)
        ro = D[0][:, owner] - P[owner].T
        rn = D2[0] - P[owner].T
        f_old, f_new = dot(ro, ro), dot(rn, rn)
        order = np.argsort(f_new, kind="stable")  # best candidate per point first
        first = order[np.unique(owner[order], return_index=True)[1]]
        better = first[f_new[first] < f_old[first] * (1 - 1e-12) - 1e-24]
        i = owner[better]
        u[i], v[i], conv[i] = u2[better], v2[better], conv2[better]
        for a, b in zip(D, D2):
            a[:, i] = b[:, better]

    def _predict(self, owner, seeds, P):
        """One Newton step on the stored sample derivatives: landing (u, v) and distance."""
        Pk = P[owner].T
        sd = self._sample_derivs(seeds)
        ki, kj = np.divmod(seeds, self.vs.size)
        su, sv = self.us[ki], self.vs[kj]
        du, dv, _ = self.newton.step(su, sv, sd[0] - Pk, *sd[1:])
        Sp = sd[0] + sd[1] * du + sd[2] * dv + 0.5 * (sd[3] * du * du + 2.0 * sd[4] * du * dv
                                                       + sd[5] * dv * dv)
        rp = Sp - Pk
        return su + du, sv + dv, np.sqrt(dot(rp, rp))

    def _reseed(self, P, sus, u, v, D, conv, per_point=400, chunk=256):
        """Newton from all parts of the face within reach of a better minimum; keep the best.

        Candidates are the samples within ``d + eps`` of the point (a KD-tree ball
        query per point), thinned and pursued by :meth:`_pursue`.
        """
        seeds = []
        for start in range(0, sus.size, chunk):
            pts = sus[start:start + chunk]
            r = D[0][:, pts] - P[pts].T
            d = np.sqrt(dot(r, r))
            balls = self.tree.query_ball_point(P[pts], d + self.eps, workers=1)
            lens = np.fromiter((len(b) for b in balls), dtype=np.intp, count=len(balls))
            if lens.sum() == 0:
                continue
            cand = self.tree_ids[np.fromiter(itertools.chain.from_iterable(balls), dtype=np.intp,
                                             count=int(lens.sum()))]
            local = np.repeat(np.arange(pts.size), lens)
            seeds.append(self._pursue(P, pts, local, cand, lens, d, u, v, per_point))
        if seeds:
            self._best_of(P, np.concatenate([o for o, _ in seeds]),
                          np.concatenate([c for _, c in seeds]), u, v, D, conv)

    def _pursue(self, P, pts, local, cand, lens, d, u, v, per_point, max_seeds=12):
        """Seeds for Newton among the candidate samples ``cand`` of points ``pts[local]``.

        Crowded candidate sets are thinned on the grid to about ``per_point``; one
        Newton step on each sample's stored derivatives predicts its landing point;
        landings away from the current foot (other grid cells) that promise a
        distance below ``d + eps / 2`` are deduplicated by cell and the
        ``max_seeds`` best are returned as (owner, sample) for :meth:`_best_of`.
        """
        # thin crowded balls on the grid: keep every s-th row and column
        stride = np.maximum(1, np.ceil(np.sqrt(lens / per_point))).astype(np.intp)[local]
        ki, kj = np.divmod(cand, self.vs.size)
        keep = (ki % stride == 0) & (kj % stride == 0)
        local, cand = local[keep], cand[keep]
        owner = pts[local]
        lu, lv, dp = self._predict(owner, cand, P)
        li, lj = self._grid_index(lu, lv)
        fi, fj = self._grid_index(u[owner], v[owner])
        ok = ((li != fi) | (lj != fj)) & (dp < d[local] + 0.5 * self.eps)
        owner, cand, dp, li, lj = owner[ok], cand[ok], dp[ok], li[ok], lj[ok]
        if owner.size == 0:
            return owner, cand
        # best candidate per (point, landing cell), then the max_seeds best per point
        order = np.lexsort((dp, lj, li, owner))
        owner, cand, dp, li, lj = owner[order], cand[order], dp[order], li[order], lj[order]
        first = np.r_[True, (np.diff(owner) != 0) | (np.diff(li) != 0) | (np.diff(lj) != 0)]
        owner, cand, dp = owner[first], cand[first], dp[first]
        order = np.lexsort((dp, owner))
        owner, cand = owner[order], cand[order]
        rank = np.arange(owner.size) - np.searchsorted(owner, owner)
        sel = rank < max_seeds
        return owner[sel], cand[sel]

    def _finish(self, P, idx, u, v, D, conv, res, max_distance):
        S, Su, Sv = D[0], D[1], D[2]                       # SoA (3, n)
        n = np.array([Su[1] * Sv[2] - Su[2] * Sv[1], Su[2] * Sv[0] - Su[0] * Sv[2],
                      Su[0] * Sv[1] - Su[1] * Sv[0]])
        nn = np.sqrt(dot(n, n))
        # degenerate normals (collapsed edges, poles) as bspline.normals has them
        bad = ((nn <= 1e-10 * self._scale_u * self._scale_v)
               | (nn <= 1e-10 * np.sqrt(dot(Su, Su) * dot(Sv, Sv))))
        with np.errstate(divide="ignore", invalid="ignore"):
            n = n / nn
        if bad.any():
            n[:, bad] = bspline.unit_normals(self.surf, u[bad], v[bad], Su[:, bad].T,
                                              Sv[:, bad].T).T
        r = P.T - S
        d = dot(r, n)
        # outside: at a bound with a tangential residual (> 1e-8 mm) pointing out of
        # the work area, i.e. the unconstrained foot lies beyond that bound
        (u0, u1), (v0, v1) = self.surf.u_range, self.surf.v_range
        out = np.zeros(u.size, dtype=bool)
        at = np.flatnonzero((u <= u0) | (u >= u1) | (v <= v0) | (v >= v1))
        if at.size:
            ra, ua, va = r[:, at], u[at], v[at]
            rt = ra - d[at] * n[:, at]
            tu, tv = dot(rt, Su[:, at]), dot(rt, Sv[:, at])
            out[at] = (dot(rt, rt) > 1e-16) & (((ua <= u0) & (tu < 0)) | ((ua >= u1) & (tu > 0))
                                               | ((va <= v0) & (tv < 0)) | ((va >= v1) & (tv > 0)))
            d[out] = np.copysign(np.sqrt(dot(r[:, out], r[:, out])), d[out])
        if max_distance is not None:
            keep = np.abs(d) <= float(max_distance)
            if not keep.all():       # (all kept: no copies)
                idx, u, v, S, n, d, out, conv = (
                    a[..., keep] for a in (idx, u, v, S, n, d, out, conv))
                D = [d_[:, keep] for d_ in D]
        res["u"][idx], res["v"][idx] = u, v
        res["foot"][idx], res["normal"][idx] = S.T, n.T
        res["distance"][idx] = d
        res["outside"][idx] = out
        res["converged"][idx] = conv
        if "derivatives" in res:
            for k, d_ in enumerate(D):
                res["derivatives"][k][:, idx] = d_


def tangent_lengths(surf, u, v, chunk=CHUNK):
    """``|Su|`` and ``|Sv|`` (mm per unit parameter) at face parameters ``u``, ``v`` (N,),
    with the projector's span-table evaluator (several times faster than
    :func:`bspline.derivatives` at many points).

    Returns
    -------
    (ndarray, ndarray), shape (N,) each
    """
    u = np.asarray(u, dtype=float).ravel()
    v = np.asarray(v, dtype=float).ravel()
    ev = SpanTable(surf) if SpanTable.size(surf) <= MAX_TABLE_VALUES else GenericEval(surf)
    lu, lv = np.empty(u.size), np.empty(u.size)
    for a in range(0, u.size, chunk):
        _, Su, Sv = ev.evaluate(u[a:a + chunk], v[a:a + chunk], 1)
        lu[a:a + chunk], lv[a:a + chunk] = np.sqrt(dot(Su, Su)), np.sqrt(dot(Sv, Sv))
    return lu, lv


def project(surf, points, max_distance=None, progress=None, workers=None):
    """Closest points of a B-spline face to measured points (issue 5).

    Parameters
    ----------
    surf : bspline.Surface
        The nominal face; feet stay inside ``surf.u_range x surf.v_range``.
    points : array_like, shape (N, 3)
        Points in mm. Rows with NaN give NaN results (``converged`` False).
    max_distance : float, optional
        Points farther than this (mm) from the face are not projected: NaN
        results, ``converged`` False. Speeds up clouds with far outliers.
    progress : callable, optional
        ``progress(fraction, message)``; may raise ``Cancelled``.
    workers : int, optional
        Threads; default the number of CPUs.

    Returns
    -------
    Projection
        Foot parameters, foot points, unit normals, signed distances,
        ``outside`` (foot on the face boundary) and ``converged`` flags.

    Notes
    -----
    For repeated projections onto the same face build a :class:`Projector`
    once and call its ``project`` method.
    """
    n = len(points)
    return Projector(surf, workers=workers, min_samples=n // 16).project(points, max_distance,
                                                                         progress)
