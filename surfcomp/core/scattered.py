"""Deviation fields from scattered (non-grid) points over the face's (u, v) (no FreeCAD).

Two parts, the scattered counterparts of the grid path's mask filter
(:mod:`surfcomp.core.filters`, Werner 2022 eq. 3-5) and correction field
(:class:`surfcomp.core.field.GridField`):

:func:`smooth`
    A penalised least-squares (smoothing) fit of the deviations ``d`` at the points,
    whose values at the points are the *determined* (systematic) component and
    ``d - determined`` the *random* one. The fit minimises (Wahba 1990, ch. 2)::

        (1/N) sum_k (d_k - f(x_k))^2  +  (ell / 2 pi)^4  J(f) / A,
        J(f) = integral (f_xx^2 + 2 f_xy^2 + f_yy^2) dx dy

    over the scaled plane ``x = (u * scale_u, v * scale_v)`` (``scale`` converts
    parameter units into approximate arc length, e.g. mm per unit parameter, so
    that directions with very different parameter ranges are weighed fairly);
    ``A`` is the area of the points' bounding box. For densely sampled data this
    damps a sine of wavelength ``L`` by ``1 / (1 + (ell / L)^4)``: ``ell`` (the
    ``smoothing`` argument, in scaled units) is the wavelength that is halved, the
    role the mask size plays on grids. ``smoothing=0`` interpolates.

    Up to :data:`EXACT_MAX` points the minimiser is the thin-plate smoothing
    spline (scipy's ``RBFInterpolator(kernel="thin_plate_spline",
    smoothing=8 pi N (ell/2pi)^4 / A)``), solved once by an eigen-decomposition
    so that generalized cross-validation (GCV, Craven & Wahba 1979) and the exact
    leave-one-out residuals (Rippa 1999: ``e_k = alpha_k / (A^-1)_kk``) cost
    nothing extra per smoothing value. Above it, the same functional is minimised
    over a cubic tensor-product B-spline space on a uniform knot grid ("P-spline"
    with the exact thin-plate energy of the spline as penalty, at most
    :data:`PSPLINE_MAX_COEFFS` coefficients), again by one generalised
    eigen-decomposition (Demmler-Reinsch); its leave-one-out residuals
    ``e_k = r_k / (1 - H_kk)`` are exact, evaluated at a seeded random subsample
    of :data:`LOO_SAMPLE` points.

    Default smoothing (``smoothing=None``): the ``ell`` minimising the GCV score
    ``N RSS / tr(I - H)^2``.

:class:`ScatteredField`
    A C1 interpolant through values at the points (interface of
    :class:`~surfcomp.core.field.GridField` as used by
    :func:`surfcomp.core.corrected.build_matching_surface`): Clough-Tocher
    piecewise cubics (scipy's ``CloughTocher2DInterpolator`` construction,
    re-implemented vectorised so that a located query set can be re-evaluated
    with new values) on the Delaunay triangulation of the scaled points, with the
    node gradients minimising the curvature along the edges (Nielson 1983, the
    functional scipy's ``estimate_gradients_2d_global`` iterates on), here solved
    by preconditioned conjugate gradients to a relative residual of 1e-13, so the
    field is linear in the values to that precision.

    Outside the points' convex hull the triangulation is extended to a frame of
    "ghost" nodes around the face box; a ghost's value is the inverse-distance
    weighted mean of its nearest measured values (so it lies in their range) and
    the ghosts take part in the curvature minimisation, so the field continues
    C1 towards a bounded local mean instead of extrapolating a polynomial.
    Beyond the frame the query is clamped onto it. The field is finally clipped to
    the range of the node values like GridField's, so noisy data can never give a
    value beyond the largest given one.
"""

import inspect
import math
from dataclasses import dataclass

import numpy as np
from scipy import linalg as sla
from scipy import sparse
from scipy.optimize import minimize_scalar
from scipy.sparse.linalg import LinearOperator, cg
from scipy.spatial import Delaunay, cKDTree
from scipy.spatial.distance import cdist

from ..errors import ComputationError, InputError
from . import bspline
from .progress import report

#: the relative-tolerance keyword of ``cg``: ``tol`` up to scipy 1.11, ``rtol`` from 1.12
#: (``tol`` was removed in 1.14)
_CG_RTOL = "rtol" if "rtol" in inspect.signature(cg).parameters else "tol"

#: largest number of points fitted with the exact thin-plate smoothing spline
EXACT_MAX = 1000
#: largest number of tensor B-spline coefficients of the large-N smoothing fit
PSPLINE_MAX_COEFFS = 1100
#: leave-one-out residuals of the large-N fit are evaluated at this many points
LOO_SAMPLE = 20000
#: the GCV search spans ell = diameter * 10**[LOG_ELL_RANGE]
LOG_ELL_RANGE = (-3.0, 2.0)
#: ghost frame margin around the points and the face box (fraction of the larger side)
FRAME_MARGIN = 0.25
#: nearest measured nodes averaged into a ghost value
GHOST_NEIGHBOURS = 6
#: relative residual of the conjugate-gradient solve for the node gradients
GRADIENT_RTOL = 1e-13


