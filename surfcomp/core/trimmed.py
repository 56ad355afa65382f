"""Integrals over a trimmed face: the parameter domain bounded by the face's wires.

Pure numpy (no FreeCAD): the app layer gives the boundary as closed polygons in (u, v)
(:func:`surfcomp.app.shapes.boundary_polylines`).
"""

import numpy as np

from . import bspline

#: panels of the composite Gauss-Legendre rule across the domain in u and in v (besides
#: the knots), and Gauss points per panel (exact for the polynomial pieces of the
#: integrands below between knots, up to degree 9)
_LINES = 16
_GAUSS = 3


def domain_integral(func, polylines, lines=_LINES, box=None, knots=None):
    """Integral of ``func(u, v)`` over the region bounded by ``polylines`` (even-odd rule:
    holes are subtracted; neither the order nor the direction of the pieces matters).

    Scan lines ``v = const`` at composite Gauss-Legendre nodes in v; on every line the
    intervals inside the polygon (between sorted crossings with the loops' segments) are
    integrated with composite Gauss-Legendre in u.

    Parameters
    ----------
    func : callable
        Vectorised ``func(u, v) -> values`` for (N,) arrays.
    polylines : list of (n, 2) arrays
        Pieces of the boundary in (u, v) (a face's edges); together they form closed
        loops.
    lines : int
        Number of composite panels in v (4 Gauss nodes each).
    box : (u0, u1, v0, v1), optional
        The scan grid's extent (default: the polylines' bounding box); two integrals over
        nearly the same region on the same grid differ by the difference of the regions,
        not by their quadrature errors.
    knots : (array, array), optional
        More panel breaks in u and in v: the knots of the surfaces in ``func``, so that
        every panel holds one polynomial piece.

    Returns
    -------
    float
    """
    segs = np.concatenate([np.stack([np.asarray(p, float)[:-1], np.asarray(p, float)[1:]],
                                    axis=1) for p in polylines])     # (m, 2 ends, 2 coords)
    (u0, v0), (u1, v1) = segs.reshape(-1, 2).min(0), segs.reshape(-1, 2).max(0)
    if box is not None:
        u0, u1, v0, v1 = box
    x, w = np.polynomial.legendre.leggauss(_GAUSS)
    ku, kv = knots if knots is not None else ((), ())
    vs, wv = _composite(_breaks(v0, v1, lines, kv), x, w)
    grid_u = _breaks(u0, u1, lines, ku)
    us, vv, ww = [], [], []
    a, b = segs[:, 0], segs[:, 1]
    for v, weight in zip(vs, wv):
        hit = (a[:, 1] <= v) != (b[:, 1] <= v)
        if not hit.any():
            continue
        t = (v - a[hit, 1]) / (b[hit, 1] - a[hit, 1])
        cross = np.sort(a[hit, 0] + t * (b[hit, 0] - a[hit, 0]))
        for lo, hi in cross.reshape(-1, 2):
            # panels on the fixed grid: integrals over nearly equal regions share them
            inner = grid_u[(grid_u > lo) & (grid_u < hi)]
            nodes, weights = _composite(np.concatenate([[lo], inner, [hi]]), x, w)
            us.append(nodes)
            ww.append(weights * weight)
            vv.append(np.full(nodes.size, v))
    if not us:
        return 0.0
    us, vv, ww = np.concatenate(us), np.concatenate(vv), np.concatenate(ww)
    return float(np.dot(func(us, vv), ww))


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
    """Integral of the correction over the trimmed face (mm^3; positive = material removed).

    The correction at ``(u, v)`` is ``delta = n . (S - S_c)`` with the outward normal ``n``
    (``S_c = S - delta n``, README "The method"), integrated with the area element
    ``|Su x Sv|`` over the region bounded by ``polylines``: the volume between the nominal and the
    corrected face to first order in ``delta``.

    Parameters
    ----------
    nominal, corrected : Surface
        Same parametrisation.
    outward : {1, -1}
    polylines : list of (n, 2) arrays
        The face's boundary in (u, v) (:func:`domain_integral`).
    """

    def func(u, v):
        # delta |Su x Sv| = (S - S_c) . (outward Su x Sv): no division, poles included
        s, su, sv = bspline.derivatives(nominal, u, v, order=1)
        return outward * np.einsum("ij,ij->i", s - bspline.evaluate(corrected, u, v),
                                   np.cross(su, sv))

    return domain_integral(func, polylines, knots=knots_of(nominal, corrected))


def inside(polylines, u, v, buckets=256):
    """Which points ``(u, v)`` lie inside the region bounded by ``polylines`` (even-odd
    rule, as :func:`domain_integral`): a bool array of the points' shape.

    Segments are sorted into ``buckets`` bands of v, so each point is tested against the
    few segments of its band only (a ray towards +u counts their crossings).
    """
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    segs = np.concatenate([np.stack([np.asarray(p, float)[:-1], np.asarray(p, float)[1:]],
                                    axis=1) for p in polylines])
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
    for k in np.unique(band[(band >= 0) & (band < buckets)]):
        pts = np.nonzero(band == k)[0]
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
