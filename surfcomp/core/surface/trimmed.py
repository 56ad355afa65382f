# SPDX-License-Identifier: LGPL-2.1-or-later
"""Integrals over a trimmed face: the parameter domain bounded by the face's wires.

Pure numpy (no FreeCAD): the app layer gives the boundary as polylines in (u, v), one per
edge in its direction along the boundary (:func:`surfcomp.app.nominal.boundary_polylines`).
"""

import numpy as np

from . import bspline

#: knots per direction above which integrals over a corrected surface do not break their
#: panels at its knots (a fixed number of panels instead)
MAX_KNOTS = 400

#: panels of the composite Gauss-Legendre rule across the domain in u (besides the knots),
#: and Gauss points per panel (exact for polynomial pieces up to degree 5)
_PANELS = 16
_GAUSS = 3


def domain_integral(func, pieces, box=None, knots=None, panels=_PANELS, grid=None):
    """Integral of ``func(u, v)`` over the region bounded by ``pieces`` (Green's theorem).

    ``integral over D of f du dv = loop integral over the boundary of F dv`` with
    ``F(u, v) = integral from u0 to u of f(s, v) ds``: ``F`` by composite Gauss-Legendre
    panels in u (from ``u0``, broken at fixed places and at the knots), the loop integral by
    the midpoint rule on the boundary's segments. The sign is chosen so that the region's
    area is positive, so the pieces may run all counter-clockwise or all clockwise around
    the region (a face's edges as oriented in it: holes run the other way round).

    Parameters
    ----------
    func : callable
        Vectorised ``func(u, v) -> values`` for (N,) arrays.
    pieces : list of (n, 2) arrays
        The boundary in (u, v), each piece in its direction along the boundary (a face's
        edges); together they form closed loops.
    box : (u0, u1, v0, v1), optional
        Where the panels in u start and end (default: the pieces' extent in u). Two
        integrals over nearly the same region with the same box and knots differ by the
        difference of the regions, not by their quadrature errors.
    knots : (array, array), optional
        Knots in u and v of the surfaces in ``func``: panels break at the u knots, so
        every panel holds one polynomial piece.
    panels : int
        Panels across the box in u besides the knots.
    grid : callable, optional
        ``grid(us, vs) -> (len(us), len(vs))`` values of ``func`` on a tensor grid (for a
        B-spline integrand: :func:`surfcomp.core.surface.bspline.evaluate_grid`, far cheaper than
        point by point). The whole panels are then summed on the grid of their nodes and
        the pieces' v values, the same rule as without it; ``func`` takes the part-panels.

    Returns
    -------
    float
    """
    segs = np.concatenate([np.stack([np.asarray(p, float)[:-1], np.asarray(p, float)[1:]],
                                    axis=1) for p in pieces])     # (m, 2 ends, 2 coords)
    mid = 0.5 * (segs[:, 0] + segs[:, 1])
    dv = segs[:, 1, 1] - segs[:, 0, 1]
    keep = dv != 0.0
    mid, dv = mid[keep], dv[keep]
    if box is None:
        box = (segs[..., 0].min(), segs[..., 0].max())
    u0, u1 = box[0], box[1]
    breaks = _breaks(u0, u1, panels, () if knots is None else knots[0])
    x, w = np.polynomial.legendre.leggauss(_GAUSS)
    full_s, full_w = _composite(breaks, x, w)                 # (panels * gauss,)
    # panels wholly between u0 and each point, and the part-panel up to it
    k = np.clip(np.searchsorted(breaks, mid[:, 0], side="right") - 1, 0, len(breaks) - 2)
    n_full = k * _GAUSS
    if grid is not None:
        lo = breaks[k]
        half = 0.5 * (mid[:, 0] - lo)
        s = ((lo + half)[:, None] + half[:, None] * x).ravel()
        wt = (half[:, None] * w).ravel()
        part = (func(s, np.repeat(mid[:, 1], _GAUSS)) * wt).reshape(-1, _GAUSS).sum(axis=1)
        F = part + _full_panels(grid, full_s, full_w, n_full, mid[:, 1])
        area = np.dot(mid[:, 0] - u0, dv)
        return float(np.sign(area) * np.dot(F, dv))
    point = np.repeat(np.arange(mid.shape[0]), n_full)
    start = np.repeat(np.cumsum(n_full) - n_full, n_full)
    node = np.arange(point.size) - start
    lo = breaks[k]
    half = 0.5 * (mid[:, 0] - lo)
    s = np.concatenate([full_s[node], ((lo + half)[:, None] + half[:, None] * x).ravel()])
    v = np.concatenate([mid[point, 1], np.repeat(mid[:, 1], _GAUSS)])
    wt = np.concatenate([full_w[node], (half[:, None] * w).ravel()])
    owner = np.concatenate([point, np.repeat(np.arange(mid.shape[0]), _GAUSS)])
    F = np.bincount(owner, weights=func(s, v) * wt, minlength=mid.shape[0])
    area = np.dot(mid[:, 0] - u0, dv)
    return float(np.sign(area) * np.dot(F, dv))


