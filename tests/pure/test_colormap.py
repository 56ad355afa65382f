# SPDX-License-Identifier: LGPL-2.1-or-later
"""Colour mapping of the GUI's maps (surfcomp.core.colormap), without FreeCAD."""

import numpy as np
import pytest
from matplotlib.colors import LinearSegmentedColormap
from numpy.testing import assert_allclose

from surfcomp.core import colormap as cm
from surfcomp.core.surface.bspline import Surface, evaluate_grid
from surfcomp.errors import InputError


def test_rainbow_ends_and_zero():
    c = cm.map_colors([-2.0, 0.0, 2.0, -5.0, 7.0], -2.0, 2.0, "rainbow")
    assert_allclose(c, [[0, 0, 1], [0, 1, 0], [1, 0, 0], [0, 0, 1], [1, 0, 0]], atol=1e-12)


@pytest.mark.parametrize("name", sorted(cm.SCHEMES))
def test_schemes_match_matplotlib_linear_segmented(name):
    """Linear interpolation between equally spaced control colours, as matplotlib's
    LinearSegmentedColormap.from_list does (N large so its lookup table is fine)."""
    ref = LinearSegmentedColormap.from_list(name, cm.SCHEMES[name], N=100001)
    rng = np.random.default_rng(4)
    v = rng.uniform(-0.05, 0.03, 500)
    got = cm.map_colors(v, -0.05, 0.03, name)
    want = ref((v + 0.05) / 0.08)[:, :3]
    assert_allclose(got, want, atol=5e-5)  # LUT step 1e-5 x slope <= 4


def test_nan_is_grey_and_bad_range_raises():
    c = cm.map_colors([np.nan, 0.0], -1.0, 1.0)
    assert_allclose(c[0], cm.NAN_COLOR)
    with pytest.raises(ValueError, match="vmin < vmax"):
        cm.map_colors([0.0], 1.0, 1.0)
    with pytest.raises(InputError, match="unknown colour scheme"):
        cm.map_colors([0.0], -1, 1, "jet")


def test_symmetric_range():
    assert cm.symmetric_range([-0.03, 0.045, np.nan]) == (-0.045, 0.045)
    assert cm.symmetric_range([-0.07, 0.01]) == (-0.07, 0.07)
    assert cm.symmetric_range([0.0, 0.0]) == (-cm.MIN_HALF_RANGE, cm.MIN_HALF_RANGE)


def test_tolerance_band_colours():
    v = np.array([-0.02, -0.01, 0.0, 0.0099, 0.0101, np.nan])
    c = cm.tolerance_colors(v, -0.01, 0.01)
    t = cm.TOLERANCE_COLORS
    assert_allclose(c, [t["below"], t["inside"], t["inside"], t["inside"], t["above"],
                        cm.NAN_COLOR])
    with pytest.raises(ValueError, match="lower <= upper"):
        cm.tolerance_colors(v, 0.01, -0.01)


def test_format_value_units():
    assert cm.format_value(0.045) == "+0.0450 mm"
    assert cm.format_value(-0.0123, "um") == "-12.3 µm"
    assert cm.format_value(-1e-9, "um") == "0.0 µm"
    assert cm.format_value(0.0) == "0.0000 mm"
    with pytest.raises(ValueError, match="display unit"):
        cm.format_value(1.0, "in")


def test_legend_levels_and_colours():
    lg = cm.legend(-0.04, 0.04, "rainbow", unit="um", levels=8)
    fr = [f for f, _ in lg["labels"]]
    assert_allclose(fr, np.linspace(0, 1, 9), atol=1e-15)
    assert lg["labels"][0][1] == "-40.0 µm"
    assert lg["labels"][4][1] == "0.0 µm"
    assert lg["labels"][-1][1] == "+40.0 µm"
    stops = dict(lg["stops"])
    assert_allclose(stops[0.0], (0, 0, 1))
    assert_allclose(stops[0.5], (0, 1, 0))
    assert_allclose(stops[1.0], (1, 0, 0))
    # every stop colour is the mapped colour of its value
    f = np.array([s[0] for s in lg["stops"]])
    assert_allclose(np.array([s[1] for s in lg["stops"]]),
                    cm.map_colors(-0.04 + 0.08 * f, -0.04, 0.04), atol=1e-12)


