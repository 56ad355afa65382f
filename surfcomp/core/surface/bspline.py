# SPDX-License-Identifier: LGPL-2.1-or-later
"""B-spline surfaces as plain numpy arrays (no FreeCAD).

The app layer converts ``Part.BSplineSurface`` to and from :class:`Surface`
(``surfcomp.app.convert``). Everything numeric on surfaces (evaluation,
derivatives, normals, projection) works on this type. This module evaluates;
:mod:`surfcomp.core.surface.bspline_basis` holds the basis functions and
:mod:`surfcomp.core.surface.bspline_fit` the fits and knot refinement, both re-exported
here (``bspline.basis_matrix``, ``bspline.fit_grid_lsq``).
"""

from dataclasses import dataclass, field

import numpy as np

from ...errors import GeometryError
from ..chunks import for_chunks
from .bspline_basis import basis_functions, basis_matrix, find_spans, greville
from .bspline_fit import fit_grid_lsq, interpolate_grid, refine_knots
from .bspline_nd import point_evaluator

__all__ = ["Surface", "CHUNK_VALUES", "evaluate", "derivatives", "normals", "evaluate_grid",
           "insert_knots", "find_spans", "basis_functions", "basis_matrix", "greville",
           "refine_knots", "interpolate_grid", "fit_grid_lsq"]


@dataclass(frozen=True)
class Surface:
    """A non-periodic (clamped or unclamped) tensor-product B-spline surface.

    Attributes
    ----------
    poles : ndarray, shape (nu, nv, 3)
        Control points in mm, first index along u.
    knots_u, knots_v : ndarray, shape (nu + degree_u + 1,), (nv + degree_v + 1,)
        Flat (expanded) knot vectors, non-decreasing.
    degree_u, degree_v : int
    weights : ndarray, shape (nu, nv), or None
        Rational weights (all > 0); None for a polynomial surface.
    u_range, v_range : tuple of float
        The face's parameter bounds (the work area); defaults to the knot domain
        ``(knots[degree], knots[-degree-1])``.
    """

    poles: np.ndarray
    knots_u: np.ndarray
    knots_v: np.ndarray
    degree_u: int
    degree_v: int
    weights: np.ndarray = None
    u_range: tuple = field(default=None)
    v_range: tuple = field(default=None)

    def __post_init__(self):
        poles = np.asarray(self.poles, dtype=float)
        ku = np.asarray(self.knots_u, dtype=float)
        kv = np.asarray(self.knots_v, dtype=float)
        object.__setattr__(self, "poles", poles)
        object.__setattr__(self, "knots_u", ku)
        object.__setattr__(self, "knots_v", kv)
        if poles.ndim != 3 or poles.shape[2] != 3:
            raise ValueError("poles must have shape (nu, nv, 3), got %r" % (poles.shape,))
        nu, nv = poles.shape[:2]
        if ku.size != nu + self.degree_u + 1 or kv.size != nv + self.degree_v + 1:
            raise ValueError("knot vector lengths do not match poles and degrees")
        if self.weights is not None:
            w = np.asarray(self.weights, dtype=float)
            if w.shape != (nu, nv) or np.any(w <= 0):
                raise ValueError("weights must be positive with shape (nu, nv)")
            object.__setattr__(self, "weights", w)
        if self.u_range is None:
            object.__setattr__(self, "u_range",
                               (float(ku[self.degree_u]), float(ku[-self.degree_u - 1])))
        if self.v_range is None:
            object.__setattr__(self, "v_range",
                               (float(kv[self.degree_v]), float(kv[-self.degree_v - 1])))

    @property
    def rational(self):
        """True when the surface has non-uniform weights."""
        return self.weights is not None and not np.allclose(self.weights, self.weights.flat[0])

    @property
    def shape(self):
        """(nu, nv): the number of poles along u and v."""
        return self.poles.shape[:2]

    def with_range(self, u_range, v_range):
        """Return a copy whose work area is ``u_range`` x ``v_range``."""
        return Surface(self.poles, self.knots_u, self.knots_v, self.degree_u, self.degree_v,
                       self.weights, tuple(map(float, u_range)), tuple(map(float, v_range)))


# ---------------------------------------------------------------------------
# Evaluation, derivatives, normals, grid evaluation, knot insertion. The basis
# functions are in bspline_basis, interpolation and least squares in bspline_fit.
# References: Piegl & Tiller, "The NURBS Book", 2nd ed. (A3.5, A4.4, eq. 4.20).
# ---------------------------------------------------------------------------

#: points per inner chunk: keeps temporaries of a bicubic rational surface
#: around 50 MB whatever the number of points
CHUNK_VALUES = 4_000_000


