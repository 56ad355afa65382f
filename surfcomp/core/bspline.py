"""B-spline surfaces as plain numpy arrays (no FreeCAD).

The app layer converts ``Part.BSplineSurface`` to and from :class:`Surface`
(``surfcomp.app.convert``). Everything numeric on surfaces (evaluation,
derivatives, normals, projection) works on this type.
"""

from dataclasses import dataclass, field

import numpy as np


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
# Numeric engine: spans, basis functions, evaluation, derivatives, normals,
# grid evaluation, knot insertion, interpolation and least-squares fitting.
# References: Piegl & Tiller, "The NURBS Book", 2nd ed. (algorithms A2.1-A2.3,
# A4.4, A5.1, eq. 9.4-9.9); de Boor, "A Practical Guide to Splines" (Greville).
# ---------------------------------------------------------------------------

import scipy.sparse as _sp  # noqa: E402  (kept below the public type on purpose)
import scipy.sparse.linalg as _spla  # noqa: E402

from ..errors import ComputationError, GeometryError, GridError  # noqa: E402

#: points per inner chunk: keeps temporaries of a bicubic rational surface
#: around 50 MB whatever the number of points
CHUNK_VALUES = 4_000_000


def _chunk_size(degree_u, degree_v, extra=1):
    return max(1024, CHUNK_VALUES // ((degree_u + 1) * (degree_v + 1) * 4 * max(1, extra)))


def find_spans(knots, degree, n_poles, t):
    """Knot span indices of parameters (NURBS book A2.1, vectorised).

    Parameters
    ----------
    knots : array_like, shape (n_poles + degree + 1,)
        Flat knot vector.
    degree : int
    n_poles : int
    t : array_like, any shape
        Parameters. Values outside ``[knots[degree], knots[n_poles]]`` get the
        first or last span (polynomial extrapolation).

    Returns
    -------
    ndarray of int, shape of ``t``
        ``span`` with ``knots[span] <= t < knots[span + 1]`` and
        ``degree <= span <= n_poles - 1``; ``t`` at the domain end maps to the
        last non-empty span.
    """
    knots = np.asarray(knots, dtype=float)
    t = np.asarray(t, dtype=float)
    span = np.searchsorted(knots, t, side="right") - 1
    # last non-empty span: the one ending at knots[n_poles]
    last = int(np.searchsorted(knots, knots[n_poles], side="left")) - 1
    last = max(degree, min(last, n_poles - 1))
    span = np.where(t >= knots[n_poles], last, span)
    return np.clip(span, degree, last).astype(np.intp)


def basis_functions(knots, degree, t, nderiv=0):
    """Non-zero B-spline basis functions and their derivatives (NURBS book A2.2/A2.3).

    Vectorised over ``t``: the triangular recurrences loop over the degree
    only.

    Parameters
    ----------
    knots : array_like, shape (n_poles + degree + 1,)
        Flat knot vector.
    degree : int
    t : array_like, shape (N,) (or any shape; flattened)
        Parameters.
    nderiv : int
        Highest derivative order; derivatives above ``degree`` are zero.

    Returns
    -------
    ders : ndarray, shape (nderiv + 1, N, degree + 1)
        ``ders[k, i, j]`` is the k-th derivative of basis function
        ``spans[i] - degree + j`` at ``t[i]``.
    spans : ndarray of int, shape (N,)
        See :func:`find_spans`.
    """
    knots = np.asarray(knots, dtype=float)
    t = np.asarray(t, dtype=float).ravel()
    p = int(degree)
    n_poles = knots.size - p - 1
    span = find_spans(knots, p, n_poles, t)
    n = t.size
    ders = np.zeros((nderiv + 1, n, p + 1))
    left = [None] + [t - knots[span + 1 - j] for j in range(1, p + 1)]
    right = [None] + [knots[span + j] - t for j in range(1, p + 1)]
    # ndu[j][r]: upper triangle basis functions, lower triangle knot differences
    ndu = [[None] * (p + 1) for _ in range(p + 1)]
    ndu[0][0] = np.ones(n)
    for j in range(1, p + 1):
        saved = np.zeros(n)
        for r in range(j):
            ndu[j][r] = right[r + 1] + left[j - r]
            temp = ndu[r][j - 1] / ndu[j][r]
            ndu[r][j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j][j] = saved
    for j in range(p + 1):
        ders[0, :, j] = ndu[j][p]
    nd = min(nderiv, p)
    for r in range(p + 1):
        a = [[None] * (nd + 1) for _ in range(2)]
        s1, s2 = 0, 1
        a[0][0] = np.ones(n)
        for k in range(1, nd + 1):
            d = np.zeros(n)
            rk, pk = r - k, p - k
            if r >= k:
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk]
                d = a[s2][0] * ndu[rk][pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j]
                d = d + a[s2][j] * ndu[rk + j][pk]
            if r <= pk:
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r]
                d = d + a[s2][k] * ndu[r][pk]
            ders[k, :, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, nd + 1):
        ders[k] *= factor
        factor *= p - k
    return ders, span


