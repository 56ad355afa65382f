"""Virtual machining (surfcomp.core.simulate): model equations with hand-computed numbers,
the random field's statistics, and the papers' orderings over replicas on a Werner-like case."""

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from examples.make_example import example_surface
from surfcomp.core import bspline
from surfcomp.core import simulate as sm
from surfcomp.core.axis_errors import AxisErrorModel
from surfcomp.core.deviations import Statistics
from surfcomp.errors import InputError


def plane(slope=0.2, lx=40.0, ly=20.0):
    """Bilinear patch z = slope * x over [0, lx] x [0, ly] (u along x, v along y)."""
    P = np.array([[[0.0, 0.0, 0.0], [0.0, ly, 0.0]],
                  [[lx, 0.0, slope * lx], [lx, ly, slope * lx]]])
    k = np.array([0.0, 0.0, 1.0, 1.0])
    return bspline.Surface(P, k, k, 1, 1)


def werner_like():
    """The bundled example's face: 45 x 45 mm, 7 x 7 poles, bicubic, interior knots."""
    return example_surface()


# ------------------------------------------------------------------ model equations
def test_systematic_error_on_tilted_plane_by_hand():
    surf = plane(0.2)
    model = sm.MachiningModel(offset=0.001, slope_gain=0.01, abs_slope_gain=0.02,
                              tilt=(0.004, 0.006), bow=(0.008, -0.002), waviness=0.003,
                              wavelength=40.0, sigma=0.0)
    frame = model.frame(surf)
    # work area x 0..40 (centre 20, half 20), y 0..20 (centre 10, half 10)
    assert_allclose(frame.half, (20.0, 10.0), atol=1e-12)
    P = np.array([[30.0, 5.0, 6.0]])
    n = np.array([[-0.2, 0.0, 1.0]]) / np.sqrt(1.04)
    assert_allclose(model.slope(n), [0.2], atol=1e-15)  # dz/dx along the feed
    # xi = 10/20 = 0.5, eta = -5/10 = -0.5, p_f = 10 mm -> sin(2 pi 10 / 40) = 1
    expected = (0.001 + 0.01 * 0.2 + 0.02 * 0.2 + 0.004 * 0.5 - 0.006 * 0.5
                + 0.008 * 0.25 - 0.002 * 0.25 + 0.003)
    assert_allclose(model.systematic(frame, P, n), [expected], atol=1e-15)
    assert_allclose(expected, 0.0105, atol=1e-15)
    # cutting the other way (feed -x): the slope changes sign, |s| does not, xi changes sign
    back = sm.MachiningModel(offset=0.001, slope_gain=0.01, abs_slope_gain=0.02, feed=(-1, 0, 0),
                             sigma=0.0, tilt=(0.0, 0.0), bow=(0.0, 0.0))
    assert_allclose(back.slope(n), [-0.2], atol=1e-15)
    assert_allclose(back.systematic(back.frame(surf), P, n), [0.001 - 0.002 + 0.004], atol=1e-15)


def test_slope_is_clipped_on_vertical_walls_and_sign_independent_of_normal_side():
    model = sm.MachiningModel()
    n = np.array([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.6, 0.0, -0.8]])
    # a wall facing -x (climbing along +x): +MAX_SLOPE; a wall along the feed: 0;
    # a downward-facing face keeps dz/dx = -n_x / n_z = 0.75
    assert_allclose(model.slope(n), [sm.MAX_SLOPE, 0.0, 0.75], atol=1e-12)


def test_axis_errors_enter_along_the_normal():
    surf = plane(0.2)
    axis = AxisErrorModel(offset=(0.0, 0.0, 0.003))  # the tool lands 3 um higher everywhere
    model = sm.MachiningModel(offset=0.0, slope_gain=0.0, abs_slope_gain=0.0, tilt=(0, 0),
                              bow=(0, 0), sigma=0.0, axis_errors=axis)
    n = np.array([[-0.2, 0.0, 1.0]]) / np.sqrt(1.04)
    e = model.systematic(model.frame(surf), np.array([[10.0, 10.0, 2.0]]), n)
    assert_allclose(e, [0.003 / np.sqrt(1.04)], atol=1e-15)
    scale = AxisErrorModel.from_components(scale={"x": 1e-4})  # E_x = 1e-4 * x
    model.axis_errors = scale
    e = model.systematic(model.frame(surf), np.array([[30.0, 10.0, 6.0]]), n)
    assert_allclose(e, [-0.2 * 30e-4 / np.sqrt(1.04)], atol=1e-15)
    assert model.as_dict()["axis_errors"]["slope"][0][0] == 1e-4


