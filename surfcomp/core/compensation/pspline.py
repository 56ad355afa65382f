# SPDX-License-Identifier: LGPL-2.1-or-later
"""Penalised cubic tensor B-spline smoothing of scattered values ("P-spline", no FreeCAD).

The large-N branch of :func:`surfcomp.core.compensation.scattered_fit.smooth`: minimise
``||d - B c||^2 + rho c^T J c`` over a cubic tensor-product B-spline space on a
uniform knot grid of at most :data:`PSPLINE_MAX_COEFFS` coefficients, with ``J`` the
exact thin-plate energy ``int (f_xx^2 + 2 f_xy^2 + f_yy^2)`` of the spline over its
knot box (Eilers & Marx 1996 for the P-spline idea; Wahba 1990, ch. 2 for the energy).

Cost linear in the number of points N, memory linear in N in chunks:

* **Normal equations from moments.** On a knot span each cubic basis function is a
  cubic polynomial in the local coordinate ``s`` in [0, 1), so the 16 x 16 block of
  ``G = B^T B`` of one knot cell is a fixed bilinear form of the cell's moments
  ``sum s^k t^l`` (k, l <= 6), and ``B^T d`` one of ``sum d s^k t^l`` (k, l <= 3):
  one pass of weighted bincounts over the points, no N-row matrix product. The fitted
  values come from the per-cell bicubic polynomials of the fitted spline.
* **One decomposition for every smoothing value** (Demmler-Reinsch): with
  ``M = G + tau J`` (tau tiny, M positive definite) the generalised eigenproblem
  ``J V = M V diag(s)``, ``V^T M V = I`` is solved once on the coefficient grid
  (K x K, K <= 1100, whatever N is); then for every ``rho`` the coefficients are
  ``c = V diag(1 / (1 + (rho - tau) s)) V^T B^T d``, and the residual sum of squares
  and the trace of the hat matrix for generalized cross-validation cost O(K).
* **Leave-one-out** residuals ``e_k = r_k / (1 - H_kk)`` (exact for a linear
  smoother), ``H_kk = b_k^T V diag(f) V^T b_k``, at a seeded random subsample of
  :data:`LOO_SAMPLE` points.
"""

import math

import numpy as np
from scipy import linalg as sla
from scipy import sparse

from ..surface import bspline
from .spline_field import CellSpline, powers, uniform_locate

#: largest number of tensor B-spline coefficients of the large-N smoothing fit
PSPLINE_MAX_COEFFS = 1100
#: leave-one-out residuals of the large-N fit are evaluated at this many points
LOO_SAMPLE = 20000
#: points per pass of the moment and evaluation loops (bounds the temporaries)
CHUNK = 1 << 17
#: highest power of a local coordinate in the moments of G (product of two cubics)
_POW = 7


def gauss_gram(knots, degree, n_poles, order):
    """Gram matrices ``int B_i^(r) B_j^(r)`` for r = 0..order over the knot domain
    (Gauss-Legendre, exact for the piecewise polynomials)."""
    xg, wg = np.polynomial.legendre.leggauss(degree + 1)
    brk = np.unique(knots[degree:n_poles + 1])
    a, b = brk[:-1, None], brk[1:, None]
    t = ((a + b) / 2 + (b - a) / 2 * xg).ravel()
    w = ((b - a) / 2 * wg).ravel()
    out = []
    for r in range(order + 1):
        B = bspline.basis_matrix(knots, degree, n_poles, t, deriv=r).toarray()
        out.append(B.T @ (B * w[:, None]))
    return out


def tensor_rows(ku, kv, nu, nv, x):
    """Sparse tensor-product cubic basis rows at points x (N, 2): shape (N, nu * nv)."""
    bu, su = bspline.basis_functions(ku, 3, x[:, 0])
    bv, sv = bspline.basis_functions(kv, 3, x[:, 1])
    n = x.shape[0]
    iu = su[:, None] - 3 + np.arange(4)
    iv = sv[:, None] - 3 + np.arange(4)
    cols = (iu[:, :, None] * nv + iv[:, None, :]).reshape(n, 16)
    vals = (bu[0][:, :, None] * bv[0][:, None, :]).reshape(n, 16)
    return sparse.csr_matrix((vals.ravel(), cols.ravel(), np.arange(0, 16 * n + 1, 16)),
                             shape=(n, nu * nv))


