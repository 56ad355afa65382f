# SPDX-License-Identifier: LGPL-2.1-or-later
"""Adaptive measurement points: denser where the slope changes fast (no FreeCAD).

The mirror paper (2019, section 2.3) placed its points along the u-curves of the face,
"added measurement points at locations where the change of the slope of two adjacent
measurement points was significant, and removed [them] where the change ... was little".
The change of slope between two adjacent points a distance ``ds`` apart is the angle the
normal turns, ``kappa ds`` with ``kappa`` the curvature. Over a face the normal turns at
the rate

    kappa(u, v) = sqrt(k1^2 + k2^2)     (1/mm; k1, k2 the principal curvatures)

and the points are placed with the density (points per mm^2)

    rho(u, v) = c (kappa_mean + kappa(u, v))

``kappa_mean`` the area mean of ``kappa`` over the reachable part of the face and ``c`` set
by the number of points. A region whose normal turns as fast as the mean gets twice the
density of a flat one; one three times the mean, four times; a face of constant curvature
(a plane, a sphere) gets a uniform layout.

Placement (deterministic, as the paper's curves): rows along u, each a u-curve at a fixed
v. The rows are spaced by the density's square root averaged along the row (``rho_row``),
so rows and the points on them are about as far apart; row ``i`` gets points in proportion
to ``sqrt(rho_row) * length``, spread along the row by equidistribution (equal integrals of
``rho`` along the arc between neighbours). Only the part of each row that the planner
allows (on the face, clear of its boundary and holes by the margin, tilted at most
``max_tilt``) receives points.
"""

import numpy as np

from ..surface import bspline
from .planning_face import curvatures_from

#: samples of the density over the face (at least; 8 per requested point above that)
MIN_SAMPLES = 40000
#: samples along each row
ROW_SAMPLES = (256, 4000)


def turning_rate(domain, u, v):
    """``kappa = sqrt(k1^2 + k2^2)`` (1/mm) at ``(u, v)``: how fast the normal turns."""
    k1, k2 = domain.curvatures(u, v)
    return np.hypot(k1, k2)


