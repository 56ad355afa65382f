"""Orthogonal projection of points onto a B-spline face (no FreeCAD).

Method: a dense sample grid of the face (:func:`bspline.evaluate_grid` with
second derivatives) in a ``scipy.spatial.cKDTree`` gives seeds; safeguarded
Newton iterations on ``(S - P) . Su = 0``, ``(S - P) . Sv = 0`` (second-order
Hessian, Gauss-Newton fallback, step halving, bound constraints on the work
area) refine them. Points near the curvature centre of concave regions, or
whose nearest samples lie in different parts of the face, get several seeds
and keep the best. Everything is vectorised over points and chunked.

Evaluation inside the Newton loop uses a per-span power-basis table of the
surface (Taylor coefficients of each polynomial piece, from the basis
functions' derivatives at the span starts) evaluated by Horner's scheme on
structure-of-arrays data; it is tested against :func:`bspline.derivatives`.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from . import bspline
from .progress import report
from ..errors import GeometryError, InputError

#: Newton stops when a full (second-order) step moves the foot point less than
#: this (mm): the error left after applying it is O(step^2 / R) ~ 1e-13 mm
STEP_TOL = 1e-6
#: the same for Gauss-Newton steps and near curvature centres (linear convergence)
STEP_TOL_SLOW = 1e-10
#: after two consecutive full Newton steps d1, d2 the error left after d2 is
#: about C d2^2 with C = d2 / d1^2; a step is also final when that is below this (mm)
PREDICTED_TOL = 1e-10
#: Newton iterations per point in the first, chunked pass (the rest is batched)
FIRST_PASS_ITER = 8
#: points per vectorised Newton chunk (keeps temporaries in cache)
CHUNK = 8192
#: upper bound on the number of seed samples
MAX_SAMPLES = 250_000
#: the power-basis table is used when it has at most this many values
MAX_TABLE_VALUES = 20_000_000


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
        Newton converged (step below 1e-10 mm). False also for NaN input points
        and points farther than ``max_distance``; their other fields are NaN
        (``outside`` False).
    """

    u: np.ndarray
    v: np.ndarray
    foot: np.ndarray
    normal: np.ndarray
    distance: np.ndarray
    outside: np.ndarray
    converged: np.ndarray

    def __len__(self):
        return self.u.shape[0]


# --------------------------------------------------------------------------- power-basis table

