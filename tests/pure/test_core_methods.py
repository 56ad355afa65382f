# SPDX-License-Identifier: LGPL-2.1-or-later
"""Deviations, statistics, mask filter and correction methods against the papers' equations."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.compensation.deviations import deviation_components, signed_deviation, statistics
from surfcomp.core.compensation.filters import (
    box_mask,
    gaussian_mask,
    make_mask,
    mask_filter,
    parse_weights,
)
from surfcomp.core.compensation.methods import compute_correction
from surfcomp.errors import InputError


def test_signed_deviation_and_components_werner_eq1():
    n = np.array([[0.0, 0.6, 0.8]])
    nom = np.array([[1.0, 2.0, 3.0]])
    meas = nom + 0.05 * n + np.array([[0.01, 0.0, 0.0]])  # tangential part is ignored
    d = signed_deviation(nom, meas, n)
    assert_allclose(d, [0.05], atol=1e-15)
    # Werner eq. 1: dx = d cos(alpha), dy = d cos(beta), dz = d cos(gamma)
    assert_allclose(deviation_components(d, n), [[0.0, 0.03, 0.04]], atol=1e-15)


def test_statistics_hand_computed():
    d = np.array([-0.03, 0.045, 0.0, 0.015, np.nan])
    st = statistics(d)
    assert st.count == 4
    assert st.max_negative == pytest.approx(-0.03, abs=1e-15)
    assert st.max_positive == pytest.approx(0.045, abs=1e-15)
    assert st.mean == pytest.approx(0.0075, abs=1e-15)
    # sample standard deviation (ddof = 1): sum of squares about the mean / 3
    ss = (0.0375 ** 2 + 0.0375 ** 2 + 0.0075 ** 2 + 0.0075 ** 2)
    assert st.std == pytest.approx(np.sqrt(ss / 3), abs=1e-15)
    assert st.rms == pytest.approx(np.sqrt((0.03 ** 2 + 0.045 ** 2 + 0.015 ** 2) / 4), abs=1e-15)
    assert st.profile == pytest.approx(0.09, abs=1e-15)  # ISO 1101 zone 2 max|d|


def test_box_filter_equals_eq_4_5_inside_the_grid():
    rng = np.random.default_rng(3)
    d = rng.normal(size=(9, 11))
    f = mask_filter(d, box_mask(3))
    i, j = 4, 5  # eq. 4 summed by hand, divided by the weight sum 9 (eq. 5)
    assert f[i, j] == pytest.approx(d[i - 1:i + 2, j - 1:j + 2].sum() / 9, abs=1e-15)
    # corner: only the 2x2 part of the window lies on the grid -> divided by 4
    assert f[0, 0] == pytest.approx(d[:2, :2].sum() / 4, abs=1e-15)


def test_weighted_mask_orientation_and_gaps():
    d = np.arange(25, dtype=float).reshape(5, 5)
    w = parse_weights("0 1 0; 0 0 0; 0 0 0")  # weights the node one row above
    f = mask_filter(d, w, edge="nearest")
    assert_allclose(f[1:, :], d[:-1, :], atol=1e-15)
    assert_allclose(f[0, :], d[0, :], atol=1e-15)
    # renormalised, the first row has no weight on a measured node: refused, naming the node
    with pytest.raises(InputError, match=r"\(row 0, col 0\)"):
        mask_filter(d, w)
    d2 = d.copy()
    d2[2, 2] = np.nan  # a gap: excluded from both sums, result NaN there
    f2 = mask_filter(d2, box_mask(3))
    assert np.isnan(f2[2, 2])
    assert f2[1, 1] == pytest.approx((d[0:3, 0:3].sum() - d[2, 2]) / 8, abs=1e-12)


@pytest.mark.parametrize("mask", [box_mask(5), gaussian_mask(7),
                                  parse_weights("1 2 1; 2 4 2; 1 2 1")])
@pytest.mark.parametrize("edge", ["renormalize", "reflect", "nearest"])
def test_constant_field_passes_unchanged(mask, edge):
    d = np.full((12, 8), 0.0123)
    d[3, 4] = np.nan
    f = mask_filter(d, mask, edge)
    assert_allclose(f[np.isfinite(d)], 0.0123, atol=1e-15)


def test_linear_field_passes_a_symmetric_mask_inside():
    i, j = np.indices((15, 15))
    d = 0.001 * i - 0.002 * j
    f = mask_filter(d, box_mask(5))
    assert_allclose(f[2:-2, 2:-2], d[2:-2, 2:-2], atol=1e-15)


@pytest.mark.parametrize("text,words", [
    ("1 1; 1 1", "odd"),
    ("1 -1 0; 0 0 0; 0 0 0", "sum to zero"),
    ("1 2; 3", "not square"),
    ("1 a 1; 1 1 1; 1 1 1", "not a list of numbers"),
    ("", "empty"),
])
def test_bad_masks_are_refused(text, words):
    with pytest.raises(InputError, match=words):
        parse_weights(text)


def test_even_mask_size_refused():
    with pytest.raises(InputError, match="odd"):
        make_mask(4)


def test_mirror_example_pr_pp_plus_s_plus_e_gives_pc_pp_minus_e():
    # Huang et al.: PR = PP + (s + e) n  ->  PC = PP - e n
    s = 0.2
    e = np.array([[0.012, -0.007], [0.0, 0.031]])
    res = compute_correction(s + e, "mirror", stock=s)
    assert_allclose(res.delta, e, atol=1e-15)
    n = np.array([0.0, 0.0, 1.0])
    pp = np.zeros(3)
    pc = pp - res.delta[..., None] * n
    pr = pp + (s + e)[..., None] * n
    dm = ((pr - (pp + s / 2 * n)) * n).sum(-1)  # eq. 1: PM = PP + DH VN, DH = s / 2
    assert_allclose(pr - 2 * dm[..., None] * n, pc, atol=1e-15)  # eq. 2


def test_methods_raw_offset_filtered():
    rng = np.random.default_rng(5)
    d = rng.normal(0.01, 0.005, size=(10, 10))
    assert_allclose(compute_correction(d, "raw").delta, d, atol=0)
    assert_allclose(compute_correction(d, "offset").delta, d.mean(), atol=1e-15)
    f = compute_correction(d, "filtered", mask=box_mask(3))
    assert_allclose(f.delta, mask_filter(d, box_mask(3)), atol=0)
    assert_allclose(f.random + f.determined, d, atol=1e-15)
    with pytest.raises(InputError, match="mirror method needs stock, "):
        compute_correction(d, "mirror")
    with pytest.raises(InputError, match="unknown method"):
        compute_correction(d, "magic")


def test_filtered_beats_raw_on_a_werner_like_case():
    """Known systematic field + noise: the 5x5 determined component is closer to the truth."""
    rng = np.random.default_rng(2022)
    x, y = np.meshgrid(np.linspace(0, 44, 45), np.linspace(0, 44, 45), indexing="ij")
    truth = 0.0075 + 0.03 * np.sin(np.pi * x / 45) * np.cos(np.pi * (y - 10) / 50)
    d = truth + rng.normal(0, 0.004, truth.shape)
    raw = compute_correction(d, "raw").delta
    filt = compute_correction(d, "filtered").delta
    err_raw = np.sqrt(np.mean((raw - truth) ** 2))
    err_filt = np.sqrt(np.mean((filt - truth) ** 2))
    assert err_raw == pytest.approx(0.004, rel=0.05)
    assert err_filt < 0.35 * err_raw  # averaging 25 points: about 1/5 of the noise, plus bias
