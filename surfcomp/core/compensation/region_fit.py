# SPDX-License-Identifier: LGPL-2.1-or-later
"""Least-squares poles of a corrected region face whose boundary curves are fitted on their
own (issue 30; numpy/scipy only).

Two faces sharing an edge meet along it only as closely as each face's fit follows the
displacement there. A plain tensor-product least-squares fit
(:func:`surfcomp.core.surface.bspline.fit_grid_lsq`) spreads its error over the whole face;
along a boundary it trades the boundary's accuracy for the rows of samples inside, where
the displacement turns towards a sharp edge's vector within a band a few pole rows wide: on
the BladeX blade's sides (42 spanwise poles within the 4x pole budget) the edges with the
caps then open by 0.3 to 4 um.

Here each direction's fit keeps the first and last poles on the first and last samples
(clamped knots: the surface's boundary passes through its boundary poles) and fits the
others by least squares with those held. Done in u and then in v, the boundary curve
``S(u, v_end)`` is the least-squares fit of the boundary samples alone, in the face's own
u knots, which are fine along the edge; the same holds for ``u_end``. A shared edge lying
on the boundaries of both faces (a blade's, a cap's) then takes each face's accuracy along
the edge, not across it. Edges inside a face's trim gain nothing and lose nothing.
"""

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from ...errors import GridError
from ..surface.bspline import basis_matrix


def _end_held(B, what):
    """``solve(R)``: poles (n, k) for samples R (M, k) with the first and last poles equal
    to the first and last samples and the others least squares (B: (M, n), clamped)."""
    B = sp.csr_matrix(B)
    n = B.shape[1]
    ends = B[[0, -1]][:, [0, n - 1]].toarray()
    if n < 3 or not np.allclose(ends, np.eye(2), atol=1e-12):
        raise GridError("the %s samples do not start and end on a clamped knot vector's ends "
                        "(%d poles)" % (what, n))
    inner = B[:, 1:n - 1].tocsc()
    innerT = inner.T.tocsr()
    M = (innerT @ inner).tocsc()
    if np.any(np.asarray(abs(M).sum(axis=0)).ravel() <= 1e-12):
        raise GridError("no %s samples in the support of a basis function: add samples "
                        "or use fewer knots" % what)
    lu = splu(M)
    first, last = B[:, [0]], B[:, [n - 1]]

    def solve(R):
        P = np.empty((n, R.shape[1]))
        P[0], P[-1] = R[0], R[-1]
        P[1:-1] = lu.solve(innerT @ (R - first @ R[:1] - last @ R[-1:]))
        return P

    return solve


def fit_ends_held(us, vs, points, knots_u, knots_v, degree_u, degree_v, weights=None):
    """Poles (nu, nv, 3) fitting ``points`` (Mu, Mv, 3) at ``(us[i], vs[j])`` by least
    squares in each direction with the boundary poles held on the boundary samples (module
    docstring). ``us`` and ``vs`` must start and end on the knot vectors' ends. ``weights``
    (nu, nv): fixed rational weights (the homogeneous points are fitted, as
    :func:`~surfcomp.core.surface.bspline.fit_grid_lsq` does)."""
    us, vs = np.asarray(us, dtype=float), np.asarray(vs, dtype=float)
    X = np.asarray(points, dtype=float)
    ku, kv = np.asarray(knots_u, dtype=float), np.asarray(knots_v, dtype=float)
    nu, nv = ku.size - degree_u - 1, kv.size - degree_v - 1
    Bu, Bv = basis_matrix(ku, degree_u, nu, us), basis_matrix(kv, degree_v, nv, vs)
    if weights is not None:
        W = Bu @ (Bv @ np.asarray(weights, dtype=float).T).T
        X = X * W[:, :, None]
    su, sv = _end_held(Bu, "u"), _end_held(Bv, "v")
    Mu, Mv = X.shape[:2]
    Y = su(X.reshape(Mu, Mv * 3)).reshape(nu, Mv, 3)
    Z = sv(np.ascontiguousarray(Y.transpose(1, 0, 2)).reshape(Mv, nu * 3))
    Q = np.ascontiguousarray(Z.reshape(nv, nu, 3).transpose(1, 0, 2))
    if weights is None:
        return Q
    return Q / np.asarray(weights, dtype=float)[:, :, None]