class _SpanTable:
    """Taylor coefficients of every polynomial piece of the (homogeneous) surface.

    For the span pair (i, j) with local coordinates ``s = (u - a_i) / h_i``,
    ``t = (v - b_j) / k_j`` in [0, 1]: ``A(s, t) = sum_ab C[i, j, a, b] s^a t^b``
    with ``C = h^a k^b / (a! b!) d^a/du^a d^b/dv^b A(a_i, b_j)``.
    """

    def __init__(self, surf):
        self.surf = surf
        pu, pv = surf.degree_u, surf.degree_v
        nu, nv = surf.shape
        self.pu, self.pv = pu, pv
        self.rational = surf.weights is not None
        Pw = bspline._homogeneous(surf) if self.rational else surf.poles
        self.dim = dim = Pw.shape[2]
        self.bu = self._breaks(surf.knots_u, pu, nu)
        self.bv = self._breaks(surf.knots_v, pv, nv)
        self.hu, self.hv = np.diff(self.bu), np.diff(self.bv)
        Ku, Kv = self.hu.size, self.hv.size
        flat = np.ascontiguousarray(Pw.transpose(1, 0, 2)).reshape(nv, nu * dim)
        # coefficient table laid out (Ku, Kv, b, a, c)
        C = np.empty((Ku, Kv, pv + 1, pu + 1, dim))
        for b in range(pv + 1):
            Bv = bspline.basis_matrix(surf.knots_v, pv, nv, self.bv[:-1], b)
            Tv = (Bv @ flat).reshape(Kv, nu, dim).transpose(1, 0, 2).reshape(nu, Kv * dim)
            fv = (self.hv ** b / math.factorial(b))[None, :, None]
            for a in range(pu + 1):
                Bu = bspline.basis_matrix(surf.knots_u, pu, nu, self.bu[:-1], a)
                fu = (self.hu ** a / math.factorial(a))[:, None, None]
                C[:, :, b, a, :] = (Bu @ Tv).reshape(Ku, Kv, dim) * fu * fv
        self.Kv = Kv
        self.row = (pv + 1) * (pu + 1) * dim
        # transposed: one column per span pair, gathered with table[:, keys]
        self._table = np.ascontiguousarray(C.reshape(Ku * Kv, self.row).T)

    @staticmethod
    def _breaks(knots, p, n):
        lo, hi = knots[p], knots[n]
        k = np.unique(knots[(knots >= lo) & (knots <= hi)])
        return k

    @staticmethod
    def size(surf):
        Ku = np.unique(surf.knots_u).size
        Kv = np.unique(surf.knots_v).size
        dim = 4 if surf.weights is not None else 3
        return Ku * Kv * (surf.degree_u + 1) * (surf.degree_v + 1) * dim

    def locate(self, u, v):
        iu = np.clip(np.searchsorted(self.bu, u, side="right") - 1, 0, self.hu.size - 1)
        iv = np.clip(np.searchsorted(self.bv, v, side="right") - 1, 0, self.hv.size - 1)
        hu, hv = self.hu[iu], self.hv[iv]
        return iu * self.Kv + iv, (u - self.bu[iu]) / hu, (v - self.bv[iv]) / hv, hu, hv

    def evaluate(self, u, v, order):
        """SoA derivatives: list of (3, n) arrays in bspline._ORDER_KEYS[order] order."""
        key, s, t, hu, hv = self.locate(u, v)
        n = u.size
        pu, pv, dim = self.pu, self.pv, self.dim
        G = self._table[:, key].reshape(pv + 1, (pu + 1) * dim, n)
        W = _horner(G, t, order)  # W[l]: d^l/dt^l, (A*C, n)
        keys = bspline._ORDER_KEYS[order]
        A = {}
        inv_hu, inv_hv = 1.0 / hu, 1.0 / hv
        for l in range(order + 1):
            Ws = W[l].reshape(pu + 1, dim, n)
            D = _horner(Ws, s, order - l)
            for k in range(order - l + 1):
                if (k, l) in keys:
                    val = D[k]
                    if k:
                        val = val * inv_hu ** k
                    if l:
                        val = val * inv_hv ** l
                    A[(k, l)] = val
        if not self.rational:
            return [A[key_] for key_ in keys]
        return _quotient_soa(A, order)


def _horner(G, x, order):
    """Value and derivatives up to ``order`` (<= 2) of ``sum_b G[b] x^b`` (leading axis b).

    ``G`` has shape (deg + 1, m, n), ``x`` shape (n,); returns a list of (m, n)
    arrays: the value, first and second derivative w.r.t. x.
    """
    deg = G.shape[0] - 1
    p = G[deg].copy()
    d1 = np.zeros_like(p) if order >= 1 else None
    d2 = np.zeros_like(p) if order >= 2 else None
    for b in range(deg - 1, -1, -1):
        if d2 is not None:
            d2 *= x
            d2 += d1
        if d1 is not None:
            d1 *= x
            d1 += p
        p *= x
        p += G[b]
    out = [p]
    if order >= 1:
        out.append(d1)
    if order >= 2:
        out.append(2.0 * d2)
    return out


def _quotient_soa(A, order):
    """Rational quotient rule (NURBS book eq. 4.20) on (4, n) homogeneous arrays."""
    w = A[(0, 0)][3]
    S = A[(0, 0)][:3] / w
    out = [S]
    if order >= 1:
        wu, wv = A[(1, 0)][3], A[(0, 1)][3]
        Su = (A[(1, 0)][:3] - wu * S) / w
        Sv = (A[(0, 1)][:3] - wv * S) / w
        out += [Su, Sv]
    if order >= 2:
        out.append((A[(2, 0)][:3] - 2.0 * wu * Su - A[(2, 0)][3] * S) / w)
        out.append((A[(1, 1)][:3] - wu * Sv - wv * Su - A[(1, 1)][3] * S) / w)
        out.append((A[(0, 2)][:3] - 2.0 * wv * Sv - A[(0, 2)][3] * S) / w)
    return out


class _GenericEval:
    """Fallback evaluator for surfaces too large for a span table."""

    def __init__(self, surf):
        self.surf = surf

    def evaluate(self, u, v, order):
        return [d.T.copy() for d in bspline.derivatives(self.surf, u, v, order)]


# --------------------------------------------------------------------------- Newton machinery

