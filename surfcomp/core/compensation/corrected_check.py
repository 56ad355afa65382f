# SPDX-License-Identifier: LGPL-2.1-or-later
"""What a corrected surface realises, and its check figures (no FreeCAD).

The realised correction at a point is where the line through the nominal point along
its outward normal meets the corrected surface (:func:`realised_correction`, Newton on
(u, v, t)); the check figures compare it with the intended correction at the measured
points and on a denser grid between them, and measure how far the zero-correction surface
strays from the nominal (:func:`check_figures`). Used by the builders in
:mod:`surfcomp.core.compensation.corrected` and by every test that measures a built face.
"""

from dataclasses import dataclass

import numpy as np

from ..surface import bspline

#: see NodeFrame.realised
FINAL_STEP = 1e-7


class NodeFrame:
    """Nominal points and outward normals at fixed (u, v), for repeated
    :func:`realised_correction` calls against changing corrected surfaces."""

    def __init__(self, nominal, u, v, outward):
        self.u = np.ravel(u).astype(float)
        self.v = np.ravel(v).astype(float)
        self.P, Su, Sv = bspline.derivatives(nominal, self.u, self.v, order=1)
        self.n = outward * bspline.unit_normals(nominal, self.u, self.v, Su, Sv)
        self._last = None

    def realised_change(self, before, after, real):
        """The realised correction on ``after`` from the one on ``before`` (``real``, from
        :meth:`realised` on ``before``), to first order in the surfaces' difference D
        (same knots and weights): the intersection moves by -D . N / (n . N) along the
        line, N the normal of ``before`` where the line met it. The residual iteration's
        surfaces differ by fractions of a um and the correction's slopes are ~1e-3, so
        what is left is ~1e-6 of the change (tested against :meth:`realised`). None when
        :meth:`realised` left no intersection to start from."""
        if self._last is None or self._last[2] is None:
            return None
        a, b, W = self._last
        diff = bspline.Surface(after.poles - before.poles, after.knots_u, after.knots_v,
                               after.degree_u, after.degree_v, after.weights,
                               after.u_range, after.v_range)
        D = bspline.evaluate(diff, a, b)
        return np.ravel(real) - np.einsum("ij,ij->i", D, W)

    def realised(self, corrected, guess=None, iterations=20):
        """See :func:`realised_correction`."""
        u, v, P, n = self.u, self.v, self.P, self.n
        t = np.zeros(u.size) if guess is None else np.ravel(guess).astype(float).copy()
        W = np.full((u.size, 3), np.nan)    # N / (n . N) at the last step (realised_change)
        # the residual iteration's surfaces differ by fractions of a um: each starts from
        # where the line met the one before
        a, b = (u.copy(), v.copy()) if self._last is None else (self._last[0].copy(),
                                                                  self._last[1].copy())
        (ua, ub), (va, vb) = corrected.u_range, corrected.v_range
        act = np.arange(u.size)  # only the points whose intersection has not converged
        for _ in range(iterations):
            C, Cu, Cv = bspline.derivatives(corrected, a[act], b[act], order=1)
            F = C + t[act, None] * n[act] - P[act]
            da, db, dt, W[act] = _solve3(Cu, Cv, n[act], -F, weights=True)
            keep = ~np.all(np.abs(F) < 1e-12, axis=1)
            act, F, da, db, dt = act[keep], F[keep], da[keep], db[keep], dt[keep]
            if act.size == 0:
                break
            a[act] = np.clip(a[act] + da, ua, ub)
            b[act] = np.clip(b[act] + db, va, vb)
            t[act] += dt
            # Newton converges quadratically: after a step from |F| < FINAL_STEP (mm) what
            # is left is of the order curvature x |F|^2, below 1e-13 mm; no evaluation
            # needed to confirm it
            act = act[~np.all(np.abs(F) < FINAL_STEP, axis=1)]
            if act.size == 0:
                break
        if np.all(np.isfinite(a)) and np.all(np.isfinite(b)):
            # (no first-order updates where a system was singular: a collapsed edge)
            self._last = (a, b, W if np.all(np.isfinite(W)) else None)
        return t