#: values of a grid integrand evaluated at once (bounds the memory of a fine rule)
_GRID_BLOCK = 1 << 17


def _full_panels(grid, nodes, weights, n_full, v):
    """``sum of weights[j] grid(nodes[j], v[i]) for j < n_full[i]`` for every i: the whole
    panels of :func:`domain_integral`, on the grid of the nodes and the distinct ``v``
    (in blocks of v values)."""
    out = np.zeros(v.shape)
    todo = np.nonzero(n_full > 0)[0]
    if not todo.size:
        return out
    vs, inv = np.unique(v[todo], return_inverse=True)
    top = int(n_full.max())
    step = max(1, _GRID_BLOCK // top)
    for start in range(0, vs.size, step):
        block = vs[start:start + step]
        vals = grid(nodes[:top], block) * weights[:top, None]
        cum = np.concatenate([np.zeros((1, block.size)), np.cumsum(vals, axis=0)])
        sel = (inv >= start) & (inv < start + block.size)
        out[todo[sel]] = cum[n_full[todo[sel]], inv[sel] - start]
    return out


def _breaks(lo, hi, panels, knots):
    """``panels`` equal panels from lo to hi, also broken at the knots between them."""
    knots = np.asarray(knots, dtype=float)
    inner = knots[(knots > lo) & (knots < hi)]
    out = np.unique(np.concatenate([np.linspace(lo, hi, panels + 1), inner]))
    # panels shorter than 1e-9 of the span add nothing but rounding
    keep = np.concatenate([[True], np.diff(out) > 1e-9 * (hi - lo)])
    return out[keep]


def _composite(breaks, x, w):
    """Nodes and weights of the Gauss rule ``(x, w)`` on every panel between ``breaks``."""
    half = 0.5 * np.diff(breaks)
    mid = breaks[:-1] + half
    return (mid[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()


def knots_of(*surfaces):
    """The distinct knots in u and in v of ``surfaces`` (for ``domain_integral``)."""
    return (np.unique(np.concatenate([s.knots_u for s in surfaces])),
            np.unique(np.concatenate([s.knots_v for s in surfaces])))


def correction_integral(nominal, corrected, outward, polylines):
    """Integral of the correction over the trimmed face (mm^3; positive = material removed):
    the volume of the layer between the nominal and the corrected face (over a face bounded
    by its surface's whole domain, :func:`whole_domain`, by :func:`tensor_integral`, else by
    :func:`domain_integral`).

    The correction at ``(u, v)`` is ``delta = n . (S - S_c)`` with the outward unit normal
    ``n`` (``S_c = S - delta n``, docs/method.md). The layer swept along the normals
    has the volume ``integral of (delta - H delta^2 + K delta^3 / 3) dA`` (``H``, ``K`` the
    mean and Gaussian curvature, ``H > 0`` where the face is convex outwards; the parallel
    surface at depth ``s`` has the area element ``(1 - 2 H s + K s^2) dA``), which is
    ``integral of delta dA`` on a flat face and differs from it by ``H delta`` (3 % for
    14 um on a 0.4 mm fillet) on a tightly curved one.

    Parameters
    ----------
    nominal, corrected : Surface
        Same parametrisation.
    outward : {1, -1}
    polylines : list of (n, 2) arrays
        The face's boundary in (u, v), oriented (:func:`domain_integral`).
    """

    def func(u, v):
        return _layer(bspline.derivatives(nominal, u, v, order=2),
                      bspline.evaluate(corrected, u, v), outward)

    def grid(us, vs):
        return _layer(bspline.evaluate_grid(nominal, us, vs, order=2),
                      bspline.evaluate_grid(corrected, us, vs), outward)

    # panels at both surfaces' knots (each holds one polynomial piece of the correction) and
    # 16 more; a correction with very many knots gets the nominal's knots and 64 panels. A
    # face bounded by its whole domain (the example's) takes the tensor rule: 1e-11 of the
    # integral from 1000 panels, and faster than Green's rule along 400 boundary points
    # (6e-8; docs/benchmarks.md, "Costs behind choices in the code")
    knots = knots_of(nominal, corrected)
    if max(len(k) for k in knots) > MAX_KNOTS:
        knots, panels = knots_of(nominal), 64
    else:
        panels = _PANELS
    if whole_domain(polylines, nominal.u_range, nominal.v_range):
        return tensor_integral(grid, nominal.u_range, nominal.v_range, knots, panels)
    return domain_integral(func, polylines, knots=knots, panels=panels, grid=grid)


def whole_domain(pieces, u_range, v_range, tol=1e-9):
    """True when the boundary ``pieces`` enclose the whole rectangle ``u_range x v_range``
    (a face bounded by its surface's whole parameter domain): every point lies on the
    rectangle's border (within ``tol`` of its sides) and the loop's area (shoelace) is the
    rectangle's, so it runs once around it (no holes, nothing cut off)."""
    (u0, u1), (v0, v1) = u_range, v_range
    du, dv = tol * (u1 - u0), tol * (v1 - v0)
    pts = np.concatenate([np.asarray(p, dtype=float) for p in pieces])
    u, v = pts[:, 0], pts[:, 1]
    border = (np.abs(u - u0) <= du) | (np.abs(u - u1) <= du) | \
        (np.abs(v - v0) <= dv) | (np.abs(v - v1) <= dv)
    within = (u >= u0 - du) & (u <= u1 + du) & (v >= v0 - dv) & (v <= v1 + dv)
    if not (border.all() and within.all()):
        return False
    area = sum(0.5 * float(np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]))
               for p in (np.asarray(q, dtype=float) for q in pieces))
    return abs(abs(area) - (u1 - u0) * (v1 - v0)) <= 1e-6 * (u1 - u0) * (v1 - v0)


def tensor_integral(grid, u_range, v_range, knots, panels=_PANELS):
    """Integral of a function over the whole rectangle ``u_range x v_range``: the composite
    Gauss-Legendre rule of :func:`domain_integral` (panels broken at the ``knots``, plus
    ``panels`` equal ones) in u and in v, on the tensor grid of its nodes (``grid(us, vs)``,
    evaluated in blocks of u). Exact where :func:`domain_integral` is in u, and so in v
    (it takes the midpoint rule along the boundary there): for a rectangle it is the same
    rule in u, more exact in v, on fewer points."""
    x, w = np.polynomial.legendre.leggauss(_GAUSS)
    su, wu = _composite(_breaks(*u_range, panels, knots[0]), x, w)
    sv, wv = _composite(_breaks(*v_range, panels, knots[1]), x, w)
    step = max(1, _GRID_BLOCK // sv.size)
    return float(sum(wu[k:k + step] @ grid(su[k:k + step], sv) @ wv
                     for k in range(0, su.size, step)))


def _dot(a, b):
    return np.einsum("...j,...j->...", a, b)


def _layer(nominal, points, outward):
    """The layer's volume density of :func:`correction_integral` per du dv, from the
    nominal's derivatives ``(S, Su, Sv, Suu, Suv, Svv)`` and the corrected surface's
    ``points`` at the same parameters (arrays of any shape (..., 3))."""
    s, su, sv, suu, suv, svv = nominal
    cross = outward * np.cross(su, sv)
    jac = np.linalg.norm(cross, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):   # poles: jac = 0
        n = cross / jac[..., None]
        e, f, g = _dot(su, su), _dot(su, sv), _dot(sv, sv)
        ll, m, nn = _dot(suu, n), _dot(suv, n), _dot(svv, n)
        det = e * g - f * f
        mean = -(e * nn - 2 * f * m + g * ll) / (2 * det)
        gauss = (ll * nn - m * m) / det
    delta = _dot(s - points, n)
    layer = delta - mean * delta ** 2 + gauss * delta ** 3 / 3.0
    return np.where(jac > 0, layer * jac, 0.0)


def area_samples(surface, bounds, polylines=None, n=60):
    """Points on the face and the area each stands for: the midpoints of an ``n`` x ``n``
    grid of its parameter ``bounds`` ``(u0, u1, v0, v1)`` on ``surface``, those inside the
    boundary ``polylines`` (all of them without)."""
    u0, u1, v0, v1 = bounds
    us, vs = (np.linspace(u0, u1, n + 1)[:-1] + 0.5 * (u1 - u0) / n,
              np.linspace(v0, v1, n + 1)[:-1] + 0.5 * (v1 - v0) / n)
    U, V = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    if polylines is not None:
        ok = inside(polylines, U, V)
        U, V = U[ok], V[ok]
    S, Su, Sv = bspline.derivatives(surface, U, V, order=1)
    return S, np.linalg.norm(np.cross(Su, Sv), axis=1) * (u1 - u0) * (v1 - v0) / n / n


#: ends of boundary pieces closer than this share of the boundary's extent are one vertex
SNAP = 1e-9


def snap_ends(polylines, share=SNAP):
    """Copies of ``polylines`` whose ends that meet (within ``share`` of the boundary's
    extent) are the very same point: the crossing rule of :func:`inside` counts a shared
    vertex once only when both pieces hold it exactly, and an edge's pcurve ends where the
    next begins only to rounding (a closed circle's seam 1e-13 apart counted a ray along
    the seam's v twice, and points on the face there as outside)."""
    lines = [np.array(p, dtype=float) for p in polylines]
    ends = np.array([p[k] for p in lines for k in (0, -1)])
    if not len(ends):
        return lines
    tol = share * max(float(np.ptp(np.concatenate(lines), axis=0).max()), 1e-300)
    for i in range(len(ends)):
        near = np.flatnonzero(np.abs(ends[:i] - ends[i]).max(axis=1) <= tol)
        if near.size:
            ends[i] = ends[near[0]]
    for j, p in enumerate(lines):
        p[0], p[-1] = ends[2 * j], ends[2 * j + 1]
    return lines


def inside(polylines, u, v, buckets=256):
    """Which points ``(u, v)`` lie inside the region bounded by ``polylines`` (even-odd
    rule, so neither order nor direction of the pieces matters): a bool array of the
    points' shape.

    Segments are sorted into ``buckets`` bands of v, so each point is tested against the
    few segments of its band only (a ray towards +u counts their crossings).
    """
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    polylines = snap_ends(polylines)
    segs = np.concatenate([np.stack([p[:-1], p[1:]], axis=1) for p in polylines])
    lo = np.minimum(segs[:, 0, 1], segs[:, 1, 1])
    hi = np.maximum(segs[:, 0, 1], segs[:, 1, 1])
    v0, v1 = lo.min(), hi.max()
    out = np.zeros(u.shape, dtype=bool)
    if not v1 > v0:
        return out
    width = (v1 - v0) / buckets
    band = np.floor((v.ravel() - v0) / width).astype(int)
    flat = out.ravel()
    uf, vf = u.ravel(), v.ravel()
    # the points of each band: one sort instead of a pass over all points per band
    order = np.argsort(band, kind="stable")
    starts = np.searchsorted(band[order], np.arange(buckets + 1))
    for k in range(buckets):
        pts = order[starts[k]:starts[k + 1]]
        if not pts.size:
            continue
        sel = segs[(hi >= v0 + k * width) & (lo <= v0 + (k + 1) * width)]
        a, b = sel[:, 0], sel[:, 1]
        vv = vf[pts, None]
        hit = (a[None, :, 1] <= vv) != (b[None, :, 1] <= vv)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (vv - a[None, :, 1]) / (b[None, :, 1] - a[None, :, 1])
            x = a[None, :, 0] + t * (b[None, :, 0] - a[None, :, 0])
        crossings = np.sum(hit & (x > uf[pts, None]), axis=1)
        flat[pts] = crossings % 2 == 1
    return flat.reshape(u.shape)