def test_legend_tolerance_blocks():
    lg = cm.legend(-0.04, 0.04, tolerance=(-0.01, 0.02))
    t = cm.TOLERANCE_COLORS
    assert [f for f, _ in lg["stops"]] == pytest.approx([0, 0.375, 0.375, 0.75, 0.75, 1])
    assert [c for _, c in lg["stops"]] == [t["below"], t["below"], t["inside"], t["inside"],
                                           t["above"], t["above"]]
    assert [s for _, s in lg["labels"]] == ["-0.0400 mm", "-0.0100 mm", "+0.0200 mm",
                                            "+0.0400 mm"]


def test_extremes():
    assert cm.extremes([0.1, -0.3, np.nan, 0.5, -0.2]) == (3, 1)
    assert cm.extremes([-0.1, -0.2]) == (None, 1)
    assert cm.extremes([np.nan, np.nan]) == (None, None)


def test_mesh_resolution():
    assert cm.mesh_resolution((45, 45)) == (90, 90)
    assert cm.mesh_resolution((10, 200)) == (80, 240)
    assert cm.mesh_resolution(None) == (80, 80)


def _bilinear_patch():
    """A degree-1 patch x = 10 u, y = 20 v, z = u v: an analytic reference."""
    poles = np.array([[[0, 0, 0], [0, 20, 0]], [[10, 0, 0], [10, 20, 1]]], dtype=float)
    k = np.array([0.0, 0.0, 1.0, 1.0])
    return Surface(poles, k, k, 1, 1)


def test_uv_grid_mesh_points_and_triangles():
    surf = _bilinear_patch().with_range((0.2, 0.8), (0.0, 0.5))
    pts, tri, u, v = cm.uv_grid_mesh(surf, (4, 3))
    assert pts.shape == (12, 3) and tri.shape == (12, 3)
    assert_allclose(u.reshape(4, 3)[:, 0], np.linspace(0.2, 0.8, 4))
    assert_allclose(v.reshape(4, 3)[0], np.linspace(0.0, 0.5, 3))
    assert_allclose(pts, np.stack([10 * u, 20 * v, u * v], axis=1), atol=1e-12)
    # triangles are counter-clockwise seen from Su x Sv (+z here) and cover the range
    p = pts[tri]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    assert np.all(n[:, 2] > 0)
    assert_allclose(0.5 * n[:, 2].sum(), 10 * 0.6 * 20 * 0.5, rtol=1e-12)
    assert np.array_equal(np.unique(tri), np.arange(12))
    with pytest.raises(ValueError, match="2 x 2"):
        cm.uv_grid_mesh(surf, (1, 5))


def test_uv_grid_mesh_matches_evaluate_grid_on_a_cubic():
    rng = np.random.default_rng(7)
    poles = np.zeros((5, 6, 3))
    poles[..., 0], poles[..., 1] = np.meshgrid(np.arange(5.0), np.arange(6.0), indexing="ij")
    poles[..., 2] = rng.normal(0, 1, (5, 6))
    ku = np.array([0, 0, 0, 0, 0.5, 1, 1, 1, 1.0])
    kv = np.array([0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1.0])
    surf = Surface(poles, ku, kv, 3, 3)
    pts, _, u, v = cm.uv_grid_mesh(surf, (7, 9))
    ref = evaluate_grid(surf, np.linspace(0, 1, 7), np.linspace(0, 1, 9)).reshape(-1, 3)
    assert_allclose(pts, ref, atol=1e-12)


def test_out_of_range_colours_are_distinct_from_the_scheme_ends():
    cols = cm.map_colors([-0.03, -0.02, 0.0, 0.02, 0.03, np.nan], -0.02, 0.02,
                         out_of_range=True)
    assert_allclose(cols[0], cm.OUT_OF_RANGE_COLORS["below"])
    assert_allclose(cols[4], cm.OUT_OF_RANGE_COLORS["above"])
    assert_allclose(cols[1], (0, 0, 1))           # the range's ends keep the scheme's colours
    assert_allclose(cols[3], (1, 0, 0))
    assert_allclose(cols[5], cm.NAN_COLOR)
    # without the option a manual range saturates to the end colours
    assert_allclose(cm.map_colors([0.03], -0.02, 0.02)[0], (1, 0, 0))