def clamped(surf):
    """True when each end knot of ``surf`` is repeated ``degree + 1`` times (the border
    pole rows are then the border curves)."""
    return not any(np.ptp(k[:d + 1]) or np.ptp(k[-d - 1:])
                   for k, d in ((surf.knots_u, surf.degree_u), (surf.knots_v, surf.degree_v)))


def compress_knots(flat):
    """Distinct knots and their multiplicities of a flat knot vector (knots within 1e-15
    relative are one)."""
    knots, mults = [], []
    for k in flat:
        if knots and abs(k - knots[-1]) <= 1e-15 * max(1.0, abs(k)):
            mults[-1] += 1
        else:
            knots.append(float(k))
            mults.append(1)
    return knots, mults


def _chunk_size(degree_u, degree_v, extra=1):
    return max(1024, CHUNK_VALUES // ((degree_u + 1) * (degree_v + 1) * 4 * max(1, extra)))


def _homogeneous(surf):
    """Poles as (nu, nv, 4) homogeneous points ``(w x, w y, w z, w)``."""
    if surf.weights is None:
        return np.concatenate([surf.poles, np.ones(surf.poles.shape[:2] + (1,))], axis=2)
    w = surf.weights[:, :, None]
    return np.concatenate([surf.poles * w, w], axis=2)


def _rational_quotient(A, order):
    """Derivatives of S = A[:3] / A[3] from homogeneous ones (NURBS book eq. 4.20, A4.4).

    ``A[(k, l)]`` has shape (n, 4); returns a dict of (n, 3) arrays.
    """
    w = A[(0, 0)][:, 3:4]
    out = {(0, 0): A[(0, 0)][:, :3] / w}
    if order >= 1:
        wu, wv = A[(1, 0)][:, 3:4], A[(0, 1)][:, 3:4]
        out[(1, 0)] = (A[(1, 0)][:, :3] - wu * out[(0, 0)]) / w
        out[(0, 1)] = (A[(0, 1)][:, :3] - wv * out[(0, 0)]) / w
    if order >= 2:
        S, Su, Sv = out[(0, 0)], out[(1, 0)], out[(0, 1)]
        out[(2, 0)] = (A[(2, 0)][:, :3] - 2.0 * wu * Su - A[(2, 0)][:, 3:4] * S) / w
        out[(1, 1)] = (A[(1, 1)][:, :3] - wu * Sv - wv * Su - A[(1, 1)][:, 3:4] * S) / w
        out[(0, 2)] = (A[(0, 2)][:, :3] - 2.0 * wv * Sv - A[(0, 2)][:, 3:4] * S) / w
    return out


_ORDER_KEYS = {0: [(0, 0)], 1: [(0, 0), (1, 0), (0, 1)],
               2: [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]}


def _ders_chunk(surf, Pw, u, v, order):
    """Derivatives up to ``order`` (0..2) at flat parameter arrays of one chunk."""
    pu, pv = surf.degree_u, surf.degree_v
    Nu, su = basis_functions(surf.knots_u, pu, u, order)
    Nv, sv = basis_functions(surf.knots_v, pv, v, order)
    iu = su[:, None] - pu + np.arange(pu + 1)
    iv = sv[:, None] - pv + np.arange(pv + 1)
    n = u.size
    nv, dim = Pw.shape[1], Pw.shape[2]
    # the (pu+1)(pv+1) poles of every point, gathered by flat index (several times faster
    # than indexing the (nu, nv) net with two index arrays)
    flat = (iu[:, :, None] * nv + iv[:, None, :]).reshape(n, -1)
    G = np.take(Pw.reshape(-1, dim), flat, axis=0)             # (n, (pu+1)(pv+1), dim)
    # one contraction per derivative with the outer product of the two bases, as a
    # stack of (1 x k) (k x dim) products
    A = {(k, kv): np.matmul((Nu[k][:, :, None] * Nv[kv][:, None, :]).reshape(n, 1, -1),
                            G)[:, 0, :]
         for (k, kv) in _ORDER_KEYS[order]}
    if surf.weights is None:
        return {key: val[:, :3] for key, val in A.items()}
    return _rational_quotient(A, order)


def _all_ders(surf, u, v, order):
    """Chunked derivatives; returns a list of arrays (..., 3) in _ORDER_KEYS order."""
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    if u.shape != v.shape:
        raise ValueError("u and v must have the same shape, got %r and %r" % (u.shape, v.shape))
    shape = u.shape
    uf, vf = u.ravel(), v.ravel()
    keys = _ORDER_KEYS[order]
    out = [np.empty((uf.size, 3)) for _ in keys]
    Pw = _homogeneous(surf) if surf.weights is not None else surf.poles
    compiled = point_evaluator(surf, Pw, uf.size) if order == 0 and uf.size else None
    def job(sl):
        if compiled is not None:     # scipy's NdBSpline where it has one (bspline_nd.py)
            out[0][sl] = compiled(np.stack([uf[sl], vf[sl]], axis=1))
            return
        res = _ders_chunk(surf, Pw, uf[sl], vf[sl], order)
        for arr, key in zip(out, keys):
            arr[sl] = res[key]

    for_chunks(job, uf.size, _chunk_size(surf.degree_u, surf.degree_v, order + 1))
    return [arr.reshape(shape + (3,)) for arr in out]


def evaluate(surf, u, v):
    """Points of the surface.

    Parameters
    ----------
    surf : Surface
    u, v : array_like, same shape (...)
        Parameters (outside the knot domain: polynomial extrapolation).

    Returns
    -------
    ndarray, shape (..., 3)
        Points in mm.
    """
    return _all_ders(surf, u, v, 0)[0]


def derivatives(surf, u, v, order=1):
    """Surface point and partial derivatives (rational: NURBS book A4.4 quotient rule).

    Parameters
    ----------
    surf : Surface
    u, v : array_like, same shape (...)
    order : {0, 1, 2}

    Returns
    -------
    tuple of ndarray, each shape (..., 3)
        order 0: ``(S,)``; order 1: ``(S, Su, Sv)``; order 2:
        ``(S, Su, Sv, Suu, Suv, Svv)``. Units mm per parameter unit^k.
    """
    if order not in _ORDER_KEYS:
        raise ValueError("order must be 0, 1 or 2, got %r" % (order,))
    return tuple(_all_ders(surf, u, v, order))


def _derivative_scales(surf):
    """Typical |Su|, |Sv| (mm per parameter unit) from the pole extent."""
    ext = float(np.ptp(surf.poles.reshape(-1, 3), axis=0).max()) or 1.0
    du = (surf.u_range[1] - surf.u_range[0]) or 1.0
    dv = (surf.v_range[1] - surf.v_range[0]) or 1.0
    return ext / abs(du), ext / abs(dv)


def _degenerate(n, Su, Sv, scale_u, scale_v, rel=1e-10):
    nn = np.linalg.norm(n, axis=-1)
    prod = np.linalg.norm(Su, axis=-1) * np.linalg.norm(Sv, axis=-1)
    return (nn <= rel * scale_u * scale_v) | (nn <= rel * prod)


def normals(surf, u, v):
    """Unit normals ``Su x Sv / |Su x Sv|``.

    Degenerate points (collapsed edges such as a sphere's pole, or parallel
    Su and Sv) take the limit of the normals of points a small parameter step
    towards the middle of the work area: normals at steps h, 2h and 4h
    (h = 1e-5, else 1e-3 of the range) extrapolated to h = 0 (Richardson,
    error O(h^3)).
    The result is never NaN.

    Parameters
    ----------
    surf : Surface
    u, v : array_like, same shape (...)

    Returns
    -------
    ndarray, shape (..., 3)
        Unit vectors.

    Raises
    ------
    GeometryError
        When even the largest step lands on a degenerate point.
    """
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    _, Su, Sv = derivatives(surf, u, v, 1)
    return unit_normals(surf, u, v, Su, Sv)


def unit_normals(surf, u, v, Su, Sv):
    """The unit normals of :func:`normals` from derivatives already evaluated at
    ``(u, v)`` (``Su``, ``Sv`` shape (..., 3))."""
    n = np.cross(Su, Sv)
    su, sv = _derivative_scales(surf)
    bad = _degenerate(n, Su, Sv, su, sv)
    if np.any(bad):
        um, vm = 0.5 * sum(surf.u_range), 0.5 * sum(surf.v_range)
        lu = abs(surf.u_range[1] - surf.u_range[0])
        lv = abs(surf.v_range[1] - surf.v_range[0])
        ub, vb = u[bad], v[bad]
        du = lu * np.where(ub <= um, 1.0, -1.0)
        dv = lv * np.where(vb <= vm, 1.0, -1.0)
        fixed = np.zeros(ub.shape + (3,))
        todo = np.ones(ub.shape, dtype=bool)
        for h in (1e-5, 1e-3):
            # unit normals 1, 2 and 4 steps inside, Richardson-extrapolated to
            # the step 0: n(0) = (8 n(h) - 6 n(2h) + n(4h)) / 3 + O(h^3)
            ns, ok = [], todo.copy()
            for f in (1.0, 2.0, 4.0):
                _, Su2, Sv2 = derivatives(surf, ub + f * h * du, vb + f * h * dv, 1)
                n2 = np.cross(Su2, Sv2)
                ok &= ~_degenerate(n2, Su2, Sv2, su, sv)
                ns.append(n2 / np.maximum(np.linalg.norm(n2, axis=-1, keepdims=True), 1e-300))
            fixed[ok] = ((8.0 * ns[0] - 6.0 * ns[1] + ns[2]) / 3.0)[ok]
            todo &= ~ok
            if not np.any(todo):
                break
        if np.any(todo):
            raise GeometryError("surface normal undefined near (u, v) = (%g, %g): the face is "
                                "degenerate there" % (ub[todo][0], vb[todo][0]))
        n = n.copy()
        n[bad] = fixed
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def grid_unit_normals(Su, Sv, outward=1):
    """Unit normals ``outward * Su x Sv / |Su x Sv|`` of grid derivatives (..., 3), NaN where
    the surface degenerates (a sphere's pole: ``Su x Sv`` zero or rounding noise, at most
    1e-9 of the grid's largest)."""
    n = np.cross(Su, Sv)
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    degenerate = length <= 1e-9 * max(float(np.max(length, initial=0.0)), 1e-300)
    with np.errstate(divide="ignore", invalid="ignore"):
        return n * (outward / np.where(degenerate, np.nan, length))


def evaluate_grid(surf, us, vs, order=0):
    """Tensor-product evaluation on the grid ``us x vs`` with sparse basis matrices.

    Parameters
    ----------
    surf : Surface
    us : array_like, shape (Mu,)
    vs : array_like, shape (Mv,)
    order : {0, 1, 2}

    Returns
    -------
    ndarray, shape (Mu, Mv, 3), or tuple of them
        order 0: points; order 1: ``(S, Su, Sv)``; order 2:
        ``(S, Su, Sv, Suu, Suv, Svv)``, ``S[i, j] = S(us[i], vs[j])``.
    """
    if order not in _ORDER_KEYS:
        raise ValueError("order must be 0, 1 or 2, got %r" % (order,))
    us = np.asarray(us, dtype=float).ravel()
    vs = np.asarray(vs, dtype=float).ravel()
    nu, nv = surf.shape
    Pw = _homogeneous(surf) if surf.weights is not None else surf.poles
    dim = Pw.shape[2]
    Bu = [basis_matrix(surf.knots_u, surf.degree_u, nu, us, k) for k in range(order + 1)]
    Bv = [basis_matrix(surf.knots_v, surf.degree_v, nv, vs, k) for k in range(order + 1)]
    if us.size * (nv + vs.size) < vs.size * nu:
        # few rows (a block of a check grid): contract along u first, (nu, nv*dim) ->
        # (Mu, nv, dim), then along v; the intermediate has Mu rows, not all nu (two
        # transposed copies, so only where they cost less than the nu x Mv intermediate)
        flat = Pw.reshape(nu, nv * dim)
        Tu = [np.ascontiguousarray((Bu[k] @ flat).reshape(us.size, nv, dim).transpose(1, 0, 2))
              .reshape(nv, us.size * dim) for k in range(order + 1)]
        A = {(k, kv): np.ascontiguousarray((Bv[kv] @ Tu[k]).reshape(vs.size, us.size, dim)
                                           .transpose(1, 0, 2)).reshape(-1, dim)
             for (k, kv) in _ORDER_KEYS[order]}
    else:
        # first contract along v: (nv, nu*dim) -> (Mv, nu, dim)
        flat = np.ascontiguousarray(Pw.transpose(1, 0, 2)).reshape(nv, nu * dim)
        Tv = [(Bv[kv] @ flat).reshape(vs.size, nu, dim).transpose(1, 0, 2)
              .reshape(nu, vs.size * dim) for kv in range(order + 1)]
        A = {(k, kv): (Bu[k] @ Tv[kv]).reshape(us.size * vs.size, dim)
             for (k, kv) in _ORDER_KEYS[order]}
    if surf.weights is None:
        res = {key: val for key, val in A.items()}
    else:
        res = _rational_quotient(A, order)
    out = [res[key].reshape(us.size, vs.size, 3) for key in _ORDER_KEYS[order]]
    return out[0] if order == 0 else tuple(out)


def insert_knots(surf, new_u=(), new_v=()):
    """Return the same surface with more knots (Boehm knot insertion).

    Parameters
    ----------
    surf : Surface
    new_u, new_v : array_like
        Knots to insert along u and v (see :func:`refine_knots`).

    Returns
    -------
    Surface
        Same geometry, degrees, work area and (for rational surfaces) the same
        rational function; more poles.
    """
    Pw = _homogeneous(surf)
    ku, Pw = refine_knots(surf.knots_u, surf.degree_u, Pw, new_u, axis=0)
    kv, Pw = refine_knots(surf.knots_v, surf.degree_v, Pw, new_v, axis=1)
    w = Pw[:, :, 3]
    poles = Pw[:, :, :3] / w[:, :, None]
    return Surface(poles, ku, kv, surf.degree_u, surf.degree_v,
                   None if surf.weights is None else w, surf.u_range, surf.v_range)