def _cross(p, q):
    """Cross products of vectors given as three component arrays (tuples or (3, N))."""
    return (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])


def _dot(p, q):
    return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]


def _solve3(a, b, c, r, weights=False):
    """Solve ``[a b c] x = r`` for each row (3 x 3 systems by columns, (N, 3) each) by
    Cramer's rule on the components (a batched LU costs several times more for millions of
    3 x 3 systems); returns the three components of x. Rows whose system is singular or
    nearly so (a collapsed edge: a zero column) get the least-squares step of the smallest
    length (pseudo-inverse) instead: never NaN. With ``weights`` also the (N, 3) rows
    ``a x b / det`` (x[2] = r . them; NaN on the singular rows)."""
    A, B, C, R = a.T, b.T, c.T, r.T
    bc, ab = _cross(B, C), _cross(A, B)
    det = _dot(A, bc)
    size = np.sqrt(_dot(A, A) * _dot(B, B) * _dot(C, C))
    bad = ~(np.abs(det) > 1e-12 * size)
    det = np.where(bad, 1.0, det)
    # x_k = det of the matrix with column k replaced by r: triple products with r
    x = np.stack([_dot(R, bc), _dot(R, _cross(C, A)), _dot(R, ab)]) / det
    if bad.any():
        J = np.stack([a[bad], b[bad], c[bad]], axis=2)
        x[:, bad] = (np.linalg.pinv(J) @ r[bad][..., None])[..., 0].T
    if not weights:
        return x[0], x[1], x[2]
    w = np.stack(ab, axis=1) / det[:, None]
    w[bad] = np.nan
    return x[0], x[1], x[2], w


def realised_correction(nominal, corrected, u, v, outward=1, guess=None, iterations=20):
    """How far the corrected surface lies inside the nominal, along the nominal normal.

    For each (u, v) the line ``S(u, v) - t n(u, v)`` is intersected with the corrected
    surface (Newton on ``S_c(a, b) + t n - S = 0``), so ``t`` is exactly the correction
    realised at that point, measured as the papers measure deviations.

    Parameters
    ----------
    nominal, corrected : Surface
    u, v : array_like, shape (N,)
    outward : {1, -1}
    guess : array_like, shape (N,), optional
        Starting values for t (e.g. the intended correction).

    Returns
    -------
    ndarray, shape (N,)
        Realised correction in mm (positive: surface moved inwards).
    """
    return NodeFrame(nominal, u, v, outward).realised(corrected, guess, iterations)


@dataclass
class CheckFigures:
    """Check figures of a corrected surface (mm).

    ``max_error_at_points``: max |realised - intended| at the measured points.
    ``max_zero_deviation``: max distance from the nominal of the surface built with
    a zero field (the construction's own error), on a grid ``density`` times
    denser than the measurement grid. ``max_realised`` / ``max_intended``: the
    largest |correction| on the face (that dense grid's, refined between the nodes
    around its largest local maxima) vs at the measured points.
    """

    max_error_at_points: float
    max_zero_deviation: float
    max_realised: float
    max_intended: float
    dense_shape: tuple
    poles_shape: tuple
    #: where the corrected surface's normal turns most from the nominal's
    #: (:class:`surfcomp.core.compensation.folds.Fold`), once the surface is chosen
    fold: object = None

    def as_dict(self):
        out = {"max_error_at_points_mm": self.max_error_at_points,
               "max_deviation_from_nominal_with_zero_correction_mm": self.max_zero_deviation,
               "max_abs_realised_correction_on_face_mm": self.max_realised,
               "max_abs_intended_correction_mm": self.max_intended,
               "dense_check_grid": list(self.dense_shape),
               "poles": list(self.poles_shape)}
        if self.fold is not None:
            out["normal_turn"] = self.fold.as_dict()
        return out


