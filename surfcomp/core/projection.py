"""Orthogonal projection of points onto a B-spline face (no FreeCAD).

Method: a dense sample grid of the face (:func:`bspline.evaluate_grid` with
second derivatives) in a ``scipy.spatial.cKDTree`` gives seeds; safeguarded
Newton iterations on ``(S - P) . Su = 0``, ``(S - P) . Sv = 0`` (second-order
Hessian, shifted to positive definite where it is not, step halving, bound
constraints on the work area) refine them. Points farther from the face than
half its smallest radius of curvature are checked: samples within reach whose
one-step prediction lands elsewhere, and (near curvature centres or where
another part of the face comes close) all parts of the face within reach, seed
further Newton runs; the best result wins. Everything is vectorised over points,
chunked and run in threads.

Evaluation inside the Newton loop uses a per-span power-basis table of the
surface (Taylor coefficients of each polynomial piece, from the basis
functions' derivatives at the span starts) evaluated by Horner's scheme on
structure-of-arrays data; it is tested against :func:`bspline.derivatives`.
"""

import itertools
import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..errors import GeometryError, InputError
from . import bspline
from .progress import report

#: Newton stops when a full (second-order) step moves the foot point less than
#: this (mm): the error left after applying it is O(step^2 / R) ~ 1e-13 mm
STEP_TOL = 1e-6
#: the same for other steps and near curvature centres (linear convergence)
STEP_TOL_SLOW = 1e-10
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
        Newton converged: the last full Newton step moved the foot less than
        ``STEP_TOL`` (1e-6 mm, leaving an error ~1e-13 mm), another step less
        than 1e-10 mm, or no further decrease was possible at the rounding
        level. False also for NaN input points and points farther than
        ``max_distance``; their other fields are NaN (``outside`` False).
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
        W = _horner(G, t, order)  # W[kv]: d^kv/dt^kv, (A*C, n)
        keys = bspline._ORDER_KEYS[order]
        A = {}
        inv_hu, inv_hv = 1.0 / hu, 1.0 / hv
        for kv in range(order + 1):
            Ws = W[kv].reshape(pu + 1, dim, n)
            D = _horner(Ws, s, order - kv)
            for k in range(order - kv + 1):
                if (k, kv) in keys:
                    val = D[k]
                    if k:
                        val = val * inv_hu ** k
                    if kv:
                        val = val * inv_hv ** kv
                    A[(k, kv)] = val
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
    Newton steps where the Hessian of f is positive definite, shifted-Hessian
    (or Gauss-Newton) steps elsewhere, variables at a bound with the gradient
    pointing outwards
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
        fix_u = ((u <= self.u0) & (gu > 0)) | ((u >= self.u1) & (gu < 0))
        fix_v = ((v <= self.v0) & (gv > 0)) | ((v >= self.v1) & (gv < 0))
        # where the Hessian is not positive definite: the Hessian shifted by
        # sigma I (sigma = 1.5 |lambda_min|, so its smallest eigenvalue becomes
        # |lambda_min| / 2, plus a little Gauss-Newton scale); with one variable
        # held at a bound only its own curvature matters (else Gauss-Newton)
        mu = 1e-9 * (a + c)
        h_u = np.where(Huu > 1e-10 * a, Huu, a + mu)
        h_v = np.where(Hvv > 1e-10 * c, Hvv, c + mu)
        if pd.all():
            H_uu, H_uv, H_vv, det2 = Huu, Huv, Hvv, det
        else:
            lam_min = 0.5 * (Huu + Hvv) - np.sqrt(0.25 * (Huu - Hvv) ** 2 + Huv * Huv)
            sigma = np.where(pd, 0.0, 1.5 * np.abs(np.minimum(lam_min, 0.0)) + 1e-3 * (a + c))
            H_uu, H_uv, H_vv = Huu + sigma, Huv, Hvv + sigma
            det2 = H_uu * H_vv - H_uv * H_uv
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            du = np.where(fix_v, -gu / h_u, (H_uv * gv - H_vv * gu) / det2)
            dv = np.where(fix_u, -gv / h_v, (H_uv * gu - H_uu * gv) / det2)
        du = np.where(fix_u | ~np.isfinite(du), 0.0, du)
        dv = np.where(fix_v | ~np.isfinite(dv), 0.0, dv)
        # trust region: at most half the work area per step
        lim = np.maximum(np.abs(du) * (2.0 / (self.u1 - self.u0)),
                         np.abs(dv) * (2.0 / (self.v1 - self.v0)))
        scale = 1.0 / np.maximum(lim, 1.0)
        un = np.minimum(np.maximum(u + du * scale, self.u0), self.u1)
        vn = np.minimum(np.maximum(v + dv * scale, self.v0), self.v1)
        # fast = a true Newton step away from a curvature centre (quadratic convergence)
        fast = np.where(fix_u | fix_v,
                        np.where(fix_u, fix_v | (Hvv > 0.5 * c), Huu > 0.5 * a),
                        pd & (det > 0.5 * gn_det))
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
            done = acc & (mvn <= np.where(fast, STEP_TOL, STEP_TOL_SLOW))
            mvl = np.where(acc, mvn, mvl)
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
        Seed sample density: the grid spacing (mm, equal along u and v) is the
        face length over ``spans * samples_per_span`` in the direction that gives
        the finer spacing; default ``3 * (degree + 1)``; coarsened so that the
        grid has at most ``MAX_SAMPLES`` points.
    workers : int, optional
        Threads for the Newton chunks and the KD-tree queries; default: the
        number of CPUs.
    """

    def __init__(self, surf, samples_per_span=None, workers=None):
        self.surf = surf
        self.workers = max(1, int(workers or os.cpu_count() or 1))
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
        self.us, self.vs = self._sample_grid(bu, bv, mu, mv)
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
        # degenerate samples (collapsed edges, poles) are no seeds: Newton cannot
        # leave them (zero gradient) and all their parameters give one point
        scale_u, scale_v = bspline._derivative_scales(surf)
        Su, Sv = self.samples[1].T, self.samples[2].T
        regular = ~bspline._degenerate(np.cross(Su, Sv), Su, Sv, scale_u, scale_v, rel=1e-6)
        if not regular.any():
            raise GeometryError("the face is degenerate everywhere (Su x Sv = 0)")
        # points closer than this to the face have a unique closest point
        # (half the smallest radius of curvature seen at the samples)
        kmax = _max_curvature(self.samples)[regular]
        kmax = kmax[np.isfinite(kmax)]
        self.safe_distance = 0.5 / kmax.max() if kmax.size and kmax.max() > 0 else np.inf
        self.tree_ids = np.flatnonzero(regular)  # tree index -> sample index
        self.tree = cKDTree(grid.reshape(-1, 3)[self.tree_ids])
        self.newton = _Newton(self.ev, surf.u_range, surf.v_range)

    def _sample_grid(self, bu, bv, mu, mv):
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
        h = max(h, np.sqrt(lu * lv / MAX_SAMPLES))
        nu_s = int(min(np.ceil(lu / h), MAX_SAMPLES // 2)) + 1
        nv_s = int(min(np.ceil(lv / h), MAX_SAMPLES // 2)) + 1
        # equal arc-length steps (the inverse of the monotone length functions)
        us = np.interp(np.linspace(0.0, lu, nu_s), Lu, fu)
        vs = np.interp(np.linspace(0.0, lv, nv_s), Lv, fv)
        us[[0, -1]], vs[[0, -1]] = (u0, u1), (v0, v1)
        return np.unique(us), np.unique(vs)

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
        # blocks are independent (disjoint result rows): one thread each
        block = CHUNK * 8
        blocks = [good[s_:s_ + block] for s_ in range(0, good.size, block)]
        job = lambda idx: self._project_block(P[idx], idx, res, max_distance)  # noqa: E731
        if self.workers == 1 or len(blocks) == 1:
            for k, idx in enumerate(blocks):
                job(idx)
                report(progress, (k + 1) / len(blocks), "projecting points")
        else:
            with ThreadPoolExecutor(self.workers) as pool:
                futures = [pool.submit(job, idx) for idx in blocks]
                try:
                    for k, fut in enumerate(futures):
                        fut.result()
                        report(progress, (k + 1) / len(blocks), "projecting points")
                except BaseException:
                    for fut in futures:
                        fut.cancel()
                    raise
        if not blocks:
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
            sus, owner, seeds = self._suspicious(P[check], u[check], v[check],
                                                 [d[:, check] for d in D])
            self._best_of(P, check[owner], seeds, u, v, D, conv)
            if sus.size:
                self._reseed(P, check[sus], u, v, D, conv)
        self._finish(P, idx, u, v, D, conv, res, max_distance)

    def _newton_from_samples(self, P, seeds, maxiter=None):
        Pt = np.ascontiguousarray(P.T)
        sd = [s_[:, seeds] for s_ in self.samples]
        iu, iv = np.divmod(seeds, self.vs.size)
        return self.newton.run(Pt, self.us[iu], self.vs[iv], sd, maxiter=maxiter)

    def _grid_index(self, u, v):
        """Indices of the nearest sample parameters."""
        out = []
        for t, ts in ((u, self.us), (v, self.vs)):
            i = np.clip(np.searchsorted(ts, t), 1, ts.size - 1)
            out.append(np.where(np.abs(t - ts[i - 1]) <= np.abs(ts[i] - t), i - 1, i))
        return out[0], out[1]

    def _suspicious(self, P, u, v, D, k=12):
        """Indices of points whose local minimum may not be the global one."""
        S, Su, Sv, Suu, Suv, Svv = D
        r = S - P.T
        a, b, c = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)
        Huu, Huv, Hvv = a + _dot(r, Suu), b + _dot(r, Suv), c + _dot(r, Svv)
        # near a curvature centre the distance Hessian degenerates
        flat = (Huu * Hvv - Huv * Huv) < 0.5 * (a * c - b * b)
        # a sample close enough to hold a better minimum (|X - P| < d + eps) that is
        # far from the foot along the face (length of the parameter offset in the
        # foot's first fundamental form > 3 |X - F| + 2 eps) although close in
        # space: another part of the face comes close (a second basin)
        dist, nb = self.tree.query(P, k=min(k, self.tree.n), workers=1)
        nb = self.tree_ids[nb.reshape(P.shape[0], -1)]
        dist = dist.reshape(P.shape[0], -1)
        ki, kj = np.divmod(nb, self.vs.size)
        i0, j0 = self._grid_index(u, v)
        i0, j0 = i0[:, None], j0[:, None]
        du_, dv_ = self.us[ki] - u[:, None], self.vs[kj] - v[:, None]
        path = np.sqrt(np.maximum(a[:, None] * du_ * du_ + 2.0 * b[:, None] * du_ * dv_
                                  + c[:, None] * dv_ * dv_, 0.0))
        X = self.samples[0][:, nb]  # (3, n, k)
        xf = np.sqrt(np.sum((X - S[:, :, None]) ** 2, axis=0))
        d = np.sqrt(_dot(r, r))[:, None]
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
        f_old, f_new = _dot(ro, ro), _dot(rn, rn)
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
        sd = [s_[:, seeds] for s_ in self.samples]
        ki, kj = np.divmod(seeds, self.vs.size)
        su, sv = self.us[ki], self.vs[kj]
        du, dv, _ = self.newton.step(su, sv, sd[0] - Pk, *sd[1:])
        Sp = sd[0] + sd[1] * du + sd[2] * dv + 0.5 * (sd[3] * du * du + 2.0 * sd[4] * du * dv
                                                       + sd[5] * dv * dv)
        rp = Sp - Pk
        return su + du, sv + dv, np.sqrt(_dot(rp, rp))

    def _reseed(self, P, sus, u, v, D, conv, max_seeds=12, per_point=400, chunk=256):
        """Newton from all parts of the face within reach of a better minimum; keep the best.

        Candidates are the samples within ``d + eps`` of the point (thinned on the
        grid to about ``per_point``); one Newton step on each sample's stored
        derivatives predicts its landing point; landings away from the current
        foot (other grid cells) that promise a distance below ``d + eps / 2`` are
        deduplicated by cell and the ``max_seeds`` best run the full Newton.
        """
        for start in range(0, sus.size, chunk):
            pts = sus[start:start + chunk]
            r = D[0][:, pts] - P[pts].T
            d = np.sqrt(_dot(r, r))
            balls = self.tree.query_ball_point(P[pts], d + self.eps, workers=1)
            lens = np.fromiter((len(b) for b in balls), dtype=np.intp, count=len(balls))
            if lens.sum() == 0:
                continue
            cand = self.tree_ids[np.fromiter(itertools.chain.from_iterable(balls), dtype=np.intp,
                                             count=int(lens.sum()))]
            local = np.repeat(np.arange(pts.size), lens)
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
            # best candidate per (point, landing cell), then the max_seeds best per point
            order = np.lexsort((dp, lj, li, owner))
            owner, cand, dp, li, lj = owner[order], cand[order], dp[order], li[order], lj[order]
            first = np.r_[True, (np.diff(owner) != 0) | (np.diff(li) != 0) | (np.diff(lj) != 0)]
            owner, cand, dp = owner[first], cand[first], dp[first]
            order = np.lexsort((dp, owner))
            owner, cand = owner[order], cand[order]
            rank = np.arange(owner.size) - np.searchsorted(owner, owner)
            sel = rank < max_seeds
            self._best_of(P, owner[sel], cand[sel], u, v, D, conv)

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
    return Projector(surf, workers=workers).project(points, max_distance, progress)
