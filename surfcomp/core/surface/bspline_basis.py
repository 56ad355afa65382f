# SPDX-License-Identifier: LGPL-2.1-or-later
"""B-spline basis functions on one flat knot vector (no FreeCAD).

Knot spans, the non-zero basis functions and their derivatives, sparse
collocation matrices and Greville abscissae: the one-dimensional layer under
surface evaluation (:mod:`surfcomp.core.surface.bspline`) and fitting
(:mod:`surfcomp.core.surface.bspline_fit`). References: Piegl & Tiller, "The NURBS
Book", 2nd ed. (algorithms A2.1-A2.3); de Boor, "A Practical Guide to Splines"
(Greville abscissae).
"""

import inspect

import numpy as np
import scipy.sparse as _sp

#: from this many parameters on, :func:`basis_matrix` takes scipy's compiled collocation
#: matrix (:func:`scipy_design_matrix`); below, the hand-written one. Importing
#: ``scipy.interpolate`` (it brings ``scipy.optimize``) costs about what the compiled
#: matrix saves on 100 000 parameters (``bench/bench_basis.py``; docs/benchmarks.md,
#: "Costs behind choices in the code"); a measurement grid of a few thousand points would
#: pay the import for a fraction of it.
SCIPY_FROM = 100_000

_DESIGN = []


def scipy_design_matrix():
    """scipy's compiled collocation matrix where the installed scipy has it with
    extrapolation (``BSpline.design_matrix(x, t, k, extrapolate)``, scipy 1.10 and later),
    else None. It gives the values of :func:`basis_functions` (to rounding: equal in
    ``tests/pure/test_basis_scipy.py``) in less time; ``bench/bench_basis.py`` prints the
    ratio. ``scipy.interpolate`` is imported on the first call."""
    if not _DESIGN:
        from scipy.interpolate import BSpline

        design = getattr(BSpline, "design_matrix", None)
        try:
            takes_extrapolate = "extrapolate" in inspect.signature(design).parameters
        except (TypeError, ValueError):
            takes_extrapolate = False
        _DESIGN.append(design if takes_extrapolate else None)
    return _DESIGN[0]


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
    if deriv == 0 and t.size >= SCIPY_FROM and scipy_design_matrix() is not None \
            and np.isfinite(t).all():
        return _scipy_basis_matrix(knots, degree, t)
    return _basis_matrix(knots, degree, n_poles, t, deriv)


def _scipy_basis_matrix(knots, degree, t):
    """:func:`basis_matrix` (``deriv=0``, finite parameters) from scipy's compiled matrix."""
    return _sp.csr_matrix(scipy_design_matrix()(t, knots, int(degree), extrapolate=True))


def _basis_matrix(knots, degree, n_poles, t, deriv=0):
    """:func:`basis_matrix` from :func:`basis_functions` (every derivative order, any
    scipy; non-finite parameters give non-finite rows)."""
    ders, span = basis_functions(knots, degree, t, deriv)
    cols = (span[:, None] - degree + np.arange(degree + 1)).ravel()
    indptr = np.arange(0, t.size * (degree + 1) + 1, degree + 1)
    return _sp.csr_matrix((ders[deriv].ravel(), cols, indptr), shape=(t.size, n_poles))


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