#: the dense check grid is ``density`` times denser than the measurement grid, with the
#: density lowered (to at least 2) for dense grids so that it stays near this many points
DENSE_CHECK_POINTS = 4.5e6


def dense_parameters(surf, shape, density=4):
    """Parameters of a check grid ``density`` times denser than an n x m grid, over the
    work area (``density`` lowered towards 2 where the grid would exceed
    ``DENSE_CHECK_POINTS``; the shape used is reported in the check figures)."""
    n, m = max(shape[0] - 1, 1), max(shape[1] - 1, 1)
    density = max(min(density, 2), min(density, int(np.sqrt(DENSE_CHECK_POINTS / (n * m)))))
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    return (np.linspace(u0, u1, density * (shape[0] - 1) + 1),
            np.linspace(v0, v1, density * (shape[1] - 1) + 1))


#: how many of the dense grid's local maxima of |realised| are refined between the nodes
PEAKS_REFINED = 8


def _local_peaks(a, us, vs):
    """(value, u, v) at the nodes of ``a`` (|realised| on the grid us x vs) that no
    neighbour exceeds, the largest :data:`PEAKS_REFINED` of them."""
    b = np.pad(np.where(np.isfinite(a), a, -np.inf), 1, constant_values=-np.inf)
    peak = np.isfinite(a)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di or dj:
                peak &= a >= b[1 + di:b.shape[0] - 1 + di, 1 + dj:b.shape[1] - 1 + dj]
    i, j = np.nonzero(peak)
    top = np.argsort(-a[i, j])[:PEAKS_REFINED]
    return [(float(a[i[k], j[k]]), float(us[i[k]]), float(vs[j[k]])) for k in top]


#: the patches evaluated around each peak: (half-width in grid steps, points a side); each
#: is centred on the best point of the one before, and a Newton step on the quadratic
#: through the last one's 3 x 3 centre ends the search
_PATCHES = ((1.0, 7), (1.0 / 3.0, 7))


def _refined_peak(nominal, corrected, outward, peaks, us, vs):
    """The largest |realised correction| near the grid's largest local maxima, found
    between the nodes: a smooth correction peaks between the nodes of the check grid by up
    to ~h^2 |f''| / 8, several nm on the example and tens of nm for raw data, more than the
    printed figure resolves. Around each peak the exact line intersection is evaluated on
    the :data:`_PATCHES` (one grid step on each side, then a third of one around the best
    point), and a Newton step on the quadratic through the best point's 3 x 3 neighbours
    ends it; all peaks in one evaluation a round. 0 without peaks."""
    if not peaks:
        return 0.0
    peaks = sorted(peaks, reverse=True)[:PEAKS_REFINED]
    (ua, ub), (va, vb) = nominal.u_range, nominal.v_range
    u = np.array([p[1] for p in peaks])
    v = np.array([p[2] for p in peaks])
    best = np.array([p[0] for p in peaks])
    hu = (us[-1] - us[0]) / max(us.size - 1, 1)
    hv = (vs[-1] - vs[0]) / max(vs.size - 1, 1)

    def value(cu, cv):
        got = np.abs(realised_correction(nominal, corrected, cu.ravel(), cv.ravel(), outward))
        return np.where(np.isfinite(got), got, -np.inf).reshape(cu.shape)

    rows = np.arange(u.size)
    for width, n in _PATCHES:
        a = np.linspace(-width, width, n)
        da, db = (x.ravel() for x in np.meshgrid(a, a, indexing="ij"))
        cu = np.clip(u[:, None] + hu * da, ua, ub)
        cv = np.clip(v[:, None] + hv * db, va, vb)
        f = value(cu, cv)
        k = np.argmax(f, axis=1)
        better = f[rows, k] > best
        u, v = np.where(better, cu[rows, k], u), np.where(better, cv[rows, k], v)
        best = np.where(better, f[rows, k], best)
    # the quadratic through the last patch's 3 x 3 points around the best one and its top
    i, j = np.divmod(k, n)
    inner = (i > 0) & (i < n - 1) & (j > 0) & (j < n - 1) & better
    g = f.reshape(-1, n, n)
    ii, jj = np.clip(i, 1, n - 2), np.clip(j, 1, n - 2)
    def at(di, dj):
        return g[rows, ii + di, jj + dj]
    gx, gy = 0.5 * (at(1, 0) - at(-1, 0)), 0.5 * (at(0, 1) - at(0, -1))
    axx, ayy = at(1, 0) - 2 * at(0, 0) + at(-1, 0), at(0, 1) - 2 * at(0, 0) + at(0, -1)
    axy = 0.25 * (at(1, 1) - at(1, -1) - at(-1, 1) + at(-1, -1))
    det = axx * ayy - axy * axy
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.clip((-ayy * gx + axy * gy) / det, -1.0, 1.0)
        y = np.clip((axy * gx - axx * gy) / det, -1.0, 1.0)
    step = 2.0 * _PATCHES[-1][0] / (n - 1)
    use = inner & (axx < 0) & (det > 0) & np.isfinite(x) & np.isfinite(y)
    if use.any():
        nu = np.clip(u[use] + step * hu * x[use], ua, ub)
        nv = np.clip(v[use] + step * hv * y[use], va, vb)
        best[use] = np.maximum(best[use], value(nu, nv))
    finite = best[np.isfinite(best)]
    return float(finite.max()) if finite.size else 0.0


