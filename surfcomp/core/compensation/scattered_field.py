# SPDX-License-Identifier: LGPL-2.1-or-later
"""C1 field through values at scattered points over the face's (u, v) (no FreeCAD).

The scattered counterpart of the grid path's correction field
(:class:`surfcomp.core.compensation.field.GridField`).

:class:`ScatteredField`
    A C1 interpolant through values at the points (interface of
    :class:`~surfcomp.core.compensation.field.GridField` as used by
    :func:`surfcomp.core.compensation.corrected.build_matching_surface`): Clough-Tocher
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

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import LinearOperator, cg
from scipy.spatial import Delaunay, cKDTree

from ...errors import ComputationError, InputError
from ..surface.uvpoints import check_duplicates, check_spread, scaled_points

#: the relative-tolerance keyword of ``cg``: ``tol`` up to scipy 1.11, ``rtol`` from 1.12
#: (``tol`` was removed in 1.14)
_CG_RTOL = "rtol" if "rtol" in inspect.signature(cg).parameters else "tol"

#: ghost frame margin around the points and the face box (fraction of the larger side)
FRAME_MARGIN = 0.25
#: nearest measured nodes averaged into a ghost value
GHOST_NEIGHBOURS = 6
#: relative residual of the conjugate-gradient solve for the node gradients
GRADIENT_RTOL = 1e-13


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
    :func:`surfcomp.core.compensation.corrected.build_matching_surface` uses with
    :class:`~surfcomp.core.compensation.field.GridField`.

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
        x = scaled_points(np.ravel(U), np.ravel(V), scale, "field nodes")
        check_spread(x, "scattered field", 3)
        check_duplicates(x, "scattered field")
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