def test_machine_then_measure_returns_the_model_error_exactly():
    """On a plane the measured deviation of the machined nominal is e_sys (projection engine)."""
    surf = plane(0.2)
    model = sm.MachiningModel(offset=0.002, slope_gain=0.01, abs_slope_gain=0.0, tilt=(0.004, 0.0),
                              bow=(0.0, 0.003),
                              sigma=0.0, probe_sigma=0.0)
    frame = model.frame(surf)
    us, vs = np.linspace(0.1, 0.9, 5), np.linspace(0.1, 0.9, 4)
    M = sm.machine(model, frame, surf, 1, us, vs, np.random.default_rng(0))
    d = sm.measure(sm.Projector(surf), 1, M, np.random.default_rng(0))
    x = 40.0 * us[:, None] + 0 * vs
    y = 0 * us[:, None] + 20.0 * vs
    expected = 0.002 + 0.01 * 0.2 + 0.004 * (x - 20) / 20 + 0.003 * ((y - 10) / 10) ** 2
    assert_allclose(d, expected, atol=1e-12)
    # the mirror method's semi-finishing pass: the stock is added on top, and the CAM
    # point moved by 0.3 n (n_x = -0.2 / sqrt(1.04)) changes the tilt term by 0.004 * dx / 20
    M = sm.machine(model, frame, surf, 1, us, vs, np.random.default_rng(0), offset=0.3)
    d = sm.measure(sm.Projector(surf), 1, M, np.random.default_rng(0))
    assert_allclose(d, expected + 0.3 + 0.004 * (0.3 * -0.2 / np.sqrt(1.04)) / 20, atol=1e-12)
    # a reversed face (outward = -Su x Sv) is machined on the other side
    M = sm.machine(model, frame, surf, -1, us, vs, np.random.default_rng(0))
    d = sm.measure(sm.Projector(surf), -1, M, np.random.default_rng(0))
    assert_allclose(d, expected, atol=1e-12)


def test_white_random_part_has_the_stated_sigma_and_is_seeded():
    surf = plane(0.0)
    model = sm.MachiningModel(sigma=0.002)
    frame = model.frame(surf)
    P = np.zeros((20000, 3))
    a = model.random(frame, P, np.random.default_rng(5))
    b = model.random(frame, P, np.random.default_rng(5))
    assert_allclose(a, b, atol=0)
    # sample std of 20000 normals: relative standard error 0.5 %
    assert_allclose(np.std(a), 0.002, rtol=0.02)
    assert abs(np.corrcoef(a[:-1], a[1:])[0, 1]) < 0.03


def test_correlated_field_has_unit_variance_and_gaussian_correlation():
    """Correlation exp(-(r/L)^2): e^-1 at r = L, e^-4 at r = 2L (20 realisations)."""
    L = 4.0
    rng = np.random.default_rng(11)
    x = np.linspace(-80.0, 80.0 - 2 * L, 400)
    y = np.linspace(-80.0, 80.0, 40)
    X, Y = np.meshgrid(x, y, indexing="ij")
    X, Y = X.ravel(), Y.ravel()
    var, c1, c2, c_half = [], [], [], []
    for _ in range(20):
        pts = (np.r_[X, X + L, X + 2 * L, X + 0.5 * L], np.r_[Y, Y, Y, Y])
        f = sm.correlated_field(pts, (80.0, 80.0), L, rng).reshape(4, -1)
        var.append(np.mean(f[0] ** 2))
        c1.append(np.mean(f[0] * f[1]))
        c2.append(np.mean(f[0] * f[2]))
        c_half.append(np.mean(f[0] * f[3]))
    assert_allclose(np.mean(var), 1.0, atol=0.05)
    assert_allclose(np.mean(c_half), np.exp(-0.25), atol=0.05)
    assert_allclose(np.mean(c1), np.exp(-1.0), atol=0.05)
    assert_allclose(np.mean(c2), np.exp(-4.0), atol=0.05)