def check_figures(nominal, corrected, zero, u, v, delta, outward, grid_shape, density=4,
                  realised=None):
    """Compute :class:`CheckFigures` for a corrected surface.

    Parameters
    ----------
    nominal, corrected : Surface
    zero : Surface
        The surface built the same way with a zero field.
    u, v, delta : array_like, shape (N,)
        Measured points' parameters and intended corrections.
    realised : array_like, shape (N,), optional
        The realised correction at the points when already known.
    """
    if realised is None:
        realised = realised_correction(nominal, corrected, u, v, outward, guess=delta)
    us, vs = dense_parameters(nominal, grid_shape, density)
    max_real = max_zero = 0.0
    peaks = []       # (|realised|, u, v) at the dense grid's local maxima
    # rows of the dense grid in blocks of about a million points (memory stays flat)
    step = max(1, int(1e6 // vs.size))
    for start in range(0, us.size, step):
        ub = us[start:start + step]
        S, Su, Sv = bspline.evaluate_grid(nominal, ub, vs, order=1)
        # no normal where the surface degenerates: NaN, left out below
        n = bspline.grid_unit_normals(Su, Sv, outward)
        # on the dense grid the normal line meets the corrected surface within the fit
        # error of the same (u, v), so the normal component of S - S_c(u, v) is the
        # realised correction to second order (exact Newton intersections at the points)
        real = np.einsum("ijk,ijk->ij", S - bspline.evaluate_grid(corrected, ub, vs), n)
        zero_dev = np.einsum("ijk,ijk->ij", S - bspline.evaluate_grid(zero, ub, vs), n)
        if np.isfinite(real).any():
            max_real = max(max_real, float(np.nanmax(np.abs(real))))
            max_zero = max(max_zero, float(np.nanmax(np.abs(zero_dev))))
            peaks.extend(_local_peaks(np.abs(real), ub, vs))
    max_real = max(max_real, _refined_peak(nominal, corrected, outward, peaks, us, vs))
    return CheckFigures(max_error_at_points=float(np.max(np.abs(np.ravel(realised)
                                                                - np.ravel(delta)))),
                        max_zero_deviation=max_zero, max_realised=max_real,
                        max_intended=float(np.max(np.abs(delta))),
                        dense_shape=(us.size, vs.size), poles_shape=tuple(corrected.shape))
