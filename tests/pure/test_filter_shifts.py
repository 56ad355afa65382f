# SPDX-License-Identifier: LGPL-2.1-or-later
"""The mask filter's shifted sums (masks up to SHIFTED_MAX) give scipy.ndimage.correlate's
numbers to the last bit, for every edge mode, on grids smaller than the mask too; larger
masks go to ndimage itself."""

import numpy as np
import pytest
from scipy import ndimage

from surfcomp.core.compensation import filters

MODES = {"renormalize": "constant", "reflect": "mirror", "nearest": "nearest"}


@pytest.mark.parametrize("edge", sorted(MODES))
@pytest.mark.parametrize("size", [1, 3, 5, 7, 9, 11])
def test_shifted_sums_equal_ndimage(edge, size):
    rng = np.random.default_rng(size * 7 + len(edge))
    for shape in [(1, 1), (1, 6), (2, 2), (3, 5), (4, 9), (45, 45), (30, 17)]:
        mask = rng.uniform(-0.2, 1.0, (size, size))
        values = rng.normal(size=shape)
        want = ndimage.correlate(values, mask, mode=MODES[edge], cval=0.0)
        got = filters.correlate(values, mask, edge)
        assert got.shape == want.shape
        assert np.array_equal(got, want), (shape, np.max(np.abs(got - want)))


def test_a_larger_mask_goes_to_ndimage(monkeypatch):
    calls = []
    real = ndimage.correlate
    monkeypatch.setattr(ndimage, "correlate", lambda *a, **k: calls.append(a[1].shape)
                        or real(*a, **k))
    values = np.random.default_rng(3).normal(size=(20, 20))
    small = filters.correlate(values, np.ones((11, 11)), "reflect")
    big = filters.correlate(values, np.ones((13, 13)), "reflect")
    assert calls == [(13, 13)]
    # a box of 11 x 11 reflected at the borders: the corner's window is known by hand
    assert small[0, 0] == pytest.approx(np.pad(values, 5, mode="reflect")[:11, :11].sum(),
                                        rel=1e-12)
    assert big.shape == values.shape


def test_the_grid_route_does_not_import_ndimage():
    import subprocess
    import sys

    from tests.conftest import ROOT

    code = ("import sys, numpy as np; from surfcomp.core.compensation import filters; "
            "print(filters.mask_filter(np.arange(49.).reshape(7, 7), np.ones((5, 5)))[3, 3], "
            "'scipy.ndimage' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["24.0", "False"]