def _dot(a, b):
    """Row-wise dot product of SoA arrays (3, n) -> (n,)."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


class _Newton:
    """Safeguarded, bound-constrained Newton iterations for many points at once.

    Minimises ``f(u, v) = |S(u, v) - P|^2 / 2`` over the work area: full
    Newton steps where the Hessian of f is positive definite, Gauss-Newton
    steps elsewhere, variables at a bound with the gradient pointing outwards
    held fixed (projected Newton), steps limited to half the work area, and
    halved back towards the last accepted point when f grew.
    """

    def __init__(self, evaluator, u_range, v_range, maxiter=60, max_halvings=40):
        self.ev = evaluator
        self.u0, self.u1 = u_range
        self.v0, self.v1 = v_range
        self.maxiter = maxiter
        self.max_halvings = max_halvings

    def step(self, u, v, r, Su, Sv, Suu, Suv, Svv):
        """Projected Newton step (du, dv) and whether it was a fast (Newton) one."""
        gu, gv = _dot(r, Su), _dot(r, Sv)
        a, b, c = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)
        Huu, Huv, Hvv = a + _dot(r, Suu), b + _dot(r, Suv), c + _dot(r, Svv)
        det = Huu * Hvv - Huv * Huv
        gn_det = a * c - b * b
        pd = (Huu > 0) & (Hvv > 0) & (det > 1e-10 * gn_det)
        # (slightly damped) Gauss-Newton where the full Hessian is not positive definite
        mu = 1e-9 * (a + c)
        Huu = np.where(pd, Huu, a + mu)
        Huv = np.where(pd, Huv, b)
        Hvv = np.where(pd, Hvv, c + mu)
        det = np.where(pd, det, (a + mu) * (c + mu) - b * b)
        fix_u = ((u <= self.u0) & (gu > 0)) | ((u >= self.u1) & (gu < 0))
        fix_v = ((v <= self.v0) & (gv > 0)) | ((v >= self.v1) & (gv < 0))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            du = np.where(fix_v, -gu / Huu, (Huv * gv - Hvv * gu) / det)
            dv = np.where(fix_u, -gv / Hvv, (Huv * gu - Huu * gv) / det)
        du = np.where(fix_u | ~np.isfinite(du), 0.0, du)
        dv = np.where(fix_v | ~np.isfinite(dv), 0.0, dv)
        # trust region: at most half the work area per step
        lim = np.maximum(np.abs(du) * (2.0 / (self.u1 - self.u0)),
                         np.abs(dv) * (2.0 / (self.v1 - self.v0)))
        scale = 1.0 / np.maximum(lim, 1.0)
        un = np.minimum(np.maximum(u + du * scale, self.u0), self.u1)
        vn = np.minimum(np.maximum(v + dv * scale, self.v0), self.v1)
        fast = pd & (det > 0.5 * gn_det)
        return un - u, vn - v, fast

    def run(self, P, u, v, seed_derivs=None, maxiter=None):
        """Iterate all points from (u, v).

        Parameters
        ----------
        P : ndarray, shape (3, n)
        u, v : ndarray, shape (n,)
        seed_derivs : list of 6 (3, n) arrays, optional
            S, Su, Sv, Suu, Suv, Svv at (u, v) when already known (samples).
        maxiter : int, optional

        Returns
        -------
        u, v : ndarray, shape (n,)
        D : list of 6 (3, n) arrays
            Derivatives at the result (S, Su, Sv by Taylor expansion over the
            last small step).
        converged : ndarray of bool
        """
        n = u.size
        U, V = np.empty(n), np.empty(n)
        OUT = [np.empty((3, n)) for _ in range(6)]
        CONV = np.zeros(n, dtype=bool)
        idx = np.arange(n)
        Pa, ua, va = P, u.copy(), v.copy()
        uprev, vprev = ua.copy(), va.copy()
        fprev = np.full(n, np.inf)
        dul, dvl = np.zeros(n), np.zeros(n)
        halv = np.zeros(n)
        mvl = np.full(n, np.inf)
        fastl = np.zeros(n, dtype=bool)
        best = None
        for it in range((maxiter or self.maxiter) + 1):
            if idx.size == 0:
                break
            if it == 0 and seed_derivs is not None:
                D = seed_derivs
            else:
                D = self.ev.evaluate(ua, va, 2)
            r = D[0] - Pa
            f = _dot(r, r)
            worse = f > fprev * (1.0 + 1e-12) + 1e-24
            acc = ~worse
            anyworse = bool(worse.any())
            if anyworse:  # rejected points keep their last accepted values
                D = [np.where(worse, b_, d_) for b_, d_ in zip(best, D)]
                r = D[0] - Pa
                f = np.where(worse, fprev, f)
                uprev = np.where(acc, ua, uprev)
                vprev = np.where(acc, va, vprev)
            else:
                uprev, vprev = ua, va
            best, fprev = D, f
            du, dv, fast = self.step(uprev, vprev, r, *D[1:])
            mv = D[1] * du + D[2] * dv
            mvn = np.sqrt(_dot(mv, mv))
            # quadratic convergence: predicted remaining error mvn^3 / mvl^2
            quad = fast & fastl & (mvn <= 1e-3) & (mvn ** 3 <= PREDICTED_TOL * mvl ** 2)
            done = acc & ((mvn <= np.where(fast, STEP_TOL, STEP_TOL_SLOW)) | quad)
            mvl = np.where(acc, mvn, mvl)
            fastl = np.where(acc, fast, fastl)
            if anyworse:
                # no decrease possible: the last accepted point is the answer; a
                # minimum when the failed step was already at rounding level
                gave = worse & ((halv >= self.max_halvings) | (mvl <= STEP_TOL_SLOW))
                dul = np.where(acc, du, 0.5 * dul)
                dvl = np.where(acc, dv, 0.5 * dvl)
                halv = np.where(acc, 0.0, halv + 1.0)
            else:
                gave = None
                dul, dvl = du, dv
                halv = np.zeros_like(halv) if it == 0 else halv * 0.0
            ua = uprev + dul
            va = vprev + dvl
            finished = done if gave is None else (done | gave)
            if finished.any():
                fin = np.flatnonzero(finished)
                gi = idx[fin]
                dn = done[fin]
                dud, dvd = np.where(dn, du[fin], 0.0), np.where(dn, dv[fin], 0.0)
                S, Su, Sv, Suu, Suv, Svv = [d_[:, fin] for d_ in D]
                # Taylor expansion over the last small step (no re-evaluation)
                OUT[0][:, gi] = S + Su * dud + Sv * dvd + 0.5 * (Suu * dud * dud
                                                                 + 2.0 * Suv * dud * dvd
                                                                 + Svv * dvd * dvd)
                OUT[1][:, gi] = Su + Suu * dud + Suv * dvd
                OUT[2][:, gi] = Sv + Suv * dud + Svv * dvd
                OUT[3][:, gi], OUT[4][:, gi], OUT[5][:, gi] = Suu, Suv, Svv
                U[gi] = uprev[fin] + dud
                V[gi] = vprev[fin] + dvd
                CONV[gi] = dn | (mvl[fin] <= 1e-8)
                keep = ~finished
                idx, Pa, ua, va = idx[keep], Pa[:, keep], ua[keep], va[keep]
                uprev, vprev, fprev = uprev[keep], vprev[keep], fprev[keep]
                dul, dvl, halv, mvl = dul[keep], dvl[keep], halv[keep], mvl[keep]
                fastl = fastl[keep]
                best = [b_[:, keep] for b_ in best]
        if idx.size:  # iteration limit: keep the last accepted point, not converged
            U[idx], V[idx] = uprev, vprev
            for o_, b_ in zip(OUT, best):
                o_[:, idx] = b_
        return U, V, OUT, CONV


# --------------------------------------------------------------------------- projector

def _sample_params(breaks, per_span, lo, hi):
    """Parameters: ``per_span`` intervals in every span, clipped to [lo, hi]."""
    f = np.linspace(0.0, 1.0, per_span + 1)[:-1]
    t = (breaks[:-1, None] + np.diff(breaks)[:, None] * f[None, :]).ravel()
    t = t[(t > lo) & (t < hi)]
    return np.unique(np.r_[lo, t, hi])


def _max_curvature(D):
    """Largest principal curvature magnitude (1/mm) at SoA derivative samples; NaN if degenerate."""
    S, Su, Sv, Suu, Suv, Svv = D
    n = np.cross(Su.T, Sv.T).T
    nn = np.sqrt(_dot(n, n))
    with np.errstate(divide="ignore", invalid="ignore"):
        n = n / nn
        E, F, G = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)
        L, M, N = _dot(n, Suu), _dot(n, Suv), _dot(n, Svv)
        den = E * G - F * F
        K = (L * N - M * M) / den
        H = (E * N - 2.0 * F * M + G * L) / (2.0 * den)
        return np.abs(H) + np.sqrt(np.maximum(H * H - K, 0.0))


class Projector:
    """Reusable projection engine for one face (samples, KD-tree, span table).

    Parameters
    ----------
    surf : bspline.Surface
        The face; projection stays inside ``surf.u_range x surf.v_range``.
    samples_per_span : int, optional
        Seed samples per knot span and direction; default ``3 * (degree + 1)``,
        reduced so that the grid has at most ``MAX_SAMPLES`` points.
    workers : int, optional
        Threads for the KD-tree queries (``cKDTree.query(workers=...)``);
        default 1.
    """

    def __init__(self, surf, samples_per_span=None, workers=None):
        self.surf = surf
        self.workers = int(workers or 1)
        if _SpanTable.size(surf) <= MAX_TABLE_VALUES:
            self.ev = _SpanTable(surf)
            bu, bv = self.ev.bu, self.ev.bv
        else:
            self.ev = _GenericEval(surf)
            bu = _SpanTable._breaks(surf.knots_u, surf.degree_u, surf.shape[0])
            bv = _SpanTable._breaks(surf.knots_v, surf.degree_v, surf.shape[1])
        (u0, u1), (v0, v1) = surf.u_range, surf.v_range
        bu = np.unique(np.r_[u0, bu[(bu > u0) & (bu < u1)], u1])
        bv = np.unique(np.r_[v0, bv[(bv > v0) & (bv < v1)], v1])
        mu = samples_per_span or 3 * (surf.degree_u + 1)
        mv = samples_per_span or 3 * (surf.degree_v + 1)
        while (bu.size * mu) * (bv.size * mv) > MAX_SAMPLES and max(mu, mv) > 1:
            mu, mv = max(1, mu - 1), max(1, mv - 1)
        self.us = _sample_params(bu, mu, u0, u1)
        self.vs = _sample_params(bv, mv, v0, v1)
        D = bspline.evaluate_grid(surf, self.us, self.vs, order=2)
        self.samples = [d.reshape(-1, 3).T.copy() for d in D]  # SoA (3, M)
        grid = D[0]
        # covering radius: half the longest cell diagonal (plus margin)
        d1 = np.linalg.norm(grid[1:, 1:] - grid[:-1, :-1], axis=2)
        d2 = np.linalg.norm(grid[1:, :-1] - grid[:-1, 1:], axis=2)
        self.eps = 0.6 * float(max(d1.max(initial=0.0), d2.max(initial=0.0)))
        # seed lookups are shared by all points of one voxel of this size
        edges = np.r_[np.linalg.norm(np.diff(grid, axis=0), axis=2).ravel(),
                      np.linalg.norm(np.diff(grid, axis=1), axis=2).ravel()]
        edges = edges[edges > 0]
        self.voxel = 0.5 * float(np.median(edges)) if edges.size else 1.0
        # points closer than this to the face have a unique closest point
        # (half the smallest radius of curvature seen at the samples)
        # degenerate samples (collapsed edges, poles) are no seeds: Newton cannot
        # leave them (zero gradient) and all their parameters give one point
        scale_u, scale_v = bspline._derivative_scales(surf)
        Su, Sv = self.samples[1].T, self.samples[2].T
        regular = ~bspline._degenerate(np.cross(Su, Sv), Su, Sv, scale_u, scale_v, rel=1e-6)
        if not regular.any():
            raise GeometryError("the face is degenerate everywhere (Su x Sv = 0)")
        kmax = _max_curvature(self.samples)[regular]
        kmax = kmax[np.isfinite(kmax)]
        self.safe_distance = 0.5 / kmax.max() if kmax.size and kmax.max() > 0 else np.inf
        self.tree_ids = np.flatnonzero(regular)  # tree index -> sample index
        # cumulative chord lengths along the grid lines: path lengths on the face
        zero_u = np.zeros((1, grid.shape[1]))
        zero_v = np.zeros((grid.shape[0], 1))
        self.arc_u = np.r_[zero_u, np.cumsum(np.linalg.norm(np.diff(grid, axis=0), axis=2), 0)]
        self.arc_v = np.c_[zero_v, np.cumsum(np.linalg.norm(np.diff(grid, axis=1), axis=2), 1)]
        self.tree = cKDTree(grid.reshape(-1, 3)[self.tree_ids])
        self.newton = _Newton(self.ev, surf.u_range, surf.v_range)

    # ------------------------------------------------------------------ public
    def project(self, points, max_distance=None, progress=None):
        """Project points; see :func:`project`."""
        P = np.asarray(points, dtype=float)
        if P.ndim != 2 or P.shape[1] != 3:
            raise InputError("points must have shape (N, 3), got %r" % (P.shape,))
        N = P.shape[0]
        res = dict(u=np.full(N, np.nan), v=np.full(N, np.nan), foot=np.full((N, 3), np.nan),
                   normal=np.full((N, 3), np.nan), distance=np.full(N, np.nan),
                   outside=np.zeros(N, dtype=bool), converged=np.zeros(N, dtype=bool))
        good = np.flatnonzero(np.all(np.isfinite(P), axis=1))
        block = CHUNK * 32
        for start in range(0, good.size, block):
            idx = good[start:start + block]
            self._project_block(P[idx], idx, res, max_distance)
            report(progress, min(1.0, (start + block) / max(good.size, 1)), "projecting points")
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
        dist, nb = self.tree.query(centres, k=1, distance_upper_bound=ub, workers=self.workers)
        near = np.isfinite(dist)
        return self.tree_ids[np.where(near, nb, 0)][inv], near[inv]

    def _project_block(self, P, idx, res, max_distance):
        seeds, near = self._seeds(P, max_distance)
        P, idx, seeds = P[near], idx[near], seeds[near]
        if P.shape[0] == 0:
            return
        parts = [self._newton_from_samples(P[c], seeds[c], FIRST_PASS_ITER)
                 for c in (slice(s_, s_ + CHUNK) for s_ in range(0, P.shape[0], CHUNK))]
        u = np.concatenate([r[0] for r in parts])
        v = np.concatenate([r[1] for r in parts])
        D = [np.concatenate([r[2][i] for r in parts], axis=1) for i in range(6)]
        conv = np.concatenate([r[3] for r in parts])
        # the few slow points of all chunks continue together (no per-chunk tail)
        slow = np.flatnonzero(~conv)
        if slow.size:
            u2, v2, D2, c2 = self.newton.run(np.ascontiguousarray(P[slow].T), u[slow], v[slow])
            u[slow], v[slow], conv[slow] = u2, v2, c2
            for a, b in zip(D, D2):
                a[:, slow] = b
        # a local minimum closer than the reach of the face is the global one;
        # the others get checked with more seeds
        r = D[0] - P.T
        check = np.flatnonzero(~(_dot(r, r) < self.safe_distance ** 2))
        if check.size:
            sus = check[self._suspicious(P[check], u[check], v[check],
                                         [d[:, check] for d in D])]
            if sus.size:
                self._reseed(P, sus, u, v, D, conv)
        self._finish(P, idx, u, v, D, conv, res, max_distance)

    def _newton_from_samples(self, P, seeds, maxiter=None):
        Pt = np.ascontiguousarray(P.T)
        sd = [s_[:, seeds] for s_ in self.samples]
        iu, iv = np.divmod(seeds, self.vs.size)
        return self.newton.run(Pt, self.us[iu], self.vs[iv], sd, maxiter=maxiter)

    def _grid_index(self, u, v):
        iu = np.clip(np.searchsorted(self.us, u), 0, self.us.size - 1)
        iv = np.clip(np.searchsorted(self.vs, v), 0, self.vs.size - 1)
        return iu, iv

    def _suspicious(self, P, u, v, D, k=12):
        """Indices of points whose local minimum may not be the global one."""
        S, Su, Sv, Suu, Suv, Svv = D
        r = S - P.T
        a, b, c = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)
        Huu, Huv, Hvv = a + _dot(r, Suu), b + _dot(r, Suv), c + _dot(r, Svv)
        # near a curvature centre the distance Hessian degenerates
        flat = (Huu * Hvv - Huv * Huv) < 0.5 * (a * c - b * b)
        # a sample close enough to hold a better minimum (|X - P| < d + eps) that is
        # far from the foot along the face (grid path > 3 |X - F| + 2 eps) although
        # close in space: another part of the face comes close (a second basin)
        dist, nb = self.tree.query(P, k=min(k, self.tree.n), workers=self.workers)
        nb = self.tree_ids[nb.reshape(P.shape[0], -1)]
        dist = dist.reshape(P.shape[0], -1)
        ki, kj = np.divmod(nb, self.vs.size)
        i0, j0 = self._grid_index(u, v)
        i0, j0 = i0[:, None], j0[:, None]
        path = (np.abs(self.arc_u[ki, j0] - self.arc_u[i0, j0])
                + np.abs(self.arc_v[ki, kj] - self.arc_v[ki, j0]))
        X = self.samples[0][:, nb]  # (3, n, k)
        xf = np.sqrt(np.sum((X - S[:, :, None]) ** 2, axis=0))
        d = np.sqrt(_dot(r, r))[:, None]
        reach = dist < d + self.eps
        far = path > 3.0 * xf + 2.0 * self.eps
        return np.flatnonzero(flat | np.any(reach & far, axis=1))

    def _reseed(self, P, sus, u, v, D, conv, max_seeds=12):
        """Newton from far-apart samples within reach of a better minimum; keep the best."""
        r = D[0][:, sus] - P[sus].T
        d = np.sqrt(_dot(r, r))
        balls = self.tree.query_ball_point(P[sus], d + self.eps, workers=self.workers)
        owner, seeds = [], []
        nvs = self.vs.size
        iu_all, iv_all = self._grid_index(u[sus], v[sus])
        for j, (i, cand) in enumerate(zip(sus, balls)):
            if not cand:
                continue
            cand = np.asarray(cand)
            dc = np.sum((self.tree.data[cand] - P[i]) ** 2, axis=1)
            cand = self.tree_ids[cand[np.argsort(dc)][:4000]]
            cu, cv = np.divmod(cand, nvs)
            cu_, cv_ = [int(iu_all[j])], [int(iv_all[j])]
            for c_, a_, b_ in zip(cand.tolist(), cu.tolist(), cv.tolist()):
                if all(abs(a_ - x) > 2 or abs(b_ - y) > 2 for x, y in zip(cu_, cv_)):
                    cu_.append(a_)
                    cv_.append(b_)
                    owner.append(i)
                    seeds.append(c_)
                    if len(cu_) > max_seeds:
                        break
        if not seeds:
            return
        owner, seeds = np.asarray(owner), np.asarray(seeds)
        u2, v2, D2, conv2 = self._newton_from_samples(P[owner], seeds)
        ro = D[0][:, owner] - P[owner].T
        rn = D2[0] - P[owner].T
        f_old, f_new = _dot(ro, ro), _dot(rn, rn)
        order = np.argsort(f_new, kind="stable")  # best candidate per point first
        first = order[np.unique(owner[order], return_index=True)[1]]
        for s_ in first:
            if f_new[s_] < f_old[s_] * (1 - 1e-12) - 1e-24:
                i = owner[s_]
                u[i], v[i], conv[i] = u2[s_], v2[s_], conv2[s_]
                for a, b in zip(D, D2):
                    a[:, i] = b[:, s_]

    def _finish(self, P, idx, u, v, D, conv, res, max_distance):
        S, Su, Sv = D[0].T, D[1].T, D[2].T
        n = bspline._unit_normals(self.surf, u, v, Su, Sv)
        r = P - S
        d = np.einsum("ij,ij->i", r, n)
        # outside: at a bound with a tangential residual (> 1e-8 mm) pointing out of
        # the work area, i.e. the unconstrained foot lies beyond that bound
        rt = r - d[:, None] * n
        big = np.einsum("ij,ij->i", rt, rt) > 1e-16
        tu = np.einsum("ij,ij->i", rt, Su)
        tv = np.einsum("ij,ij->i", rt, Sv)
        (u0, u1), (v0, v1) = self.surf.u_range, self.surf.v_range
        out = big & (((u <= u0) & (tu < 0)) | ((u >= u1) & (tu > 0)) |
                     ((v <= v0) & (tv < 0)) | ((v >= v1) & (tv > 0)))
        d = np.where(out, np.copysign(np.linalg.norm(r, axis=1), d), d)
        keep = np.ones(u.size, dtype=bool)
        if max_distance is not None:
            keep = np.abs(d) <= float(max_distance)
        idx = idx[keep]
        res["u"][idx], res["v"][idx] = u[keep], v[keep]
        res["foot"][idx], res["normal"][idx] = S[keep], n[keep]
        res["distance"][idx] = d[keep]
        res["outside"][idx] = out[keep]
        res["converged"][idx] = conv[keep]


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
        Threads for the KD-tree queries; default 1.

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
    return Projector(surf, workers=workers).project(points, max_distance, progress)