def span_polynomials(knots, spans):
    """Power-basis coefficients ``C[i, k, a]`` of the cubic basis functions on each span:
    on span i (knots[3 + i] .. knots[4 + i]) basis function ``i + a`` (a = 0..3) is
    ``sum_k C[i, k, a] s^k`` with ``s`` the local coordinate in [0, 1] (Taylor
    coefficients at the span start, exact for the cubic pieces)."""
    start = knots[3:3 + spans]
    h = knots[4:4 + spans] - start
    ders, _ = bspline.basis_functions(knots, 3, start, nderiv=3)     # (4, spans, 4)
    fac = np.array([h ** k / math.factorial(k) for k in range(4)])  # (4, spans)
    return np.transpose(ders * fac[:, :, None], (1, 0, 2))


class PSplineSolver:
    """The P-spline fit of values ``d`` at points ``x`` (N, 2) in the box ``lo``..``hi``,
    decomposed once for all smoothing parameters (see the module docstring).

    ``gcv(rho)`` is the GCV score ``N RSS / tr(I - H)^2``; ``solve(rho)`` returns the
    residuals ``d - f`` (N,), the leave-one-out residuals at the sample and ``tr(H)``.
    """

    def __init__(self, x, d, lo, hi):
        n = x.shape[0]
        ext = hi - lo
        # spans per direction: about N/4 coefficients, at most PSPLINE_MAX_COEFFS, aspect kept
        total = min(PSPLINE_MAX_COEFFS, max(16, n // 4))
        ratio = ext[0] / ext[1]
        nsu = int(np.clip(np.sqrt(total * ratio) - 3, 2, 200))
        nsv = int(np.clip(total / (nsu + 3) - 3, 2, 200))
        self.ku = np.r_[[lo[0]] * 3, np.linspace(lo[0], hi[0], nsu + 1), [hi[0]] * 3]
        self.kv = np.r_[[lo[1]] * 3, np.linspace(lo[1], hi[1], nsv + 1), [hi[1]] * 3]
        self.nsu, self.nsv = nsu, nsv
        self.nu, self.nv = nsu + 3, nsv + 3
        self.cu = span_polynomials(self.ku, nsu)
        self.cv = span_polynomials(self.kv, nsv)
        G, h = self._normal_equations(x, d)
        S0u, S1u, S2u = gauss_gram(self.ku, 3, self.nu, 2)
        S0v, S1v, S2v = gauss_gram(self.kv, 3, self.nv, 2)
        J = np.kron(S2u, S0v) + 2 * np.kron(S1u, S1v) + np.kron(S0u, S2v)
        self.tau = 1e-9 * np.trace(G) / np.trace(J)
        s, V = sla.eigh(J, G + self.tau * J)
        self.s = np.maximum(s, 0.0)
        self.V = V
        self.y = V.T @ h
        self.dd = float(d @ d)
        self.x, self.d, self.n, self.J = x, d, n, J

    # ------------------------------------------------------------------ assembly
    def _cells(self, x):
        iu, s = uniform_locate(self.ku[3], self.ku[3 + self.nsu], self.nsu, x[:, 0])
        iv, t = uniform_locate(self.kv[3], self.kv[3 + self.nsv], self.nsv, x[:, 1])
        return iu, iv, s, t

    def _normal_equations(self, x, d):
        """``G = B^T B`` (K x K, dense) and ``h = B^T d`` (K,) from per-cell moments."""
        nsu, nsv = self.nsu, self.nsv
        cells = nsu * nsv
        mom = np.zeros((_POW, _POW, cells))
        momd = np.zeros((4, 4, cells))
        for a in range(0, x.shape[0], CHUNK):
            iu, iv, s, t = self._cells(x[a:a + CHUNK])
            cell = iu * nsv + iv
            sp, tp = powers(s, _POW), powers(t, _POW)
            dc = d[a:a + CHUNK]
            for k in range(_POW):
                for m in range(_POW):
                    mom[k, m] += np.bincount(cell, sp[k] * tp[m], cells)
                    if k < 4 and m < 4:
                        momd[k, m] += np.bincount(cell, dc * sp[k] * tp[m], cells)
        mom = mom.reshape(_POW, _POW, nsu, nsv)
        momd = momd.reshape(4, 4, nsu, nsv)
        # products of two cubics on a span: uu[i, a, c, k] = sum_{p+q=k} C[i,p,a] C[i,q,c]
        uu, vv = self._square(self.cu), self._square(self.cv)
        blocks = np.einsum("iack,jbel,klij->ijabce", uu, vv, mom, optimize=True)
        hb = np.einsum("ika,jlb,klij->ijab", self.cu, self.cv, momd, optimize=True)
        rows = self._block_index()
        K = self.nu * self.nv
        G = np.bincount((rows[:, :, None] * K + rows[:, None, :]).ravel(),
                        blocks.reshape(-1), K * K).reshape(K, K)
        h = np.bincount(rows.ravel(), hb.reshape(-1), K)
        return G, h

    @staticmethod
    def _square(c):
        spans = c.shape[0]
        out = np.zeros((spans, 4, 4, _POW))
        for p in range(4):
            for q in range(4):
                out[:, :, :, p + q] += c[:, p, :, None] * c[:, q, None, :]
        return out

    def _block_index(self):
        """Coefficient numbers (cells, 16) of the 4 x 4 basis functions of every cell,
        ``(i + a) * nv + (j + b)`` in (a, b) order."""
        i = np.arange(self.nsu)[:, None, None, None]
        j = np.arange(self.nsv)[None, :, None, None]
        a = np.arange(4)[None, None, :, None]
        b = np.arange(4)[None, None, None, :]
        return ((i + a) * self.nv + (j + b)).reshape(self.nsu * self.nsv, 16)

    # ------------------------------------------------------------------ smoothing values
    def _f(self, rho):
        return 1.0 / (1.0 + (rho - self.tau) * self.s)

    def gcv(self, rho):
        """GCV score ``N RSS / (N - tr H)^2`` (Craven & Wahba 1979) at ``rho``."""
        f = self._f(rho)
        y2 = self.y ** 2
        rss = max(self.dd - 2 * np.sum(y2 * f) + np.sum(y2 * (1 - self.tau * self.s) * f * f), 0.0)
        tr = self.n - np.sum((1 - self.tau * self.s) * f)
        return self.n * rss / tr ** 2

    def coefficients(self, rho):
        """Spline coefficients (nu * nv,) of the fit at ``rho``."""
        return self.V @ (self._f(rho) * self.y)

    def spline(self, c):
        """The fitted spline with coefficients ``c`` (:class:`CellSpline`)."""
        return CellSpline(self.cu, self.cv, c.reshape(self.nu, self.nv),
                          (self.ku[3], self.kv[3]), (self.ku[3 + self.nsu], self.kv[3 + self.nsv]))

    def values(self, c, x):
        """The spline with coefficients ``c`` at points x (M, 2)."""
        return self.spline(c).values(x)

    def solve(self, rho, rng_seed=0):
        """Residuals ``d - f`` (N,), leave-one-out residuals at the sample, ``tr(H)``."""
        f = self._f(rho)
        resid = self.d - self.values(self.coefficients(rho), self.x)
        dof = float(np.sum((1 - self.tau * self.s) * f))
        if self.n > LOO_SAMPLE:
            idx = np.sort(np.random.default_rng(rng_seed).choice(self.n, LOO_SAMPLE, replace=False))
        else:
            idx = np.arange(self.n)
        # H_kk = w_k^T Z w_k with Z = V diag(f) V^T = (B^T B + rho J)^-1 and w_k the 16
        # basis values of point k: the 16 x 16 block of Z of the point's cell
        iu, iv, su, tv = self._cells(self.x[idx])
        rows = self._block_index()[iu * self.nsv + iv]                 # (m, 16)
        Z = (self.V * f) @ self.V.T
        bu = np.einsum("mk,mka->ma", powers(su, 4).T, self.cu[iu])
        bv = np.einsum("mk,mkb->mb", powers(tv, 4).T, self.cv[iv])
        w = (bu[:, :, None] * bv[:, None, :]).reshape(-1, 16)
        Hkk = np.einsum("ma,mab,mb->m", w, Z[rows[:, :, None], rows[:, None, :]], w)
        loo = resid[idx] / np.maximum(1.0 - Hkk, 1e-12)
        return resid, loo, dof
