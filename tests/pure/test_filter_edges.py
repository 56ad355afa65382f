# SPDX-License-Identifier: LGPL-2.1-or-later
"""The filter's edge modes by what they do at the border: ``reflect`` is numpy.pad's
``reflect`` (the grid mirrored about its border node, which is not repeated; scipy.ndimage
calls it ``mirror``), ``nearest`` repeats the border node."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.compensation.filters import mask_filter


def _padded_filter(d, mask, mode):
    """Eq. 4-5 on a grid completed by numpy.pad: the weighted window sum over the sum of
    the weights (every window full)."""
    r = mask.shape[0] // 2
    p = np.pad(d, r, mode=mode)
    out = np.empty_like(d)
    for i in range(d.shape[0]):
        for j in range(d.shape[1]):
            out[i, j] = np.sum(p[i:i + 2 * r + 1, j:j + 2 * r + 1] * mask) / mask.sum()
    return out


@pytest.mark.parametrize("edge, pad_mode", [("reflect", "reflect"), ("nearest", "edge")])
def test_edge_modes_are_numpys_pad_modes(edge, pad_mode):
    rng = np.random.default_rng(29)
    d = rng.normal(size=(7, 9))
    mask = np.array([[1.0, 2, 1], [2, 4, 2], [1, 2, 1]])
    mask5 = np.outer([1.0, 3, 4, 3, 1], [1.0, 3, 4, 3, 1])
    for m in (mask, mask5):
        assert_allclose(mask_filter(d, m, edge=edge), _padded_filter(d, m, pad_mode),
                        atol=1e-14, rtol=0)


def test_reflect_does_not_repeat_the_border_node():
    """A ramp along the rows: mirrored about the border node, the 3-wide box mean at the
    border is (x1 + x0 + x1) / 3; repeating the border node would give (x0 + x0 + x1) / 3."""
    d = np.tile(np.arange(5.0), (3, 1)).T          # d[i, j] = i
    f = mask_filter(d, np.ones((3, 3)), edge="reflect")
    assert_allclose(f[0], 2.0 / 3.0, atol=1e-15, rtol=0)
    assert_allclose(f[-1], 4 - 2.0 / 3.0, atol=1e-15, rtol=0)
    assert_allclose(mask_filter(d, np.ones((3, 3)), edge="nearest")[0], 1.0 / 3.0, atol=1e-15,
                    rtol=0)