# --------------------------------------------------------------------------- input checks
def _scaled_points(u, v, scale, what="points"):
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    if u.ndim != 1 or u.shape != v.shape:
        raise InputError("u and v of the %s must be 1-D arrays of equal length, got shapes %r "
                         "and %r" % (what, u.shape, v.shape))
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(v))):
        k = int(np.flatnonzero(~(np.isfinite(u) & np.isfinite(v)))[0])
        raise InputError("point %d of the %s has a non-finite (u, v) = (%g, %g)"
                         % (k, what, u[k], v[k]))
    su, sv = (float(s) for s in scale)
    if not (su > 0 and sv > 0 and np.isfinite(su) and np.isfinite(sv)):
        raise InputError("scale factors must be finite and > 0 (length per unit parameter), "
                         "got %r" % (scale,))
    return np.stack([u * su, v * sv], axis=1)


def _check_spread(x, what, minimum=3):
    n = x.shape[0]
    if n < minimum:
        raise InputError("%s: %d points given, at least %d (not on one line) are needed"
                         % (what, n, minimum))
    c = x - x.mean(axis=0)
    sv = np.linalg.svd(c, compute_uv=False)
    if sv[-1] <= 1e-9 * sv[0]:
        raise InputError("%s: the %d points lie on one line in (u, v); a surface field needs "
                         "points spread over the face" % (what, n))


def _check_duplicates(x, what):
    ext = float(np.max(np.ptp(x, axis=0)))
    pairs = cKDTree(x).query_pairs(1e-9 * ext, output_type="ndarray")
    if len(pairs):
        i, j = sorted(pairs[0])
        raise InputError("%s: points %d and %d have the same (u, v); merge or drop duplicate "
                         "measurements first" % (what, i, j))


# --------------------------------------------------------------------------- smoothing fit
@dataclass
class SmoothFit:
    """Result of :func:`smooth` (values in the units of ``d``, normally mm).

    Attributes
    ----------
    determined : ndarray, shape (N,)
        The smoothed field at the points (systematic component).
    random : ndarray, shape (N,)
        ``d - determined``.
    smoothing : float
        The smoothing length ``ell`` used (scaled units; the wavelength halved).
    chosen_by : str
        ``"user"`` or ``"gcv"``.
    method : str
        ``"tps"`` (exact thin-plate smoothing spline) or ``"pspline"``.
    fit_rms, fit_max : float
        RMS and max of ``|random|`` (the fit residual).
    loo_rms, loo_max : float
        RMS and max of the leave-one-out residuals ``d_k - f_(-k)(x_k)`` (the fit
        without point k, evaluated at point k): the error of the field at an
        unmeasured point *as seen by a new measurement*, i.e. including that
        measurement's own noise.
    loo_points : int
        How many leave-one-out residuals were evaluated (N, or a subsample).
    dof : float
        Effective degrees of freedom ``tr(H)`` of the fit.
    noise_rms : float
        Noise estimate ``sqrt(RSS / tr(I - H))`` (Wahba's variance estimate).
    field_error_rms : float
        Estimated RMS error of the field itself, ``sqrt(max(loo_rms^2 - noise_rms^2, 0))``.
    """

    determined: np.ndarray
    random: np.ndarray
    smoothing: float
    chosen_by: str
    method: str
    fit_rms: float
    fit_max: float
    loo_rms: float
    loo_max: float
    loo_points: int
    dof: float
    noise_rms: float
    field_error_rms: float

    def as_dict(self):
        """The scalar figures (for reports)."""
        return {k: getattr(self, k) for k in ("smoothing", "chosen_by", "method", "fit_rms",
                                              "fit_max", "loo_rms", "loo_max", "loo_points",
                                              "dof", "noise_rms", "field_error_rms")}


