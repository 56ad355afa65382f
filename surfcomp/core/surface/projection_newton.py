# SPDX-License-Identifier: LGPL-2.1-or-later
"""Evaluation and Newton iterations of point projection (no FreeCAD).

The machinery under :class:`surfcomp.core.surface.projection.Projector`: a per-span
power-basis table of the surface (Taylor coefficients of each polynomial piece,
from the basis functions' derivatives at the span starts) evaluated by Horner's
scheme on structure-of-arrays data (tested against :func:`bspline.derivatives`),
and safeguarded, bound-constrained Newton iterations on ``(S - P) . Su = 0``,
``(S - P) . Sv = 0`` for many points at once.
"""

import math

import numpy as np

from . import bspline

#: Newton stops when a full (second-order) step moves the foot point less than
#: this (mm): the error left after applying it is O(step^2 / R) ~ 1e-13 mm
STEP_TOL = 1e-6
#: the same for other steps and near curvature centres (linear convergence)
STEP_TOL_SLOW = 1e-10
#: points evaluated at once by :meth:`SpanTable.evaluate`: the Horner temporaries then
#: stay in the processor's cache (a bicubic face's gathered coefficients are 0.8 MB for
#: 2048 points; 2048 took 0.54-0.60 us a point against 0.83-0.97 us for 8192 and 0.63-0.76
#: for 4096, 65536 points, 4 alternations; 8192 was about 3 times faster per point than
#: 65536 at once, bench/bench_align.py)
EVAL_BLOCK = 2048


# --------------------------------------------------------------------------- power-basis table

class SpanTable:
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
        Bu = [bspline.basis_matrix(surf.knots_u, pu, nu, self.bu[:-1], a)
              for a in range(pu + 1)]
        for b in range(pv + 1):
            Bv = bspline.basis_matrix(surf.knots_v, pv, nv, self.bv[:-1], b)
            Tv = (Bv @ flat).reshape(Kv, nu, dim).transpose(1, 0, 2).reshape(nu, Kv * dim)
            fv = (self.hv ** b / math.factorial(b))[None, :, None]
            for a in range(pu + 1):
                fu = (self.hu ** a / math.factorial(a))[:, None, None]
                C[:, :, b, a, :] = (Bu[a] @ Tv).reshape(Ku, Kv, dim) * fu * fv
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
        # np.minimum / np.maximum: np.clip's argument checks cost more than the work at
        # a few points
        iu = np.minimum(np.maximum(np.searchsorted(self.bu, u, side="right") - 1, 0),
                        self.hu.size - 1)
        iv = np.minimum(np.maximum(np.searchsorted(self.bv, v, side="right") - 1, 0),
                        self.hv.size - 1)
        hu, hv = self.hu[iu], self.hv[iv]
        return iu * self.Kv + iv, (u - self.bu[iu]) / hu, (v - self.bv[iv]) / hv, hu, hv

    def evaluate(self, u, v, order):
        """SoA derivatives: list of (3, n) arrays in bspline._ORDER_KEYS[order] order."""
        n = u.size
        if n <= EVAL_BLOCK:
            return self._evaluate(u, v, order)
        out = None
        for a in range(0, n, EVAL_BLOCK):
            part = self._evaluate(u[a:a + EVAL_BLOCK], v[a:a + EVAL_BLOCK], order)
            if out is None:
                out = [np.empty((p.shape[0], n)) for p in part]
            for o, p in zip(out, part):
                o[:, a:a + EVAL_BLOCK] = p
        return out

    def _evaluate(self, u, v, order):
        key, s, t, hu, hv = self.locate(u, v)
        n = u.size
        pu, pv, dim = self.pu, self.pv, self.dim
        G = self._table[:, key].reshape(pv + 1, (pu + 1) * dim, n)
        # along v: the value and derivatives of every u coefficient, in one buffer laid
        # out (kv, a, c, n); then along u on all kv at once: derivative k of the u
        # polynomial of the kv-th v derivative, for k + kv <= order
        Wt = np.empty((order + 1, (pu + 1) * dim, n))
        _horner_into(G, t, list(Wt))
        Gs = Wt.reshape(order + 1, pu + 1, dim, n).transpose(1, 0, 2, 3)
        Ws = [np.empty((order + 1 - k, dim, n)) for k in range(order + 1)]
        _horner_into(Gs, s, Ws)
        # the accumulators hold d^k/ds^k / k! (k <= 2): the 2 of the second derivatives
        # joins the span scale (a power of two: the same rounding)
        inv_hu, inv_hv = 1.0 / hu, 1.0 / hv
        fu = (None, inv_hu, 2.0 * inv_hu ** 2)
        fv = (None, inv_hv, 2.0 * inv_hv ** 2)
        keys = bspline._ORDER_KEYS[order]
        A = {}
        for (k, kv) in keys:
            val = Ws[k][kv]
            if k:
                val = val * fu[k]
            if kv:
                val = val * fv[kv]
            A[(k, kv)] = val
        if not self.rational:
            return [A[key_] for key_ in keys]
        return _quotient_soa(A, order)