def test_bad_model_parameters_are_refused():
    with pytest.raises(InputError, match="sigma must be >= 0"):
        sm.MachiningModel(sigma=-1.0)
    with pytest.raises(InputError, match="parallel to the tool axis"):
        sm.MachiningModel(feed=(0, 0, 1))
    with pytest.raises(InputError, match="unknown method 'best'"):
        sm.method_specs(["raw", "best"])
    with pytest.raises(InputError, match="odd"):
        sm.method_specs(["filtered"], masks=[4])
    with pytest.raises(InputError, match="at least 3 x 3"):
        sm.make_layout(plane(), (2, 9))


def test_method_specs_and_layout():
    specs = sm.method_specs(["none", "filtered", "mirror"], masks=[3, 5], stock=0.2)
    assert [s.label for s in specs] == ["none", "filtered 3x3", "filtered 5x5", "mirror"]
    assert specs[3].options.stock == 0.2 and specs[1].options.mask().shape == (3, 3)
    lay = sm.make_layout(plane(), (4, 3), margin=0.1, between=2)
    assert lay.eval_shape == (7, 5)
    assert_allclose(lay.us[::2], np.linspace(0.1, 0.9, 4), atol=1e-15)
    assert lay.node_mask().sum() == 12


def test_spread_and_table_by_hand():
    a = Statistics(10, -0.002, 0.004, 0.001, 0.002, 0.0022, 0.008)
    b = Statistics(10, -0.004, 0.002, 0.003, 0.001, 0.0031, 0.008)
    sp = sm.spread([a, b])
    assert_allclose([sp["mean"]["mean"], sp["mean"]["range"], sp["std"]["std"]],
                    [0.002, 0.002, np.sqrt(0.5e-6)], atol=1e-15)
    text = sm.format_simulation_table([("Before", [a, b])], 2)
    assert "Max. negative" in text and "-3.00 (2.00)" in text and "1.50 (1.00)" in text


# ------------------------------------------------------------------ the loop
def test_zero_error_machine_gives_zero_deviation_for_every_method():
    surf = werner_like()
    model = sm.MachiningModel(offset=0.0, slope_gain=0.0, abs_slope_gain=0.0, tilt=(0, 0),
                              bow=(0, 0), sigma=0.0, probe_sigma=0.0)
    res = sm.simulate(surf, 1, model, grid=(7, 7), replicas=1, seed=3,
                      specs=sm.method_specs(stock=0.3))
    for label in ["before"] + res.labels:
        st = res.values(label, "profile")
        assert st[0] < 2e-6, (label, st)
    # the mirror method's semi-finished part stands the stock proud of the nominal
    assert_allclose(res.semi_finish["mirror"][0].mean, 0.3, atol=1e-9)


def test_results_do_not_depend_on_which_other_methods_run():
    surf = werner_like()
    model = sm.MachiningModel(sigma=0.002)
    one = sm.simulate(surf, 1, model, grid=(9, 9), replicas=2, seed=7,
                      specs=sm.method_specs(["raw"]))
    two = sm.simulate(surf, 1, model, grid=(9, 9), replicas=2, seed=7,
                      specs=sm.method_specs(["none", "offset", "raw"]))
    assert_allclose(one.values("raw", "std"), two.values("raw", "std"), atol=0)
    assert_allclose(one.values("before", "mean"), two.values("before", "mean"), atol=0)
    other = sm.simulate(surf, 1, model, grid=(9, 9), replicas=2, seed=8,
                        specs=sm.method_specs(["raw"]))
    assert np.all(other.values("raw", "std") != one.values("raw", "std"))


@pytest.fixture(scope="module")
def werner_small_random():
    """Werner-like: systematic -0.030 .. +0.044 mm, 1.5 um random, 0.5 um probe; 23 x 23 grid."""
    model = sm.MachiningModel()
    return sm.simulate(werner_like(), 1, model, grid=(23, 23), replicas=4, seed=2022,
                       specs=sm.method_specs(stock=0.3))