def basis_matrix(knots, degree, n_poles, t, deriv=0):
    """Sparse collocation matrix of the B-spline basis (or a derivative of it).

    Parameters
    ----------
    knots : array_like, shape (n_poles + degree + 1,)
    degree, n_poles : int
    t : array_like, shape (M,)
        Parameters.
    deriv : int
        Derivative order of the basis functions.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (M, n_poles)
        ``B[i, j] = N_j^(deriv)(t[i])``; at most ``degree + 1`` non-zeros a row.
    """
    t = np.asarray(t, dtype=float).ravel()
    knots = np.asarray(knots, dtype=float)
    if knots.size != n_poles + degree + 1:
        raise ValueError("knot vector length %d does not match n_poles + degree + 1 = %d"
                         % (knots.size, n_poles + degree + 1))
    ders, span = basis_functions(knots, degree, t, deriv)
    cols = (span[:, None] - degree + np.arange(degree + 1)).ravel()
    indptr = np.arange(0, t.size * (degree + 1) + 1, degree + 1)
    return _sp.csr_matrix((ders[deriv].ravel(), cols, indptr), shape=(t.size, n_poles))


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
    n, k_u, k_v = u.size, pu + 1, pv + 1
    G = Pw[iu[:, :, None], iv[:, None, :]].reshape(n, k_u * k_v, -1)  # (n, (pu+1)(pv+1), dim)
    # one contraction per derivative with the outer product of the two bases (faster
    # than two chained einsums over these short axes)
    A = {(k, kv): np.einsum("nk,nkc->nc",
                            (Nu[k][:, :, None] * Nv[kv][:, None, :]).reshape(n, -1), G)
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
    step = _chunk_size(surf.degree_u, surf.degree_v, order + 1)
    for start in range(0, uf.size, step):
        sl = slice(start, start + step)
        res = _ders_chunk(surf, Pw, uf[sl], vf[sl], order)
        for arr, key in zip(out, keys):
            arr[sl] = res[key]
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
    return _unit_normals(surf, u, v, Su, Sv)


def _unit_normals(surf, u, v, Su, Sv):
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
    # first contract along v: (nv, nu*dim) -> (Mv, nu, dim)
    flat = np.ascontiguousarray(Pw.transpose(1, 0, 2)).reshape(nv, nu * dim)
    Tv = [(Bv[kv] @ flat).reshape(vs.size, nu, dim).transpose(1, 0, 2).reshape(nu, vs.size * dim)
          for kv in range(order + 1)]
    A = {(k, kv): (Bu[k] @ Tv[kv]).reshape(us.size * vs.size, dim)
         for (k, kv) in _ORDER_KEYS[order]}
    if surf.weights is None:
        res = {key: val for key, val in A.items()}
    else:
        res = _rational_quotient(A, order)
    out = [res[key].reshape(us.size, vs.size, 3) for key in _ORDER_KEYS[order]]
    return out[0] if order == 0 else tuple(out)


def greville(knots, degree):
    """Greville abscissae ``(t[i+1] + ... + t[i+degree]) / degree``.

    Parameters
    ----------
    knots : array_like, shape (n_poles + degree + 1,)
    degree : int

    Returns
    -------
    ndarray, shape (n_poles,)
        Non-decreasing; for ``degree == 0`` the span midpoints.
    """
    knots = np.asarray(knots, dtype=float)
    n = knots.size - degree - 1
    if degree == 0:
        return 0.5 * (knots[:-1] + knots[1:])
    c = np.concatenate([[0.0], np.cumsum(knots)])
    i = np.arange(n)
    return (c[i + degree + 1] - c[i + 1]) / degree


def refine_knots(knots, degree, ctrl, new_knots, axis=0):
    """Insert knots into a spline without changing it (same result as Boehm, NURBS book A5.1).

    Parameters
    ----------
    knots : array_like, shape (n + degree + 1,)
    degree : int
    ctrl : array_like, shape (..., n, ...)
        Control values along ``axis`` (use homogeneous coordinates for a
        rational spline).
    new_knots : array_like, shape (K,)
        Knots to insert (any order, repeats allowed); each must lie strictly
        inside the domain ``(knots[degree], knots[n])`` and the resulting
        multiplicity may not exceed ``degree``.
    axis : int

    Returns
    -------
    knots : ndarray, shape (n + K + degree + 1,)
    ctrl : ndarray, shape of ``ctrl`` with n + K along ``axis``
    """
    knots = np.asarray(knots, dtype=float)
    p = int(degree)
    Q = np.moveaxis(np.asarray(ctrl, dtype=float), axis, 0)
    lo, hi = knots[p], knots[knots.size - p - 1]
    add = np.sort(np.asarray(new_knots, dtype=float).ravel())
    if add.size == 0:
        return knots.copy(), np.moveaxis(Q, 0, axis)
    bad = np.nonzero(~((add > lo) & (add < hi)))[0]
    if bad.size:
        raise ValueError("knot %g lies outside the open domain (%g, %g)" % (add[bad[0]], lo, hi))
    merged = np.sort(np.concatenate([knots, add]))
    values, counts = np.unique(merged[p + 1:merged.size - p - 1], return_counts=True)
    if counts.size and counts.max() > p:
        raise ValueError("knot %g would get multiplicity above the degree %d"
                         % (values[np.argmax(counts)], p))
    # The refined space contains the spline, so interpolating the spline's own values at
    # the refined space's Greville abscissae gives the refined coefficients exactly (up to
    # rounding; the collocation matrix is banded and well conditioned). One banded solve
    # for all knots instead of one Boehm step (and one copy of the net) per knot.
    n_old, n_new = Q.shape[0], merged.size - p - 1
    g = greville(merged, p)
    values_at_g = basis_matrix(knots, p, n_old, g) @ Q.reshape(n_old, -1)
    solve = _factor(basis_matrix(merged, p, n_new, g), "knot refinement matrix")
    R = solve(values_at_g).reshape((n_new,) + Q.shape[1:])
    return merged, np.moveaxis(R, 0, axis)


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


def _grid_inputs(us, vs, points, knots_u, knots_v, degree_u, degree_v):
    us = np.asarray(us, dtype=float).ravel()
    vs = np.asarray(vs, dtype=float).ravel()
    X = np.asarray(points, dtype=float)
    if X.shape != (us.size, vs.size, 3):
        raise GridError("points must have shape (len(us), len(vs), 3) = (%d, %d, 3), got %r"
                        % (us.size, vs.size, X.shape))
    if not np.all(np.isfinite(X)):
        raise GridError("grid points contain NaN or infinite values; a fit needs every grid node")
    ku = np.asarray(knots_u, dtype=float)
    kv = np.asarray(knots_v, dtype=float)
    nu, nv = ku.size - degree_u - 1, kv.size - degree_v - 1
    Bu = basis_matrix(ku, degree_u, nu, us)
    Bv = basis_matrix(kv, degree_v, nv, vs)
    return us, vs, X, Bu, Bv, nu, nv


def _homogeneous_target(X, Bu, Bv, weights):
    """``W(u, v) * X`` with W the denominator of the rational spline on the grid."""
    if weights is None:
        return X
    W = Bu @ (Bv @ np.asarray(weights, dtype=float).T).T
    return X * W[:, :, None]


def _kron_solve(solve_u, solve_v, X, nu, nv):
    """Apply ``solve_u`` along the first and ``solve_v`` along the second grid axis."""
    Mu, Mv = X.shape[:2]
    Y = solve_u(X.reshape(Mu, Mv * 3)).reshape(nu, Mv, 3)
    Z = solve_v(np.ascontiguousarray(Y.transpose(1, 0, 2)).reshape(Mv, nu * 3))
    return np.ascontiguousarray(Z.reshape(nv, nu, 3).transpose(1, 0, 2))


def _factor(M, what):
    try:
        lu = _spla.splu(_sp.csc_matrix(M))
    except RuntimeError as exc:
        raise GridError("the %s is singular (%s): the sample parameters do not fit the knot "
                        "vector (Schoenberg-Whitney condition: every basis function needs "
                        "samples inside its support)" % (what, exc)) from exc
    return lu.solve


def _finish(Q, weights):
    if not np.all(np.isfinite(Q)):
        raise ComputationError("spline fit produced non-finite poles (ill-conditioned system)")
    if weights is None:
        return Q
    return Q / np.asarray(weights, dtype=float)[:, :, None]


def interpolate_grid(us, vs, points, knots_u, knots_v, degree_u, degree_v, weights=None):
    """Poles of the surface that interpolates a grid of points (NURBS book eq. 9.4-9.9).

    The tensor-product system ``(Bu kron Bv) vec(P) = vec(X)`` is solved as two
    sparse LU solves, first along u, then along v.

    Parameters
    ----------
    us : array_like, shape (nu,)
    vs : array_like, shape (nv,)
        Grid parameters (e.g. :func:`greville` of the knots).
    points : array_like, shape (nu, nv, 3)
        Points in mm to interpolate, ``points[i, j]`` at ``(us[i], vs[j])``.
    knots_u, knots_v : array_like
        Flat knot vectors with ``nu + degree_u + 1`` and ``nv + degree_v + 1`` knots.
    degree_u, degree_v : int
    weights : array_like, shape (nu, nv), optional
        Fixed rational weights: the homogeneous system ``sum N N (w P) = W X``
        is solved, so a rational nominal sampled and refitted with its own
        weights comes back exactly.

    Returns
    -------
    ndarray, shape (nu, nv, 3)
        Poles in mm.

    Raises
    ------
    GridError
        Wrong shapes, NaN points, or parameters that make the system singular.
    """
    us, vs, X, Bu, Bv, nu, nv = _grid_inputs(us, vs, points, knots_u, knots_v,
                                             degree_u, degree_v)
    if us.size != nu or vs.size != nv:
        raise GridError("interpolation needs as many grid parameters as poles: got %d x %d "
                        "parameters for %d x %d poles (use fit_grid_lsq for more samples)"
                        % (us.size, vs.size, nu, nv))
    X = _homogeneous_target(X, Bu, Bv, weights)
    Q = _kron_solve(_factor(Bu, "u collocation matrix"), _factor(Bv, "v collocation matrix"),
                    X, nu, nv)
    return _finish(Q, weights)


def fit_grid_lsq(us, vs, points, knots_u, knots_v, degree_u, degree_v, weights=None):
    """Least-squares poles for a grid with at least as many samples as poles.

    Minimises ``sum_ij |S(us[i], vs[j]) - X[i, j]|^2`` (for rational weights the
    homogeneous residual ``W (S - X)``). Because the pseudo-inverse of a
    Kronecker product is the Kronecker product of the pseudo-inverses, the
    fit is two banded normal-equation solves (NURBS book eq. 9.66-9.67 per
    direction).

    Parameters
    ----------
    us : array_like, shape (Mu,), Mu >= nu
    vs : array_like, shape (Mv,), Mv >= nv
    points : array_like, shape (Mu, Mv, 3)
        Points in mm.
    knots_u, knots_v : array_like
        Flat knot vectors of the result.
    degree_u, degree_v : int
    weights : array_like, shape (nu, nv), optional
        Fixed rational weights (see :func:`interpolate_grid`).

    Returns
    -------
    ndarray, shape (nu, nv, 3)
        Poles in mm.

    Raises
    ------
    GridError
        Wrong shapes, NaN points, or a basis function without samples in its
        support (singular normal equations).
    """
    us, vs, X, Bu, Bv, nu, nv = _grid_inputs(us, vs, points, knots_u, knots_v,
                                             degree_u, degree_v)
    if us.size < nu or vs.size < nv:
        raise GridError("least-squares fit needs at least as many samples as poles: got "
                        "%d x %d samples for %d x %d poles" % (us.size, vs.size, nu, nv))
    for B, name in ((Bu, "u"), (Bv, "v")):
        empty = np.flatnonzero(np.asarray(abs(B).sum(axis=0)).ravel() <= 1e-12)
        if empty.size:
            raise GridError("no %s samples in the support of basis function(s) %s: add samples "
                            "or use fewer knots" % (name, empty[:5].tolist()))
    X = _homogeneous_target(X, Bu, Bv, weights)
    BuT, BvT = Bu.T.tocsr(), Bv.T.tocsr()
    su = _factor(BuT @ Bu, "u normal matrix")
    sv = _factor(BvT @ Bv, "v normal matrix")
    Q = _kron_solve(lambda R: su(BuT @ R), lambda R: sv(BvT @ R), X, nu, nv)
    return _finish(Q, weights)