def _cdf_quantiles(x, weights, count):
    """``count`` positions in ``x`` (M,) at the mid-quantiles of the piecewise-constant
    density whose segment ``[x_k, x_k+1]`` carries ``weights[k]`` (M - 1,)."""
    cum = np.concatenate([[0.0], np.cumsum(weights)])
    targets = (np.arange(count) + 0.5) / count * cum[-1]
    k = np.clip(np.searchsorted(cum, targets, side="right") - 1, 0, len(weights) - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.where(weights[k] > 0, (targets - cum[k]) / weights[k], 0.5)
    return x[k] + frac * (x[k + 1] - x[k])


def _allocate(shares, total):
    """Whole numbers proportional to ``shares`` summing to ``total`` (largest remainder)."""
    shares = np.asarray(shares, dtype=float)
    if shares.sum() <= 0:
        return np.zeros(len(shares), dtype=np.int64)
    exact = shares / shares.sum() * total
    out = np.floor(exact).astype(np.int64)
    rest = int(total - out.sum())
    if rest > 0:
        out[np.argsort(-(exact - out), kind="stable")[:rest]] += 1
    return out


def _row_profile(domain, us, v, allowed, kappa_mean, uniform=False):
    """Density, allowed mask and arc length along the u-curve at ``v`` (samples ``us``):
    ``(rho (Gu,), ok (Gu,), seg_len (Gu - 1,))``."""
    vv = np.full(us.shape, float(v))
    D = bspline.derivatives(domain.surface, us, vv, 2)
    k1, k2 = curvatures_from(D, domain.outward)
    rho = kappa_mean + np.hypot(k1, k2) * (0.0 if uniform else 1.0)
    ok = allowed(us, vv, D[0], D[1], D[2])
    seg = np.linalg.norm(np.diff(D[0], axis=0), axis=1)
    return rho, ok, seg


def adaptive_layout(domain, count, allowed, samples=None, uniform=False):
    """``count`` adaptive points on the face (module docstring).

    Parameters
    ----------
    domain : FaceDomain
    count : int
        Points wanted.
    allowed : callable
        ``allowed(u, v, S, Su, Sv) -> bool array``: where points may go (on the face,
        margin, tilt).
    samples : int, optional
        Density samples over the face (default ``max(MIN_SAMPLES, 8 * count)``).
    uniform : bool
        A constant density instead (the same rows and equidistribution: the adaptive
        layout's uniform twin, for comparisons at equal point counts).

    Returns
    -------
    dict
        ``u``, ``v``, ``row``, ``along`` (N,) with N <= ``count`` (fewer only when the
        allowed part of the face is empty), ``kappa_mean`` (1/mm), ``rows`` (int).
    """
    us, vs = domain.samples(samples or max(MIN_SAMPLES, 8 * int(count)))
    D = bspline.evaluate_grid(domain.surface, us, vs, order=2)
    flat = tuple(d.reshape(-1, 3) for d in D)
    U, V = np.meshgrid(us, vs, indexing="ij")
    ok = allowed(U.ravel(), V.ravel(), flat[0], flat[1], flat[2]).reshape(U.shape)
    k1, k2 = curvatures_from(flat, domain.outward)
    kappa = np.hypot(k1, k2).reshape(U.shape) * (0.0 if uniform else 1.0)
    area = np.linalg.norm(np.cross(D[1], D[2]), axis=-1) * ok
    empty = dict(u=np.zeros(0), v=np.zeros(0), row=np.zeros(0, int), along=np.zeros(0),
                 kappa_mean=0.0, rows=0)
    if not area.sum() > 0:
        return empty
    kappa_mean = float((kappa * area).sum() / area.sum())
    if kappa_mean <= 0:
        kappa_mean = 1.0          # flat: any constant gives the uniform layout
    rho = kappa_mean + kappa
    seg_u = np.linalg.norm(np.diff(D[0], axis=0), axis=-1)         # (Gu-1, Gv)
    both = ok[:-1] & ok[1:]
    length = (seg_u * both).sum(axis=0)                              # (Gv,)
    mass = (0.5 * (rho[:-1] + rho[1:]) * seg_u * both).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        rho_row = np.where(length > 0, mass / length, 0.0)
    across = np.linalg.norm(D[2], axis=-1).mean(axis=0)             # |Sv| per row
    g = np.sqrt(rho_row) * across * (length > 0)
    dv = np.diff(vs)
    w = 0.5 * (g[:-1] + g[1:]) * dv
    total_area = float(area.sum() * (us[1] - us[0]) * (vs[1] - vs[0]))
    mean_len = float(length[length > 0].mean())
    n_rows = int(np.clip(round(np.sqrt(count * total_area) / max(mean_len, 1e-12)), 1, count))
    v_rows = _cdf_quantiles(vs, w, n_rows)
    gu = int(np.clip(len(us), *ROW_SAMPLES))
    ur = np.linspace(us[0], us[-1], gu)
    profiles = [_row_profile(domain, ur, v, allowed, kappa_mean, uniform) for v in v_rows]
    shares = []
    for rho_r, ok_r, seg in profiles:
        both_r = ok_r[:-1] & ok_r[1:]
        L = float((seg * both_r).sum())
        m = float((0.5 * (rho_r[:-1] + rho_r[1:]) * seg * both_r).sum())
        shares.append(np.sqrt(m / L) * L if L > 0 else 0.0)
    per_row = _allocate(shares, int(count))
    us_out, vs_out, rows, along = [], [], [], []
    for i, ((rho_r, ok_r, seg), n) in enumerate(zip(profiles, per_row)):
        if n <= 0:
            continue
        wts = 0.5 * (rho_r[:-1] + rho_r[1:]) * seg * (ok_r[:-1] & ok_r[1:])
        u = _cdf_quantiles(ur, wts, int(n))
        us_out.append(u)
        vs_out.append(np.full(u.shape, v_rows[i]))
        rows.append(np.full(u.shape, i))
        along.append(u)
    if not us_out:
        return empty
    return dict(u=np.concatenate(us_out), v=np.concatenate(vs_out), row=np.concatenate(rows),
                along=np.concatenate(along), kappa_mean=kappa_mean, rows=n_rows)