def _horner_into(G, x, outs):
    """Horner's scheme for ``sum_b G[b] x^b`` (leading axis b) and its derivatives.

    ``G`` has shape (deg + 1, m, ...), ``x`` shape (n,) (the last axis); ``outs[k]``
    (k <= 2), of shape (m_k, ...) with m_k <= m, receives ``d^k/dx^k / k!`` of the
    polynomials ``G[:, :m_k]`` (so the second derivative is ``2 * outs[2]``). The
    arithmetic is that of the textbook loop from zero derivative accumulators; the
    first steps, whose accumulators are still zero, are taken on ``0 * x`` alone.
    """
    deg = G.shape[0] - 1
    order = len(outs) - 1
    p = outs[0]
    m = [o.shape[0] for o in outs]
    if deg == 0:
        p[...] = G[0, :m[0]]
        for o in outs[1:]:
            o[...] = 0.0
        return
    z = x * 0.0                                  # 0 * x: the zero accumulator times x
    if order >= 2:
        d2 = z + 0.0                             # (0 * x + 0)
    if order >= 1:
        d1 = outs[1]
        np.add(G[deg, :m[1]], z, out=d1)         # 0 * x + G[deg]
    np.multiply(G[deg, :m[0]], x, out=p)
    p += G[deg - 1, :m[0]]
    if order >= 2:
        if deg >= 2:
            np.add(d2 * x, d1[:m[2]], out=outs[2])
        else:
            outs[2][...] = d2
        d2 = outs[2]
    for b in range(deg - 2, -1, -1):
        if order >= 2 and b < deg - 2:
            d2 *= x
            d2 += d1[:m[2]]
        if order >= 1:
            d1 *= x
            d1 += p[:m[1]]
        p *= x
        p += G[b, :m[0]]


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


class GenericEval:
    """Fallback evaluator for surfaces too large for a span table."""

    def __init__(self, surf):
        self.surf = surf

    def evaluate(self, u, v, order):
        return [d.T.copy() for d in bspline.derivatives(self.surf, u, v, order)]


# --------------------------------------------------------------------------- Newton machinery