def test_stepped_colours_are_the_middles_of_the_legend_steps():
    lg = cm.legend(-1.0, 1.0, levels=4, stepped=True)
    # sharp edges: every colour appears twice, at both ends of its step
    assert [f for f, _ in lg["stops"]] == pytest.approx([0, .25, .25, .5, .5, .75, .75, 1])
    steps = cm.map_colors([-0.75, -0.25, 0.25, 0.75], -1, 1)
    assert_allclose([c for _, c in lg["stops"][::2]], steps, atol=1e-12)
    # any value of a step takes the step's colour
    assert_allclose(cm.map_colors([-0.99, -0.51], -1, 1, levels=4), steps[[0, 0]], atol=1e-12)


def test_a_value_on_a_step_edge_takes_the_step_above_whatever_the_rounding():
    """On the default manual range -0.05 .. 0.05 mm in 10 steps, -0.01 and +0.03 mm sit a
    rounding error below their edges and took the step under the label, +0.01 and +0.02
    the one above."""
    lo, hi, n = -0.05, 0.05, 10
    labels = lo + np.linspace(0.0, 1.0, n + 1) * (hi - lo)
    typed = np.round(labels, 6)              # the values as a measurement file gives them
    middles = lo + (np.arange(n) + 0.5) / n * (hi - lo)
    above = cm.map_colors(middles[list(range(n)) + [n - 1]], lo, hi)
    for values in (labels, typed):
        assert_allclose(cm.map_colors(values, lo, hi, levels=n), above, atol=1e-12)
    lo, hi = -0.047134, 0.047134             # the example's automatic range
    labels = lo + np.linspace(0.0, 1.0, n + 1) * (hi - lo)
    middles = lo + (np.arange(n) + 0.5) / n * (hi - lo)
    assert_allclose(cm.map_colors(labels, lo, hi, levels=n),
                    cm.map_colors(middles[list(range(n)) + [n - 1]], lo, hi), atol=1e-12)


def test_band_fractions_and_warning_band():
    v = np.array([-0.02, -0.009, -0.004, 0.0, 0.004, 0.009, 0.011, 0.03, np.nan, 0.01])
    fr = cm.band_fractions(v, -0.01, 0.01, warning=0.8)
    assert fr["below"] == pytest.approx(100 / 9)
    assert fr["above"] == pytest.approx(200 / 9)
    assert fr["inside"] == pytest.approx(600 / 9)
    # warning limits +-0.008: -0.009, 0.009, 0.01 warn
    assert fr["warning"] == pytest.approx(300 / 9)
    cols = cm.tolerance_colors(v, -0.01, 0.01, warning=0.8)
    assert_allclose(cols[1], cm.WARNING_COLOR)
    assert_allclose(cols[2], cm.TOLERANCE_COLORS["inside"])
    assert_allclose(cols[6], cm.TOLERANCE_COLORS["above"])
    blocks = cm.legend(-0.02, 0.02, tolerance=(-0.01, 0.01), warning=0.8)["blocks"]
    assert [b[0] for b in blocks] == ["below", "warning", "inside", "warning", "above"]
    assert_allclose([b[1] for b in blocks], [0, 0.25, 0.3, 0.7, 0.75])


def test_histogram_counts_and_legend_colours():
    rng = np.random.default_rng(0)
    v = rng.normal(0, 0.01, 1000)
    h = cm.histogram(v, -0.02, 0.02, bins=8)
    assert h["counts"].sum() + h["below"] + h["above"] == 1000
    assert h["below"] == np.count_nonzero(v < -0.02)
    assert_allclose(h["colors"], cm.map_colors(0.5 * (h["edges"][1:] + h["edges"][:-1]),
                                               -0.02, 0.02))


def test_stepped_histogram_bars_hold_the_values_of_their_colour():
    """With the histogram panel's 24 bins over 10 steps, a bar across a step's edge counted
    values of two colours under one: on a spread like the example's a tenth of the points
    were in a bar of another colour than theirs on the map."""
    v = np.random.default_rng(2).uniform(-0.047, 0.047, 2000)
    lo, hi = cm.symmetric_range(v)
    h = cm.histogram(v, lo, hi, bins=24, levels=10)
    assert len(h["counts"]) == 20 and h["counts"].sum() == v.size
    bar = np.clip(np.searchsorted(h["edges"], v, side="right") - 1, 0, len(h["counts"]) - 1)
    assert_allclose(h["colors"][bar], cm.map_colors(v, lo, hi, levels=10), atol=1e-12)
