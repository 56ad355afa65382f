# SPDX-License-Identifier: LGPL-2.1-or-later
"""Smoothing fit of scattered deviations over the face's (u, v) (no FreeCAD).

The scattered counterpart of the grid path's mask filter
(:mod:`surfcomp.core.compensation.filters`, Werner 2022 eq. 3-5).

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
    :data:`~surfcomp.core.compensation.pspline.PSPLINE_MAX_COEFFS` coefficients; normal equations
    from per-cell moments, time and memory linear in N), again by one generalised
    eigen-decomposition (Demmler-Reinsch) on the coefficient grid; its leave-one-out
    residuals ``e_k = r_k / (1 - H_kk)`` are exact, evaluated at a seeded random
    subsample of :data:`~surfcomp.core.compensation.pspline.LOO_SAMPLE` points
    (:mod:`surfcomp.core.compensation.pspline`).

    Default smoothing (``smoothing=None``): the ``ell`` minimising the GCV score
    ``N RSS / tr(I - H)^2``.
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial.distance import cdist

from ...errors import InputError
from ..progress import report
from ..surface.uvpoints import check_duplicates, check_spread, scaled_points
from .pspline import PSplineSolver
from .spline_field import SplineField

#: largest number of points fitted with the exact thin-plate smoothing spline
EXACT_MAX = 1000
#: the GCV search spans ell = diameter * 10**[LOG_ELL_RANGE]
LOG_ELL_RANGE = (-3.0, 2.0)


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
    field : SplineField or None
        The fitted field over face parameters (``"pspline"`` fits; None for ``"tps"``),
        equal to ``determined`` at the points.
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
    field: object = None

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
    x = scaled_points(u, v, scale)
    d = np.asarray(d, dtype=float)
    if d.shape != (x.shape[0],):
        raise InputError("d must have shape (N,) = (%d,), got %r" % (x.shape[0], d.shape))
    if not np.all(np.isfinite(d)):
        raise InputError("deviation %d is not finite" % int(np.flatnonzero(~np.isfinite(d))[0]))
    if smoothing is not None and not (float(smoothing) >= 0 and np.isfinite(smoothing)):
        raise InputError("smoothing must be a length >= 0 (or None for GCV), got %r" % (smoothing,))
    if method not in ("auto", "tps", "pspline"):
        raise InputError("method must be 'auto', 'tps' or 'pspline', got %r" % (method,))
    check_spread(x, "smoothing fit", 4)
    n = x.shape[0]
    if method == "auto":
        method = "tps" if n <= EXACT_MAX else "pspline"
    lo, hi = x.min(axis=0), x.max(axis=0)
    area = float(np.prod(hi - lo))
    diam = float(np.hypot(*(hi - lo)))
    report(progress, 0.05, "decomposing the smoothing system")
    if method == "tps":
        check_duplicates(x, "smoothing fit")
        solver = _TPSSolver(x - lo, d)
        to_par = 8 * np.pi * n / area / (2 * np.pi) ** 4   # s = to_par * ell^4
    else:
        solver = PSplineSolver(x, d, lo, hi)
        to_par = n / area / (2 * np.pi) ** 4               # rho = to_par * ell^4
    report(progress, 0.6, "choosing the smoothing")
    if smoothing is None:
        chosen = "gcv"
        grid = np.linspace(*LOG_ELL_RANGE, 101)
        scores = np.array([solver.gcv(to_par * (diam * 10 ** g) ** 4) for g in grid])
        k = int(np.nanargmin(scores))
        a, b = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        # imported here: the module's importers (the workbench, the reports) need no optimizer
        from scipy.optimize import minimize_scalar

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
    field = None
    if method == "pspline":
        top = float(np.max(np.abs(determined)))
        field = SplineField(solver.spline(solver.coefficients(par)), scale, (-top, top))
    noise2 = float(resid @ resid) / max(n - dof, 1e-12) if n - dof > 1e-9 else 0.0
    loo_rms = float(np.sqrt(np.mean(loo ** 2)))
    report(progress, 1.0, "smoothing done")
    return SmoothFit(determined=determined, random=resid, smoothing=ell, chosen_by=chosen,
                     method=method, fit_rms=float(np.sqrt(np.mean(resid ** 2))),
                     fit_max=float(np.max(np.abs(resid))), loo_rms=loo_rms,
                     loo_max=float(np.max(np.abs(loo))), loo_points=int(loo.size),
                     dof=float(dof), noise_rms=float(np.sqrt(noise2)),
                     field_error_rms=float(np.sqrt(max(loo_rms ** 2 - noise2, 0.0))),
                     field=field)


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
    x = scaled_points(u, v, scale)
    d = np.asarray(d, dtype=float)
    check_spread(x, "leave-one-out", 4)
    check_duplicates(x, "leave-one-out")
    lo, hi = x.min(axis=0), x.max(axis=0)
    s = tps_smoothing_parameter(x.shape[0], float(np.prod(hi - lo)), smoothing)
    return _TPSSolver(x - lo, d).solve(s)[1]


def tps_smoothing_parameter(n, area, ell):
    """scipy ``RBFInterpolator(kernel="thin_plate_spline")`` ``smoothing`` value of the
    functional in the module docstring: ``8 pi n (ell / 2 pi)^4 / area``."""
    return 8 * np.pi * n * (ell / (2 * np.pi)) ** 4 / area