def test_werner_like_case_reproduces_table_1(werner_small_random):
    res = werner_small_random
    lo, hi = res.values("before", "max_negative"), res.values("before", "max_positive")
    assert np.all((lo > -0.036) & (lo < -0.028)), lo
    assert np.all((hi > 0.042) & (hi < 0.050)), hi
    assert_allclose(res.values("before", "std"), 0.0165, atol=0.001)


def test_every_compensation_shrinks_the_profile_error_in_every_replica(werner_small_random):
    res = werner_small_random
    none = res.values("none", "profile")
    assert_allclose(none, res.values("before", "profile"), rtol=0.15)  # the same part again
    # offset: the zone shrinks by about twice the mean it removes (mean ~4.7 um)
    assert np.all(res.values("offset", "profile") < none - 0.005)
    for label in ("raw", "filtered", "mirror"):
        assert np.all(res.values(label, "profile") < 0.3 * none), label
    for label in ("raw", "filtered", "mirror"):
        # std from ~16.5 um to a few um (Werner Tab. 5: 17.3 -> 1.8 / 1.4 um)
        assert np.all(res.values(label, "std") < 0.2 * res.values("none", "std")), label
        assert np.all(np.abs(res.values(label, "mean")) < 0.001), label


def test_offset_fixes_the_mean_but_not_the_spread(werner_small_random):
    """Mirror paper Tab. 3: tool radius compensation moves the mean to ~0, std unchanged."""
    res = werner_small_random
    assert np.all(res.values("none", "mean") > 0.004)
    assert np.all(np.abs(res.values("offset", "mean")) < 0.0005)
    assert_allclose(res.values("offset", "std"), res.values("none", "std"), rtol=0.02)
    # mirror and raw use the same measured error (the model has no depth-of-cut term)
    assert_allclose(res.values("mirror", "std"), res.values("raw", "std"), rtol=0.1)


def test_as_dict_is_json_and_holds_every_replica(werner_small_random):
    d = json.loads(json.dumps(werner_small_random.as_dict()))
    assert d["schema"] == "surfcomp-simulation/1" and d["replicas"] == 4
    assert d["grid"] == [23, 23] and d["evaluation_grid"] == [45, 45]
    labels = [m["label"] for m in d["methods"]]
    assert labels == ["none", "offset", "raw", "filtered", "mirror"]
    raw = d["methods"][2]
    assert len(raw["replicas"]) == 4 and raw["replicas"][0]["all"]["count"] == 45 * 45
    assert raw["replicas"][0]["grid"]["count"] == 23 * 23
    stds = [r["all"]["std"] for r in raw["replicas"]]
    assert_allclose(raw["spread"]["all"]["std"]["range"], np.ptp(stds), atol=1e-15)
    assert len(d["methods"][4]["semi_finish"]["replicas"]) == 4
    assert max(raw["max_error_at_points_mm"]) < 5e-5
    assert "Profile error ISO 1101" in d["table"]


def test_filtered_beats_raw_only_when_the_random_part_matters():
    """Werner 2022 Tab. 5: filtering helps when random errors matter; with almost no
    random part the raw correction wins (the 5x5 filter smooths the systematic part)."""
    surf = werner_like()
    specs = sm.method_specs(["raw", "filtered"])
    noisy = sm.simulate(surf, 1, sm.MachiningModel(sigma=0.004), grid=(23, 23), replicas=4,
                        seed=5, specs=specs)
    raw, filt = noisy.values("raw", "std"), noisy.values("filtered", "std")
    # raw: sqrt(2) sigma (two random realisations); filtered: ~sigma plus the filter's bias
    assert_allclose(raw, np.sqrt(2 * 0.004 ** 2 + 2 * 0.0005 ** 2), rtol=0.1)
    assert np.all(filt < raw - 0.0003), (filt, raw)
    assert np.all(noisy.values("filtered", "profile").mean()
                  < noisy.values("raw", "profile").mean())
    quiet = sm.simulate(surf, 1, sm.MachiningModel(sigma=0.0003), grid=(23, 23), replicas=4,
                        seed=5, specs=specs)
    assert np.all(quiet.values("raw", "std") < quiet.values("filtered", "std") - 0.0005)
