# SPDX-License-Identifier: LGPL-2.1-or-later
"""basis_matrix through scipy's BSpline.design_matrix (scipy 1.10 and later) gives the
hand-written basis's matrix: the same non-zeros in the same places, the values to 4e-16,
also at the domain's ends, at multiple knots and beyond the domain (extrapolation)."""

import numpy as np
import pytest
import scipy
from numpy.testing import assert_allclose

from surfcomp.core.surface import bspline_basis as bb


def _version():
    return tuple(int(x) for x in scipy.__version__.split(".")[:2])


def test_the_installed_scipy_decides():
    """Debian 12's scipy 1.10 and later have design_matrix with extrapolation: it is used."""
    assert (bb.scipy_design_matrix() is not None) == (_version() >= (1, 10))


@pytest.mark.skipif(bb.scipy_design_matrix() is None, reason="scipy before 1.10")
@pytest.mark.parametrize("degree", [0, 1, 2, 3, 5])
def test_scipy_matrix_equals_the_hand_written_one(degree):
    rng = np.random.default_rng(100 + degree)
    inner = np.sort(rng.uniform(2.0, 7.0, 9))
    inner[4] = inner[3]                       # a double knot
    if degree >= 2:
        inner[6] = inner[7] = inner[5]        # a knot of multiplicity 3
    knots = np.r_[[2.0] * (degree + 1), inner, [7.0] * (degree + 1)]
    n_poles = knots.size - degree - 1
    t = np.r_[rng.uniform(2.0, 7.0, 500), 2.0, 7.0, inner, 1.5, 7.25, np.nextafter(7.0, 0)]
    ours = bb._basis_matrix(knots, degree, n_poles, t)
    got = bb._scipy_basis_matrix(knots, degree, t)
    assert got.shape == ours.shape == (t.size, n_poles)
    assert_allclose(got.toarray(), ours.toarray(), atol=4e-16, rtol=0)
    # partition of unity, also where extrapolated polynomials leave [0, 1]
    assert_allclose(np.asarray(got.sum(axis=1)).ravel(), 1.0, atol=1e-13, rtol=0)


def test_derivatives_and_non_finite_parameters_use_the_hand_written_basis():
    knots = np.r_[0.0, 0, 0, 0.5, 1, 1, 1]
    t = np.array([0.0, 0.25, 0.5, 1.0])
    d1 = bb.basis_matrix(knots, 2, 4, t, deriv=1).toarray()
    assert_allclose(d1, bb._basis_matrix(knots, 2, 4, t, deriv=1).toarray(), atol=0, rtol=0)
    assert_allclose(d1.sum(axis=1), 0.0, atol=1e-14)     # derivative of the unit sum
    # a non-finite parameter: a non-finite row, not an exception
    bad = bb.basis_matrix(knots, 2, 4, np.array([0.3, np.nan])).toarray()
    assert np.isfinite(bad[0]).all() and not np.isfinite(bad[1]).all()


@pytest.mark.skipif(bb.scipy_design_matrix() is None, reason="scipy before 1.10")
def test_scipy_takes_only_the_large_parameter_sets(monkeypatch):
    """Below SCIPY_FROM parameters the hand-written matrix is built (scipy.interpolate's
    import would cost more than it saves); from SCIPY_FROM on, scipy's."""
    calls = []
    real = bb._scipy_basis_matrix
    monkeypatch.setattr(bb, "_scipy_basis_matrix",
                        lambda *a: calls.append(a[2].size) or real(*a))
    knots = np.r_[0.0, 0, 0, 0, np.linspace(0.1, 0.9, 9), 1, 1, 1, 1]
    n_poles = knots.size - 4
    for m in (bb.SCIPY_FROM - 1, bb.SCIPY_FROM):
        t = np.linspace(0.0, 1.0, m)
        got = bb.basis_matrix(knots, 3, n_poles, t)
        assert got.shape == (m, n_poles)
        assert_allclose(np.asarray(got.sum(axis=1)).ravel(), 1.0, atol=1e-13, rtol=0)
    assert calls == [bb.SCIPY_FROM]


def test_the_grid_route_does_not_import_scipy_interpolate():
    """Importing the basis, and building a small matrix, leave scipy.interpolate (and the
    scipy.optimize it imports) unloaded."""
    import subprocess
    import sys

    from tests.conftest import ROOT

    code = ("import sys, numpy as np; from surfcomp.core.surface import bspline_basis as bb; "
            "bb.basis_matrix(np.r_[0., 0, 0, 0, 1, 1, 1, 1], 3, 4, np.linspace(0, 1, 2025)); "
            "print(sorted(m for m in ('scipy.interpolate', 'scipy.optimize') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"
