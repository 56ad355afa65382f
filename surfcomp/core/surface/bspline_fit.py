# SPDX-License-Identifier: LGPL-2.1-or-later
"""Fitting B-spline surfaces and refining knot vectors (no FreeCAD).

Interpolation and least-squares fits of point grids in a given tensor-product
spline space (NURBS book eq. 9.4-9.9, 9.66-9.67) and knot refinement of control
nets by one banded solve (the result of Boehm's insertion, NURBS book A5.1).
"""

import numpy as np
import scipy.sparse as _sp
import scipy.sparse.linalg as _spla
from scipy.linalg import lapack as _lapack

from ...errors import ComputationError, GridError
from .bspline_basis import basis_matrix, greville


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


#: matrices whose nonzeros lie this close to the diagonal are factored as band matrices
#: (LAPACK gbtrf/gbtrs: the many right-hand sides of a pole net in one column-major sweep,
#: faster than SuperLU's solve for pole nets of a million poles)
MAX_BAND = 16


def _singular(what, why):
    return GridError("the %s is singular (%s): the sample parameters do not fit the knot "
                     "vector (Schoenberg-Whitney condition: every basis function needs "
                     "samples inside its support)" % (what, why))


def _factor(M, what):
    """LU of a square sparse matrix; returns ``solve(B)`` for B of shape (n,) or (n, k)."""
    C = _sp.coo_matrix(M)
    n = C.shape[0]
    below = int(max(0, np.max(C.row - C.col, initial=0)))
    above = int(max(0, np.max(C.col - C.row, initial=0)))
    if below + above > MAX_BAND or n < 2:
        try:
            return _spla.splu(_sp.csc_matrix(M)).solve
        except RuntimeError as exc:
            raise _singular(what, exc) from exc
    band = np.zeros((2 * below + above + 1, n))
    np.add.at(band, (below + above + C.row - C.col, C.col), C.data)
    lu, piv, info = _lapack.dgbtrf(band, below, above)
    if info != 0:
        raise _singular(what, "zero pivot in column %d" % info)

    def solve(B):
        B = np.asarray(B, dtype=float)
        X, info = _lapack.dgbtrs(lu, below, above, np.asfortranarray(B.reshape(n, -1)), piv)
        return X.reshape(B.shape)

    return solve


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

    Returns the poles in mm, shape (nu, nv, 3), or raises :class:`GridError` for wrong
    shapes, NaN points, or a basis function without samples in its support (singular
    normal equations).
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
