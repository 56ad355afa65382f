# SPDX-License-Identifier: LGPL-2.1-or-later
"""The P-spline smoothing fit (surfcomp.core.compensation.pspline) against dense reference solves of
the same penalised least-squares problem, and its GCV choice against the former
implementation (sparse N-row product B^T B), whose results are recorded below."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.compensation.pspline import PSplineSolver, tensor_rows
from surfcomp.core.compensation.scattered import smooth


def field_data(n, seed, box):
    """Seeded points in a box (mm) with a smooth systematic field and 3 um noise."""
    rng = np.random.default_rng(seed)
    x = rng.random((n, 2)) * box
    truth = 0.02 * np.sin(x[:, 0] / 12) * np.cos(x[:, 1] / 9) + 0.0003 * x[:, 0]
    return x, truth + rng.normal(0, 0.003, n)


def dense_reference(solver, x, d, rho):
    """The same problem solved densely: ``c = (B^T B + rho J)^-1 B^T d`` with the
    collocation matrix B of all points; the hat matrix ``H = B (B^T B + rho J)^-1 B^T``."""
    B = tensor_rows(solver.ku, solver.kv, solver.nu, solver.nv, x).toarray()
    A = B.T @ B + rho * solver.J
    c = np.linalg.solve(A, B.T @ d)
    H = B @ np.linalg.solve(A, B.T)
    return B, c, H


@pytest.mark.parametrize("n,box", [(600, (30.0, 10.0)), (2400, (45.0, 45.0))])
def test_normal_equations_from_moments_equal_the_collocation_product(n, box):
    x, d = field_data(n, 21, box)
    solver = PSplineSolver(x, d, x.min(axis=0), x.max(axis=0))
    B = tensor_rows(solver.ku, solver.kv, solver.nu, solver.nv, x)
    G, h = solver._normal_equations(x, d)
    ref = (B.T @ B).toarray()
    assert_allclose(G, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert_allclose(h, B.T @ d, rtol=0, atol=1e-12 * np.abs(B.T @ d).max())


@pytest.mark.parametrize("n,box", [(600, (30.0, 10.0)), (2400, (45.0, 45.0))])
@pytest.mark.parametrize("rho", [1e-3, 0.3, 30.0])
def test_solver_equals_a_dense_reference_solve(n, box, rho):
    x, d = field_data(n, 22, box)
    solver = PSplineSolver(x, d, x.min(axis=0), x.max(axis=0))
    B, c, H = dense_reference(solver, x, d, rho)
    scale = np.abs(d).max()
    resid, loo, dof = solver.solve(rho)
    assert_allclose(solver.coefficients(rho), c, rtol=0, atol=1e-9 * np.abs(c).max())
    assert_allclose(resid, d - B @ c, rtol=0, atol=1e-9 * scale)
    assert_allclose(dof, np.trace(H), rtol=1e-9)
    r = d - H @ d
    assert_allclose(loo, r / (1 - np.diag(H)), rtol=0, atol=1e-9 * scale)
    rss, tr = r @ r, n - np.trace(H)
    assert_allclose(solver.gcv(rho), n * rss / tr ** 2, rtol=1e-9)


#: the former solver (dense B^T B from the sparse N-row product, the same
#: Demmler-Reinsch decomposition) on field_data(n, seed, box): GCV's smoothing length
#: (mm), leave-one-out RMS (mm) and degrees of freedom
FORMER = [
    (1200, 11, (80.0, 40.0), 16.505821338445173, 0.003094581852178998, 61.08508528248221),
    (6000, 12, (100.0, 20.0), 12.408889736339365, 0.0030133292022505973, 77.88764088395571),
    (25000, 13, (45.0, 45.0), 10.583176103448654, 0.0030181172841359924, 99.94444997977575),
]


@pytest.mark.parametrize("n,seed,box,ell,loo_rms,dof", FORMER)
def test_gcv_choice_equals_the_former_solver(n, seed, box, ell, loo_rms, dof):
    """Same smoothing length, leave-one-out RMS and degrees of freedom. The new normal
    equations differ from the former ones by rounding only (1e-12 relative, above);
    the GCV search resolves log10(ell) to 1e-4 (2.3e-4 relative), so 1e-6 relative
    bounds a drift that would still be far inside the search's own resolution
    (measured: 1.3e-10, 1.7e-10, 8.9e-11)."""
    x, d = field_data(n, seed, box)
    fit = smooth(x[:, 0], x[:, 1], d, method="pspline")
    assert fit.method == "pspline" and fit.chosen_by == "gcv"
    assert_allclose(fit.smoothing, ell, rtol=1e-6)
    assert_allclose(fit.loo_rms, loo_rms, rtol=1e-9)
    assert_allclose(fit.dof, dof, rtol=1e-8)
    assert fit.loo_points == min(n, 20000)
