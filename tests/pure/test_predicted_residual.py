# SPDX-License-Identifier: LGPL-2.1-or-later
"""The predicted residual (core) for each method, against its closed form."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.compensation.methods import compute_correction, predicted_residual


@pytest.fixture
def deviations():
    rng = np.random.default_rng(7)
    u, v = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 11), indexing="ij")
    return 0.03 * np.sin(3 * u) + 0.02 * v + 0.002 * rng.standard_normal(u.shape)


@pytest.mark.parametrize("method, stock", [("filtered", None), ("raw", None),
                                           ("mirror", 0.1), ("offset", None)])
def test_residual_of_each_method(deviations, method, stock):
    d = deviations + (stock or 0.0)
    c = compute_correction(d, method, stock=stock)
    got = predicted_residual(c.determined, c.delta, method, stock)
    expected = {"filtered": np.zeros_like(d), "raw": -c.random, "mirror": -c.random,
                "offset": c.determined - np.mean(d)}[method]
    assert_allclose(got, expected, atol=1e-15)
    assert np.abs(got).max() > 1e-4 or method == "filtered"


def test_stock_counts_for_mirror_only():
    assert_allclose(predicted_residual([0.5], [0.1], "raw", 0.2), [0.4], atol=1e-15)
    assert_allclose(predicted_residual([0.5], [0.1], "mirror", 0.2), [0.2], atol=1e-15)