def _tps_kernel(x, y):
    r = cdist(x, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = r * r * np.log(r)
    k[r == 0] = 0.0
    return k


class _TPSSolver:
    """Thin-plate smoothing spline on fixed points, decomposed once for all smoothing values.

    With ``P = [1, x, y]`` and ``Q2`` an orthonormal basis of ``null(P^T)``, the system
    ``(K + s I) alpha + P beta = d, P^T alpha = 0`` gives
    ``alpha = Q2 W diag(1 / (mu + s)) W^T Q2^T d`` where ``Q2^T K Q2 = W diag(mu) W^T``
    (positive definite: K is conditionally positive definite of order 2). The
    residual is ``d - f = s alpha``, ``I - H = s C`` with ``C = Q2 W diag(1/(mu+s)) W^T Q2^T``
    the upper-left block of the inverse of the full system matrix, so Rippa's
    leave-one-out residual is ``alpha_k / C_kk``.
    """

    def __init__(self, x, d):
        n = x.shape[0]
        c = x - x.mean(axis=0)
        P = np.column_stack([np.ones(n), c / np.max(np.abs(c))])
        Q, _ = np.linalg.qr(P, mode="complete")
        Q2 = Q[:, 3:]
        K = _tps_kernel(x, x)
        mu, W = np.linalg.eigh(Q2.T @ K @ Q2)
        if mu[0] <= 0:
            mu = np.maximum(mu, mu[-1] * 1e-15)
        self.mu = mu
        self.QW = Q2 @ W
        self.z = self.QW.T @ d
        self.QW2 = self.QW ** 2
        self.n = n

    def gcv(self, s):
        f = s / (self.mu + s)
        rss = np.sum((f * self.z) ** 2)
        tr = np.sum(f)
        return self.n * rss / tr ** 2

    def solve(self, s):
        g = 1.0 / (self.mu + s)
        alpha = self.QW @ (g * self.z)
        resid = s * alpha
        Ckk = self.QW2 @ g
        loo = alpha / Ckk
        dof = self.n - s * np.sum(g)
        return resid, loo, dof


def _gauss_gram(knots, degree, n_poles, order):
    """Gram matrices ``int B_i^(r) B_j^(r)`` for r = 0..order over the knot domain
    (Gauss-Legendre, exact for the piecewise polynomials)."""
    xg, wg = np.polynomial.legendre.leggauss(degree + 1)
    brk = np.unique(knots[degree:n_poles + 1])
    a, b = brk[:-1, None], brk[1:, None]
    t = ((a + b) / 2 + (b - a) / 2 * xg).ravel()
    w = ((b - a) / 2 * wg).ravel()
    out = []
    for r in range(order + 1):
        B = bspline.basis_matrix(knots, degree, n_poles, t, deriv=r).toarray()
        out.append(B.T @ (B * w[:, None]))
    return out


def _tensor_rows(ku, kv, nu, nv, x):
    """Sparse tensor-product cubic basis rows at points x (N, 2)."""
    bu, su = bspline.basis_functions(ku, 3, x[:, 0])
    bv, sv = bspline.basis_functions(kv, 3, x[:, 1])
    n = x.shape[0]
    iu = su[:, None] - 3 + np.arange(4)
    iv = sv[:, None] - 3 + np.arange(4)
    cols = (iu[:, :, None] * nv + iv[:, None, :]).reshape(n, 16)
    vals = (bu[0][:, :, None] * bv[0][:, None, :]).reshape(n, 16)
    return sparse.csr_matrix((vals.ravel(), cols.ravel(), np.arange(0, 16 * n + 1, 16)),
                             shape=(n, nu * nv))


class _PSplineSolver:
    """Penalised cubic tensor B-spline fit, decomposed once (Demmler-Reinsch).

    ``min ||d - B c||^2 + rho c^T J c`` with J the exact thin-plate energy of the
    spline over its knot box. With ``M = G + tau J`` (G = B^T B, tau tiny, M positive
    definite) and the generalised eigenproblem ``J V = M V diag(s)``, ``V^T M V = I``:
    ``c = V diag(1 / (1 + (rho - tau) s)) V^T B^T d``.
    """

    def __init__(self, x, d, lo, hi):
        n = x.shape[0]
        ext = hi - lo
        # spans per direction: about N/4 coefficients, at most PSPLINE_MAX_COEFFS, aspect kept
        total = min(PSPLINE_MAX_COEFFS, max(16, n // 4))
        ratio = ext[0] / ext[1]
        nsu = int(np.clip(np.sqrt(total * ratio) - 3, 2, 200))
        nsv = int(np.clip(total / (nsu + 3) - 3, 2, 200))
        self.ku = np.r_[[lo[0]] * 3, np.linspace(lo[0], hi[0], nsu + 1), [hi[0]] * 3]
        self.kv = np.r_[[lo[1]] * 3, np.linspace(lo[1], hi[1], nsv + 1), [hi[1]] * 3]
        self.nu, self.nv = nsu + 3, nsv + 3
        B = _tensor_rows(self.ku, self.kv, self.nu, self.nv, x)
        G = (B.T @ B).toarray()
        h = B.T @ d
        S0u, S1u, S2u = _gauss_gram(self.ku, 3, self.nu, 2)
        S0v, S1v, S2v = _gauss_gram(self.kv, 3, self.nv, 2)
        J = np.kron(S2u, S0v) + 2 * np.kron(S1u, S1v) + np.kron(S0u, S2v)
        self.tau = 1e-9 * np.trace(G) / np.trace(J)
        s, V = sla.eigh(J, G + self.tau * J)
        self.s = np.maximum(s, 0.0)
        self.V = V
        self.y = V.T @ h
        self.dd = float(d @ d)
        self.B, self.d, self.n, self._J = B, d, n, J

    def _f(self, rho):
        return 1.0 / (1.0 + (rho - self.tau) * self.s)

    def gcv(self, rho):
        f = self._f(rho)
        y2 = self.y ** 2
        rss = max(self.dd - 2 * np.sum(y2 * f) + np.sum(y2 * (1 - self.tau * self.s) * f * f), 0.0)
        tr = self.n - np.sum((1 - self.tau * self.s) * f)
        return self.n * rss / tr ** 2

    def solve(self, rho, rng_seed=0):
        f = self._f(rho)
        c = self.V @ (f * self.y)
        resid = self.d - self.B @ c
        dof = float(np.sum((1 - self.tau * self.s) * f))
        if self.n > LOO_SAMPLE:
            idx = np.sort(np.random.default_rng(rng_seed).choice(self.n, LOO_SAMPLE, replace=False))
        else:
            idx = np.arange(self.n)
        Hkk = np.empty(idx.size)
        for a in range(0, idx.size, 4096):
            rows = self.B[idx[a:a + 4096]] @ self.V
            Hkk[a:a + 4096] = (rows ** 2) @ f
        loo = resid[idx] / np.maximum(1.0 - Hkk, 1e-12)
        return resid, loo, dof


def smooth(u, v, d, smoothing=None, scale=(1.0, 1.0), method="auto", progress=None):
    """Split scattered deviations into a smooth determined part and a random part.

    The scattered counterpart of the mask filter (Werner 2022, eq. 3-5): a
    smoothing fit over the face's (u, v), see the module docstring for the
    functional, the meaning of ``smoothing`` and the methods.

    Parameters
    ----------
    u, v : array_like, shape (N,)
        Face parameters of the points.
    d : array_like, shape (N,)
        Deviations (mm, or any unit: the results carry it); must be finite.
    smoothing : float, optional
        Smoothing length ``ell`` >= 0 in scaled units (the wavelength damped to
        half); 0 interpolates (``determined == d``). Default: chosen by
        generalized cross-validation.
    scale : (float, float)
        Length per unit parameter along u and v (e.g. mm per unit parameter from
        the face's mean arc length), so the fit is isotropic on the face.
    method : {"auto", "tps", "pspline"}
        ``"auto"``: thin-plate spline up to :data:`EXACT_MAX` points, else P-spline.
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    SmoothFit
    """
    x = _scaled_points(u, v, scale)
    d = np.asarray(d, dtype=float)
    if d.shape != (x.shape[0],):
        raise InputError("d must have shape (N,) = (%d,), got %r" % (x.shape[0], d.shape))
    if not np.all(np.isfinite(d)):
        raise InputError("deviation %d is not finite" % int(np.flatnonzero(~np.isfinite(d))[0]))
    if smoothing is not None and not (float(smoothing) >= 0 and np.isfinite(smoothing)):
        raise InputError("smoothing must be a length >= 0 (or None for GCV), got %r" % (smoothing,))
    if method not in ("auto", "tps", "pspline"):
        raise InputError("method must be 'auto', 'tps' or 'pspline', got %r" % (method,))
    _check_spread(x, "smoothing fit", 4)
    n = x.shape[0]
    if method == "auto":
        method = "tps" if n <= EXACT_MAX else "pspline"
    lo, hi = x.min(axis=0), x.max(axis=0)
    area = float(np.prod(hi - lo))
    diam = float(np.hypot(*(hi - lo)))
    report(progress, 0.05, "decomposing the smoothing system")
    if method == "tps":
        _check_duplicates(x, "smoothing fit")
        solver = _TPSSolver(x - lo, d)
        to_par = 8 * np.pi * n / area / (2 * np.pi) ** 4   # s = to_par * ell^4
    else:
        solver = _PSplineSolver(x, d, lo, hi)
        to_par = n / area / (2 * np.pi) ** 4               # rho = to_par * ell^4
    report(progress, 0.6, "choosing the smoothing")
    if smoothing is None:
        chosen = "gcv"
        grid = np.linspace(*LOG_ELL_RANGE, 101)
        scores = np.array([solver.gcv(to_par * (diam * 10 ** g) ** 4) for g in grid])
        k = int(np.nanargmin(scores))
        a, b = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        res = minimize_scalar(lambda g: solver.gcv(to_par * (diam * 10 ** g) ** 4),
                              bounds=(a, b), method="bounded", options={"xatol": 1e-4})
        g = res.x if res.fun <= scores[k] else grid[k]
        ell = float(diam * 10 ** g)
    else:
        chosen = "user"
        ell = float(smoothing)
    par = to_par * ell ** 4
    report(progress, 0.8, "leave-one-out residuals")
    resid, loo, dof = solver.solve(par)
    if method == "tps" and ell == 0:
        resid = np.zeros(n)
    determined = d - resid
    noise2 = float(resid @ resid) / max(n - dof, 1e-12) if n - dof > 1e-9 else 0.0
    loo_rms = float(np.sqrt(np.mean(loo ** 2)))
    report(progress, 1.0, "smoothing done")
    return SmoothFit(determined=determined, random=resid, smoothing=ell, chosen_by=chosen,
                     method=method, fit_rms=float(np.sqrt(np.mean(resid ** 2))),
                     fit_max=float(np.max(np.abs(resid))), loo_rms=loo_rms,
                     loo_max=float(np.max(np.abs(loo))), loo_points=int(loo.size),
                     dof=float(dof), noise_rms=float(np.sqrt(noise2)),
                     field_error_rms=float(np.sqrt(max(loo_rms ** 2 - noise2, 0.0))))


def loo_residuals(u, v, d, smoothing=0.0, scale=(1.0, 1.0)):
    """Exact leave-one-out residuals of the thin-plate (smoothing) spline (Rippa 1999).

    Parameters
    ----------
    u, v, d : array_like, shape (N,)
    smoothing : float
        Smoothing length ``ell`` (see :func:`smooth`); 0 interpolates.
    scale : (float, float)

    Returns
    -------
    ndarray, shape (N,)
        ``d_k - f_(-k)(x_k)``, f_(-k) fitted without point k with the same
        smoothing parameter (scipy's ``smoothing = 8 pi N (ell/2pi)^4 / A`` of the
        full set).
    """
    x = _scaled_points(u, v, scale)
    d = np.asarray(d, dtype=float)
    _check_spread(x, "leave-one-out", 4)
    _check_duplicates(x, "leave-one-out")
    lo, hi = x.min(axis=0), x.max(axis=0)
    s = tps_smoothing_parameter(x.shape[0], float(np.prod(hi - lo)), smoothing)
    return _TPSSolver(x - lo, d).solve(s)[1]


def tps_smoothing_parameter(n, area, ell):
    """scipy ``RBFInterpolator(kernel="thin_plate_spline")`` ``smoothing`` value of the
    functional in the module docstring: ``8 pi n (ell / 2 pi)^4 / area``."""
    return 8 * np.pi * n * (ell / (2 * np.pi)) ** 4 / area


# --------------------------------------------------------------------------- Clough-Tocher
def _ct_edges(tri):
    """Each edge of the triangulation once (its triangle is the lower-numbered one)."""
    simp, nb = tri.simplices, tri.neighbors
    t = np.arange(simp.shape[0])
    out = []
    for k in range(3):
        own = (nb[:, k] < 0) | (nb[:, k] > t)
        out.append(simp[own][:, [(k + 1) % 3, (k + 2) % 3]])  # the edge opposite vertex k
    return np.concatenate(out)


def _gradient_system(points, tri):
    """Sparse M (2n x 2n), its inverted 2 x 2 diagonal blocks (n, 2, 2) and R (2n x n)
    with ``M g = R f`` the minimiser over the node gradients g of the edge curvature
    sum ``sum_e int (d^2 f / ds^2)^2 ds`` (cubic Hermite along each edge; Nielson 1983,
    the functional of scipy's estimate_gradients_2d_global)."""
    n = points.shape[0]
    E = _ct_edges(tri)
    i, j = E[:, 0], E[:, 1]
    e = points[j] - points[i]
    L3 = np.sum(e * e, axis=1) ** 1.5
    ee = (e[:, :, None] * e[:, None, :] / L3[:, None, None]).reshape(-1, 4)   # (m, 4)
    pq = np.array([[0, 0], [0, 1], [1, 0], [1, 1]])
    rows = np.concatenate([2 * a[:, None] + pq[:, 0] for a in (i, j, i, j)]).ravel()
    cols = np.concatenate([2 * b[:, None] + pq[:, 1] for b in (i, j, j, i)]).ravel()
    vals = np.concatenate([8 * ee, 8 * ee, 4 * ee, 4 * ee]).ravel()
    M = sparse.csr_matrix((vals, (rows, cols)), shape=(2 * n, 2 * n))
    blocks = np.stack([np.bincount(i, 8 * ee[:, c], n) + np.bincount(j, 8 * ee[:, c], n)
                       for c in range(4)], axis=1).reshape(n, 2, 2)
    # R f: 12 (f_j - f_i) e / L^3 added to both ends
    c = 12.0 * e / L3[:, None]                                                 # (m, 2)
    r_rows = np.concatenate([2 * a[:, None] + np.arange(2) for a in (i, i, j, j)]).ravel()
    r_cols = np.concatenate([np.repeat(b, 2) for b in (j, i, j, i)])
    r_vals = np.concatenate([c, -c, c, -c]).ravel()
    R = sparse.csr_matrix((r_vals, (r_rows, r_cols)), shape=(2 * n, n))
    det = blocks[:, 0, 0] * blocks[:, 1, 1] - blocks[:, 0, 1] * blocks[:, 1, 0]
    inv = np.stack([blocks[:, 1, 1], -blocks[:, 0, 1], -blocks[:, 1, 0], blocks[:, 0, 0]],
                   axis=1).reshape(n, 2, 2) / det[:, None, None]
    return M, inv, R


def _transforms(points, simplices):
    """Barycentric transforms like ``Delaunay.transform``: T (ns, 2, 2) and r (ns, 2)
    with ``(b0, b1) = T (x - r)``, ``b2 = 1 - b0 - b1``."""
    P = points[simplices]
    A = np.stack([P[:, 0] - P[:, 2], P[:, 1] - P[:, 2]], axis=2)            # columns
    det = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    T = np.stack([np.stack([A[:, 1, 1], -A[:, 0, 1]], 1),
                  np.stack([-A[:, 1, 0], A[:, 0, 0]], 1)], 1) / det[:, None, None]
    return T, P[:, 2]


def _ct_gfactors(tri, T, r):
    """scipy's affine-invariant C1 direction factors g (n_simplex, 3)."""
    simp, nb = tri.simplices, tri.neighbors
    cent = tri.points[simp].mean(axis=1)                     # (T, 2)
    g = np.full(nb.shape, -0.5)
    for k in range(3):
        has = nb[:, k] >= 0
        y = cent[nb[has, k]]
        c01 = np.einsum("tij,tj->ti", T[has], y - r[has])
        c = np.column_stack([c01, 1.0 - c01.sum(axis=1)])
        if k == 0:
            g[has, 0] = (2 * c[:, 2] + c[:, 1] - 1) / (2 - 3 * c[:, 2] - 3 * c[:, 1])
        elif k == 1:
            g[has, 1] = (2 * c[:, 0] + c[:, 2] - 1) / (2 - 3 * c[:, 0] - 3 * c[:, 2])
        else:
            g[has, 2] = (2 * c[:, 1] + c[:, 0] - 1) / (2 - 3 * c[:, 1] - 3 * c[:, 0])
    return g


#: Bezier ordinates of the Clough-Tocher split: (i, j, k, l) exponents of b1, b2, b3, b4
_CT_KEYS = ("3000", "0300", "0030", "2100", "2010", "1200", "0210", "1020", "0120",
            "2001", "0201", "0021", "1101", "1011", "0111", "1002", "0102", "0012", "0003")
_CT_MULT = np.array([6.0 / np.prod([math.factorial(int(c)) for c in key]) for key in _CT_KEYS])


def _ct_coefficients(points, simplices, gfac, f, grad):
    """The 19 Bezier ordinates per triangle (T, 19, c) from node values f (n, c) and
    gradients grad (n, 2, c) (scipy's _clough_tocher_2d_single, vectorised)."""
    P = points[simplices]                                    # (T, 3, 2)
    e12 = P[:, 1] - P[:, 0]
    e23 = P[:, 2] - P[:, 1]
    e31 = P[:, 0] - P[:, 2]
    F = f[simplices]                                         # (T, 3, c)
    D = grad[simplices]                                      # (T, 3, 2, c)

    def dd(k, e):
        return np.einsum("tpc,tp->tc", D[:, k], e)

    f1, f2, f3 = F[:, 0], F[:, 1], F[:, 2]
    df12, df21 = dd(0, e12), -dd(1, e12)
    df23, df32 = dd(1, e23), -dd(2, e23)
    df31, df13 = dd(2, e31), -dd(0, e31)
    c = {}
    c["3000"], c["0300"], c["0030"] = f1, f2, f3
    c["2100"] = f1 + df12 / 3
    c["2010"] = f1 + df13 / 3
    c["1200"] = f2 + df21 / 3
    c["0210"] = f2 + df23 / 3
    c["1020"] = f3 + df31 / 3
    c["0120"] = f3 + df32 / 3
    c["2001"] = (c["2100"] + c["2010"] + c["3000"]) / 3
    c["0201"] = (c["1200"] + c["0300"] + c["0210"]) / 3
    c["0021"] = (c["1020"] + c["0120"] + c["0030"]) / 3
    g0, g1, g2 = (gfac[:, k, None] for k in range(3))
    c["0111"] = (g0 * (-c["0300"] + 3 * c["0210"] - 3 * c["0120"] + c["0030"])
                 + (-c["0300"] + 2 * c["0210"] - c["0120"] + c["0021"] + c["0201"])) / 2
    c["1011"] = (g1 * (-c["0030"] + 3 * c["1020"] - 3 * c["2010"] + c["3000"])
                 + (-c["0030"] + 2 * c["1020"] - c["2010"] + c["2001"] + c["0021"])) / 2
    c["1101"] = (g2 * (-c["3000"] + 3 * c["2100"] - 3 * c["1200"] + c["0300"])
                 + (-c["3000"] + 2 * c["2100"] - c["1200"] + c["2001"] + c["0201"])) / 2
    c["1002"] = (c["1101"] + c["1011"] + c["2001"]) / 3
    c["0102"] = (c["1101"] + c["0111"] + c["0201"]) / 3
    c["0012"] = (c["1011"] + c["0111"] + c["0021"]) / 3
    c["0003"] = (c["1002"] + c["0102"] + c["0012"]) / 3
    return np.stack([c[k] for k in _CT_KEYS], axis=1) * _CT_MULT[None, :, None]


def _ct_basis(bary):
    """Bernstein monomials (M, 19) of the split at barycentric coordinates (M, 3), in
    :data:`_CT_KEYS` order (multinomial factors are in the ordinates)."""
    m = bary.min(axis=1)
    b1, b2, b3 = (bary[:, k] - m for k in range(3))       # one of them is 0
    b4 = 3 * m
    out = np.empty((bary.shape[0], len(_CT_KEYS)))
    for col, key in enumerate(_CT_KEYS):
        term = None
        for b, e in zip((b1, b2, b3, b4), key):
            e = int(e)
            if e:
                p = b if e == 1 else (b * b if e == 2 else b * b * b)
                term = p if term is None else term * p
        out[:, col] = term
    return out


def _ct_evaluate(coef, simplex, bary, chunk=1 << 18):
    """Values (M, c) of the Clough-Tocher patches ``coef`` (T, 19, c) at located points."""
    out = np.empty((simplex.size, coef.shape[2]))
    for a in range(0, simplex.size, chunk):
        s = slice(a, a + chunk)
        out[s] = np.einsum("mk,mkc->mc", _ct_basis(bary[s]), coef[simplex[s]])
    return out


def _block_jacobi(M, inv):
    """Block-Jacobi preconditioner from the inverted 2 x 2 diagonal blocks of M."""
    return LinearOperator(M.shape, dtype=float,
                          matvec=lambda r: np.einsum("nij,nj->ni", inv, r.reshape(-1, 2)).ravel())


def _solve_gradients(M, precond, rhs):
    """Node gradients from ``M g = rhs`` (conjugate gradients, block-Jacobi preconditioned,
    relative residual 1e-13: linear in the values to that precision)."""
    if not np.any(rhs):
        return np.zeros_like(rhs)
    g, info = cg(M, rhs, atol=0.0, M=precond, maxiter=20000, **{_CG_RTOL: GRADIENT_RTOL})
    if info != 0:
        raise ComputationError("the gradient system of the scattered field did not converge "
                               "(%d iterations); the node layout is too degenerate" % info)
    return g


# --------------------------------------------------------------------------- the field
class ScatteredField:
    """C1 interpolant of values at scattered points over the face's (u, v).

    See the module docstring for the construction. The interface is the one
    :func:`surfcomp.core.corrected.build_matching_surface` uses with
    :class:`~surfcomp.core.field.GridField`.

    Parameters
    ----------
    U, V : array_like, shape (N,)
        Face parameters of the points (distinct, not all on one line, N >= 3).
    values : array_like, shape (N,) or (N, k)
        Values at the points (mm); finite.
    scale : (float, float)
        Length per unit parameter along u and v (see :func:`smooth`).
    box : ((u0, u1), (v0, v1)), optional
        The face's parameter box; the ghost frame is placed around it and the
        points so that the whole box lies inside the triangulation.

    Notes
    -----
    Bounds: every value is within ``[min(values), max(values)]`` (clipped like
    GridField), so ``|field| <= max|values|`` everywhere.
    """

    def __init__(self, U, V, values, scale=(1.0, 1.0), box=None):
        x = _scaled_points(np.ravel(U), np.ravel(V), scale, "field nodes")
        _check_spread(x, "scattered field", 3)
        _check_duplicates(x, "scattered field")
        self._scale = np.array([float(s) for s in scale])
        n = x.shape[0]
        lo, hi = x.min(axis=0), x.max(axis=0)
        if box is not None:
            (u0, u1), (v0, v1) = box
            blo = np.array([min(u0, u1), min(v0, v1)]) * self._scale
            bhi = np.array([max(u0, u1), max(v0, v1)]) * self._scale
            lo, hi = np.minimum(lo, blo), np.maximum(hi, bhi)
        ext = hi - lo
        margin = FRAME_MARGIN * float(ext.max())
        flo, fhi = lo - margin, hi + margin
        # ghost spacing: about 4 mean point spacings, 4..256 per side
        h = 4.0 * np.sqrt(np.prod(np.maximum(x.max(0) - x.min(0), 1e-300)) / n)
        side = fhi - flo
        nu = int(np.clip(np.ceil(side[0] / h), 4, 256))
        nv = int(np.clip(np.ceil(side[1] / h), 4, 256))
        gu = np.linspace(flo[0], fhi[0], nu + 1)
        gv = np.linspace(flo[1], fhi[1], nv + 1)
        ghosts = np.concatenate([
            np.column_stack([gu, np.full(gu.size, flo[1])]),
            np.column_stack([gu, np.full(gu.size, fhi[1])]),
            np.column_stack([np.full(gv.size - 2, flo[0]), gv[1:-1]]),
            np.column_stack([np.full(gv.size - 2, fhi[0]), gv[1:-1]])])
        k = min(GHOST_NEIGHBOURS, n)
        dist, idx = cKDTree(x).query(ghosts, k=k)
        dist, idx = dist.reshape(len(ghosts), k), idx.reshape(len(ghosts), k)
        w = 1.0 / dist ** 2
        w /= w.sum(axis=1, keepdims=True)
        self._ghost_w = sparse.csr_matrix((w.ravel(), idx.ravel(),
                                           np.arange(0, w.size + 1, k)), shape=(len(ghosts), n))
        pts = np.concatenate([x, ghosts])
        self._tri = Delaunay(pts)
        if len(self._tri.coplanar):
            raise ComputationError("the Delaunay triangulation of the field nodes dropped %d "
                                   "points" % len(self._tri.coplanar))
        self._frame = (flo, fhi)
        self._n = n
        self._T, self._r = _transforms(pts, self._tri.simplices)
        self._gfac = _ct_gfactors(self._tri, self._T, self._r)
        self._M, inv, self._R = _gradient_system(pts, self._tri)
        self._precond = _block_jacobi(self._M, inv)
        self._set_values(values)

    def _set_values(self, values):
        vals = np.asarray(values, dtype=float)
        if vals.shape[:1] != (self._n,) or vals.ndim not in (1, 2):
            raise InputError("field values must have shape (N,) or (N, k) with N = %d, got %r"
                             % (self._n, vals.shape))
        if not np.all(np.isfinite(vals)):
            raise InputError("field values must be finite at every node")
        self._scalar = vals.ndim == 1
        v2 = vals[:, None] if self._scalar else vals
        f = np.concatenate([v2, self._ghost_w @ v2])
        grad = np.column_stack([_solve_gradients(self._M, self._precond, self._R @ f[:, c])
                                for c in range(f.shape[1])]).reshape(-1, 2, f.shape[1])
        self._coef = _ct_coefficients(self._tri.points, self._tri.simplices, self._gfac, f, grad)
        self._lo, self._hi = v2.min(axis=0), v2.max(axis=0)
        self.values = vals

    def with_values(self, values):
        """The same field (nodes, triangulation, factorisation) with new node values.

        Parameters
        ----------
        values : array_like, shape (N,) or (N, k)
        """
        other = object.__new__(ScatteredField)
        other.__dict__.update(self.__dict__)
        other._set_values(values)
        return other

    def locate(self, u, v):
        """Triangle and barycentric coordinates of face parameters (u, v).

        Points beyond the ghost frame are clamped onto it.

        Parameters
        ----------
        u, v : array_like, shape (M,)

        Returns
        -------
        simplex : ndarray of int, shape (M,)
        bary : ndarray, shape (M, 3)
        """
        q = np.stack([np.ravel(u) * self._scale[0], np.ravel(v) * self._scale[1]], axis=1)
        flo, fhi = self._frame
        pad = 1e-9 * (fhi - flo)
        q = np.clip(q, flo + pad, fhi - pad)
        simplex = self._tri.find_simplex(q)
        if np.any(simplex < 0):
            bad = int(np.flatnonzero(simplex < 0)[0])
            raise ComputationError("could not locate (u, v) = (%g, %g) in the field's "
                                   "triangulation" % tuple(q[bad] / self._scale))
        b01 = np.einsum("mij,mj->mi", self._T[simplex], q - self._r[simplex])
        bary = np.column_stack([b01, 1.0 - b01.sum(axis=1)])
        return simplex, bary

    def at_index(self, simplex, bary):
        """Field values at located points (see :meth:`locate`), clipped to the node range.

        Returns
        -------
        ndarray, shape (M,) or (M, k)
        """
        val = np.clip(_ct_evaluate(self._coef, np.asarray(simplex), np.asarray(bary)),
                      self._lo, self._hi)
        return val[:, 0] if self._scalar else val

    def __call__(self, u, v):
        """Field values at face parameters (u, v) (arrays of equal shape)."""
        shape = np.shape(u)
        out = self.at_index(*self.locate(u, v))
        return out.reshape(shape) if self._scalar else out.reshape(shape + (out.shape[-1],))