def dot(a, b):
    """Row-wise dot product of SoA arrays (3, n) -> (n,)."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


class Newton:
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
        gu, gv = dot(r, Su), dot(r, Sv)
        a, b, c = dot(Su, Su), dot(Su, Sv), dot(Sv, Sv)
        Huu, Huv, Hvv = a + dot(r, Suu), b + dot(r, Suv), c + dot(r, Svv)
        det = Huu * Hvv - Huv * Huv
        gn_det = a * c - b * b
        pd = (Huu > 0) & (Hvv > 0) & (det > 1e-10 * gn_det)
        fix_u = ((u <= self.u0) & (gu > 0)) | ((u >= self.u1) & (gu < 0))
        fix_v = ((v <= self.v0) & (gv > 0)) | ((v >= self.v1) & (gv < 0))
        # where the Hessian is not positive definite: the Hessian shifted by
        # sigma I (sigma = 1.5 |lambda_min|, so its smallest eigenvalue becomes
        # |lambda_min| / 2, plus a little Gauss-Newton scale); with one variable
        # held at a bound only its own curvature matters (else Gauss-Newton)
        fixed = bool((fix_u | fix_v).any())
        if fixed:
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
            du = (H_uv * gv - H_vv * gu) / det2
            dv = (H_uv * gu - H_uu * gv) / det2
            if fixed:   # (none at a bound: the same values without these selections)
                du = np.where(fix_v, -gu / h_u, du)
                dv = np.where(fix_u, -gv / h_v, dv)
        if fixed:
            du = np.where(fix_u | ~np.isfinite(du), 0.0, du)
            dv = np.where(fix_v | ~np.isfinite(dv), 0.0, dv)
        else:
            du = np.where(np.isfinite(du), du, 0.0)
            dv = np.where(np.isfinite(dv), dv, 0.0)
        # trust region: at most half the work area per step
        lim = np.maximum(np.abs(du) * (2.0 / (self.u1 - self.u0)),
                         np.abs(dv) * (2.0 / (self.v1 - self.v0)))
        scale = 1.0 / np.maximum(lim, 1.0)
        un = np.minimum(np.maximum(u + du * scale, self.u0), self.u1)
        vn = np.minimum(np.maximum(v + dv * scale, self.v0), self.v1)
        # fast = a true Newton step away from a curvature centre (quadratic convergence)
        fast = pd & (det > 0.5 * gn_det)
        if fixed:
            fast = np.where(fix_u | fix_v,
                            np.where(fix_u, fix_v | (Hvv > 0.5 * c), Huu > 0.5 * a), fast)
        return un - u, vn - v, fast

    def quick(self, P, u, v, seed_derivs, evaluations=2, extra=1):
        """Plain Newton steps from samples: the common case without the safeguards.

        From ``seed_derivs`` (S, Su, Sv, Suu, Suv, Svv at (u, v)), ``evaluations``
        steps each followed by an evaluation, then one more step taken by Taylor
        expansion; ``done`` marks the points where every step decreased the distance
        and the last one was a full Newton step shorter than ``STEP_TOL``: there the
        result is what :meth:`run` reaches (one iteration further at most). Points
        still on their way get ``extra`` more evaluations (one at a time, on them
        alone); the others must go through :meth:`run`, their entries are
        meaningless.

        Returns
        -------
        u, v : ndarray, shape (n,)
        D : list of 6 (3, n) arrays
        done : ndarray of bool
        """
        D = seed_derivs
        r = D[0] - P
        f = dot(r, r)
        ok = np.ones(u.size, dtype=bool)
        for _ in range(evaluations):
            du, dv, _ = self.step(u, v, r, *D[1:])
            u, v = u + du, v + dv
            D = self.ev.evaluate(u, v, 2)
            r = D[0] - P
            fn = dot(r, r)
            ok &= ~(fn > f * (1.0 + 1e-12) + 1e-24)
            f = fn
        du, dv, fast = self.step(u, v, r, *D[1:])
        S, Su, Sv, Suu, Suv, Svv = D
        mv = Su * du + Sv * dv
        done = ok & fast & (dot(mv, mv) <= STEP_TOL * STEP_TOL)
        on = np.flatnonzero(ok & ~done) if extra else ()
        out = [S + mv + 0.5 * (Suu * du * du + 2.0 * Suv * du * dv + Svv * dv * dv),
               Su + Suu * du + Suv * dv, Sv + Suv * du + Svv * dv, Suu, Suv, Svv]
        un, vn = u + du, v + dv
        if len(on):
            u2, v2, D2, done2 = self.quick(P[:, on], u[on], v[on], [d_[:, on] for d_ in D], 1,
                                           extra - 1)
            un[on], vn[on], done[on] = u2, v2, done2
            for o_, d_ in zip(out, D2):
                o_[:, on] = d_
        return un, vn, out, done

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
            f = dot(r, r)
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
            mvn = np.sqrt(dot(mv, mv))
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
