# SPDX-License-Identifier: LGPL-2.1-or-later
"""Axis error model (Dobariya 2015, eq. 6-16), its fitting, compensation and CSV input."""

import os

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy import optimize, stats

from surfcomp.core.axis.axis_checks import error_stats, validate, volumetric_map
from surfcomp.core.axis.axis_errors import AxisErrorModel, SimulatedMachine, fit_axis_errors
from surfcomp.errors import ComputationError, InputError, MeasurementFileError
from surfcomp.io.axis_csv import format_axis_errors, read_axis_errors, write_axis_errors
from surfcomp.io.gcode import parse_gcode, read_gcode
from tests.conftest import REALDATA

BEAR = os.path.join(REALDATA, "gcode", "CAMotics_GPL", "bear.nc")


def paper_like_model():
    """Magnitudes as in Dobariya 2015 Table 3: X and Y linear (up to 358 and 449 um over
    100 mm), Z quadratic (-17 um at Z = -20, +21 um at Z = -50), plus squareness and a
    flatness error, e0 = (5, 90, 0) um at the reference (0, 0, 0)."""
    return AxisErrorModel.from_components(
        scale={"x": 3.58e-3, "y": 4.49e-3},
        positional={"z": (1.7e-3, 4.25e-5)},
        straightness={"z(x)": (0.0, 2e-6), "x(y)": (0.0, -1e-6)},
        squareness={"xy": 5e-5, "zx": 1e-4, "yz": -3e-5},
        offset=(0.005, 0.090, 0.0))


def measure_positions():
    return {"x": np.linspace(0.0, 100.0, 11), "y": np.linspace(0.0, 100.0, 11),
            "z": np.linspace(-50.0, 0.0, 11)}


# --------------------------------------------------------------- eq. 14 composition
def test_composition_matches_paper_equations_6_to_14():
    """E_i = delta_i(x) + delta_i(y) + delta_i(z) with eq. 6 (positional = scale +
    ball screw) and eq. 7-8 (cross errors = straightness/flatness + alpha * travel),
    written out term by term, at random points, with a reference off the origin."""
    s = {"x": 12e-6, "y": -7e-6, "z": 3e-6}                       # delta_a1 = s t
    pos = {"x": (1e-6, 2e-7), "y": (-2e-6, -1e-7), "z": (0.5e-6, 3e-7)}  # delta_a2
    st = {"y(x)": (1e-6, 4e-8), "z(x)": (-2e-6, 5e-8), "x(y)": (3e-6, -6e-8),
          "z(y)": (0.0, 7e-8), "x(z)": (-1e-6, 8e-8), "y(z)": (2e-6, -9e-8)}
    al = {"xy": 11e-6, "xz": -12e-6, "yx": 13e-6, "yz": 14e-6, "zx": -15e-6, "zy": 16e-6}
    ref = np.array([10.0, -20.0, 5.0])
    e0 = np.array([0.001, -0.002, 0.003])
    model = AxisErrorModel.from_components(scale=s, positional=pos, straightness=st,
                                           squareness=al, reference=ref, offset=e0)
    rng = np.random.default_rng(6)
    P = rng.uniform(-200, 300, (50, 3))
    x, y, z = (P - ref).T

    def q(c, t):
        return c[0] * t + c[1] * t * t

    # eq. 6: delta_x(x) = delta_x1(x) + delta_x2(x); eq. 7-8: delta_y(x) = delta'_y(x) + a_xy x
    dx_x = s["x"] * x + q(pos["x"], x)
    dy_x = q(st["y(x)"], x) + al["xy"] * x
    dz_x = q(st["z(x)"], x) + al["xz"] * x
    dx_y = q(st["x(y)"], y) + al["yx"] * y
    dy_y = s["y"] * y + q(pos["y"], y)
    dz_y = q(st["z(y)"], y) + al["yz"] * y
    dx_z = q(st["x(z)"], z) + al["zx"] * z
    dy_z = q(st["y(z)"], z) + al["zy"] * z
    dz_z = s["z"] * z + q(pos["z"], z)
    # eq. 14 (plus the error at the reference)
    E = np.stack([dx_x + dx_y + dx_z, dy_x + dy_y + dy_z, dz_x + dz_y + dz_z], axis=1) + e0
    assert_allclose(model.error(P), E, rtol=0, atol=1e-15)
    # the single functions of eq. 6-8
    assert_allclose(model.delta("y", "x", P[:, 0]), dy_x, rtol=0, atol=1e-15)
    assert_allclose(model.delta("z", "z", P[:, 2]), dz_z, rtol=0, atol=1e-15)
    # the 12 components come back
    c = model.components()
    assert_allclose([c["scale"][a] for a in "xyz"],
                    [s[a] + pos[a][0] for a in "xyz"], atol=1e-18)
    assert_allclose([c["positional_quadratic"][a] for a in "xyz"],
                    [pos[a][1] for a in "xyz"], atol=1e-18)
    assert_allclose([c["straightness"][k] for k in ("y(x)", "x(y)", "x(z)")],
                    [st[k][1] for k in ("y(x)", "x(y)", "x(z)")], atol=1e-18)
    assert_allclose([c["flatness"][k] for k in ("z(x)", "z(y)", "y(z)")],
                    [st[k][1] for k in ("z(x)", "z(y)", "y(z)")], atol=1e-18)
    # squareness between two slides = sum of the two measured slopes
    assert c["squareness"]["xy"] == pytest.approx(al["xy"] + al["yx"] + st["y(x)"][0]
                                                  + st["x(y)"][0], abs=1e-18)
    assert c["slopes"]["zx"] == pytest.approx(al["zx"] + st["x(z)"][0], abs=1e-18)


def test_jacobian_matches_finite_differences():
    model = paper_like_model()
    P = np.random.default_rng(1).uniform(-50, 100, (20, 3))
    J = model.jacobian(P)
    h = 1e-4
    for a in range(3):
        d = np.zeros(3)
        d[a] = h
        fd = (model.error(P + d) - model.error(P - d)) / (2 * h)
        assert_allclose(J[:, :, a], fd, rtol=0, atol=1e-11)


# ----------------------------------------------------------------------- fitting
def test_linear_fit_against_hand_computed_coefficients():
    """X at 0, 10, 20, 30 mm with ex = 0, 11, 19, 32 um: mean t 15 mm, mean e 15.5 um,
    b1 = sum((t-15)(e-15.5)) / sum((t-15)^2) = 520 / 500 um/mm = 1.04 um/mm,
    b0 = 15.5 - 1.04 * 15 = -0.1 um; residuals 0.1, 0.7, -1.7, 0.9 um (RSS 4.2 um^2);
    TSS = 15.5^2 + 4.5^2 + 3.5^2 + 16.5^2 = 545 um^2."""
    pos = np.array([0.0, 10.0, 20.0, 30.0])
    err = np.zeros((4, 3))
    err[:, 0] = np.array([0.0, 11.0, 19.0, 32.0]) * 1e-3
    model = fit_axis_errors({"x": (pos, err)}, model="linear")
    f = model.fits[0]
    assert (f.axis, f.component, f.degree, f.rule) == ("x", "x", 1, "given")
    assert_allclose(f.coefficients, [-0.1e-3, 1.04e-3, 0.0], rtol=0, atol=1e-15)
    assert_allclose(f.residuals, np.array([0.1, 0.7, -1.7, 0.9]) * 1e-3, rtol=0, atol=1e-15)
    assert f.rss == pytest.approx(4.2e-6, abs=1e-18)
    assert f.rms == pytest.approx(np.sqrt(4.2e-6 / 4), abs=1e-15)
    # adjusted R^2 = 1 - (RSS/(n-2)) / (TSS/(n-1))
    assert f.r2_adjusted == pytest.approx(1 - (4.2e-6 / 2) / (5.45e-4 / 3), abs=1e-12)
    assert model.slope[0, 0] == pytest.approx(1.04e-3, abs=1e-15)
    assert model.offset[0] == pytest.approx(-0.1e-3, abs=1e-15)
    # only X measured: the other slides carry no error
    assert not model.slope[1:].any() and not model.curvature.any()


def test_quadratic_fit_against_hand_computed_coefficients():
    """Five Z positions -20..20 mm (u = t / 10 = -2..2) with ez = 4, 1, 0, 1, 5 um.
    Normal equations: b1 = sum(u e) / sum(u^2) = 2/10; 5 b0 + 10 b2 = 11 and
    10 b0 + 34 b2 = 38 give b2 = 8/7, b0 = -3/35 (um, per u)."""
    pos = np.array([-20.0, -10.0, 0.0, 10.0, 20.0])
    err = np.zeros((5, 3))
    err[:, 2] = np.array([4.0, 1.0, 0.0, 1.0, 5.0]) * 1e-3
    model = fit_axis_errors({"z": (pos, err)}, model="quadratic")
    f = [g for g in model.fits if g.component == "z"][0]
    assert f.degree == 2
    assert_allclose(f.coefficients, [-3 / 35 * 1e-3, 0.2e-3 / 10, 8 / 7 * 1e-3 / 100],
                    rtol=0, atol=1e-15)
    assert model.curvature[2, 2] == pytest.approx(8 / 7 * 1e-5, abs=1e-18)
    # three points: the quadratic passes through them exactly
    m3 = fit_axis_errors({"z": (pos[1:4], err[1:4])}, model="quadratic")
    assert_allclose(m3.fits[2].residuals, 0.0, atol=1e-16)
    assert_allclose(m3.curvature[2, 2], 2e-3 / 2 / 100, atol=1e-18)


def test_auto_model_uses_the_partial_f_test():
    """'auto' picks the quadratic only when F = (RSS1 - RSS2) / (RSS2 / (n - 3)) is
    significant at 5 %; F and p are checked against numpy.polyfit and scipy.stats.f."""
    rng = np.random.default_rng(3)
    t = np.linspace(-100, 100, 15)
    noise = rng.normal(0, 1e-3, (15, 3))
    err = np.stack([2e-4 * t, 1e-6 * t * t, 5e-5 * t], axis=1) + noise
    model = fit_axis_errors({"y": (t, err)}, model="auto")
    degrees = [f.degree for f in model.fits]
    assert degrees == [1, 2, 1]
    for i, f in enumerate(model.fits):
        r1 = err[:, i] - np.polyval(np.polyfit(t, err[:, i], 1), t)
        r2 = err[:, i] - np.polyval(np.polyfit(t, err[:, i], 2), t)
        F = (r1 @ r1 - r2 @ r2) / (r2 @ r2 / 12)
        assert f.rule == "F-test"
        assert f.f_statistic == pytest.approx(F, rel=1e-9)
        assert f.p_value == pytest.approx(stats.f.sf(F, 1, 12), rel=1e-9)
    # exact straight line: linear without a test; fewer than 4 points: linear
    exact = fit_axis_errors({"x": (t, np.outer(t, [1e-4, 0, 0]))}, model="auto")
    assert [f.rule for f in exact.fits] == ["exact line"] * 3
    few = fit_axis_errors({"x": (t[:3], err[:3])}, model="auto")
    assert [(f.degree, f.rule) for f in few.fits] == [(1, "n < 4")] * 3


def test_fit_recovers_a_known_machine_exactly_and_reference_offset():
    true = paper_like_model()
    data = SimulatedMachine(true).measure(measure_positions())
    fit = fit_axis_errors(data, model="auto")
    assert_allclose(fit.slope, true.slope, rtol=0, atol=1e-13)
    assert_allclose(fit.curvature, true.curvature, rtol=0, atol=1e-15)
    assert_allclose(fit.offset, true.offset, rtol=0, atol=1e-13)
    assert_allclose(fit.offset_spread, 0.0, atol=1e-13)
    # quadratic exactly where the machine is quadratic
    quad = {(f.axis, f.component) for f in fit.fits if f.degree == 2}
    assert quad == {("x", "z"), ("y", "x"), ("z", "z")}
    assert_allclose(fit.travel, [[0, 100], [0, 100], [-50, 0]])


def test_fit_refuses_bad_input():
    p = np.array([0.0, 10.0])
    e = np.zeros((2, 3))
    with pytest.raises(InputError, match="unknown axis error model 'cubic'"):
        fit_axis_errors({"x": (p, e)}, model="cubic")
    with pytest.raises(InputError, match="a quadratic fit needs at least 3"):
        fit_axis_errors({"x": (p, e)}, model="quadratic")
    with pytest.raises(InputError, match="axis X: 1 distinct position"):
        fit_axis_errors({"x": (np.array([5.0, 5.0]), e)}, model="linear")
    with pytest.raises(InputError, match="no axis error measurements"):
        fit_axis_errors({})
    with pytest.raises(InputError, match="non-finite"):
        fit_axis_errors({"z": (p, np.full((2, 3), np.inf))})
    with pytest.raises(InputError, match="axis Z: error along X/Y/Z measured at 0 distinct"):
        fit_axis_errors({"z": (p, np.full((2, 3), np.nan))})
    half = np.array([[0.0, 0.0, 0.0], [0.001, np.nan, 0.0], [0.002, np.nan, 0.0]])
    with pytest.raises(InputError, match="axis X: error along Y measured at 1 distinct"):
        fit_axis_errors({"x": (np.array([0.0, 10.0, 20.0]), half)})


def test_unmeasured_rows_are_left_out_of_their_component_fit():
    """NaN = not measured in that row: each component is fitted on its own rows only, the
    others on all rows as before (same numbers as fitting those rows alone)."""
    pos = np.array([0.0, 100.0, 200.0, 0.0, 100.0, 200.0])
    err = np.array([[0.0, np.nan, 0.0], [0.010, np.nan, 0.001], [0.020, np.nan, 0.002],
                    [np.nan, 0.0, 0.0], [np.nan, 0.002, 0.001], [np.nan, 0.004, 0.002]])
    m = fit_axis_errors({"x": (pos, err)}, model="linear")
    f = {fit.component: fit for fit in m.fits}
    assert [fit.component for fit in m.fits] == ["x", "y", "z"]
    assert (f["x"].n, f["y"].n, f["z"].n) == (3, 3, 6)
    assert_allclose(m.slope[0], [1e-4, 2e-5, 1e-5], rtol=1e-12, atol=1e-18)
    assert_allclose(f["x"].positions, [0, 100, 200], atol=0)
    assert_allclose(f["y"].values, [0, 0.002, 0.004], atol=0)
    assert_allclose(m.offset, [0, 0, 0], atol=1e-15)
    whole = fit_axis_errors({"x": (pos[:3], np.nan_to_num(err[:3]))}, model="linear")
    assert_allclose(m.slope[0, 0], whole.slope[0, 0], rtol=0, atol=0)


# ------------------------------------------------------------------ compensation
def test_compensation_solves_the_fixed_point_equation():
    model = paper_like_model()
    P = np.random.default_rng(11).uniform(-60, 160, (500, 3))
    C = model.compensate(P)
    assert_allclose(C + model.error(C), P, rtol=0, atol=1e-10)
    # against a library root finder on a few points
    for k in range(5):
        ref = optimize.fsolve(lambda x, k=k: x + model.error(x) - P[k], P[k], xtol=1e-14)
        assert_allclose(C[k], ref, rtol=0, atol=1e-9)
    # analytic: a pure scale error s gives X' = X / (1 + s)
    s = 2.5e-3
    scale = AxisErrorModel.from_components(scale={"x": s, "y": -s, "z": s})
    assert_allclose(scale.compensate(P), P / (1 + np.array([s, -s, s])), rtol=0, atol=1e-12)
    # the paper's first-order X - E(X) is off by about E * dE/dX
    first = P - model.error(P)
    assert np.abs(first - C).max() > 1e-6


def test_zero_model_returns_the_input_exactly():
    P = np.random.default_rng(2).uniform(-1e3, 1e3, (100, 3))
    C = AxisErrorModel.zero().compensate(P)
    assert np.array_equal(C, P) and C is not P


def test_compensation_fails_for_a_standing_slide():
    model = AxisErrorModel.from_components(scale={"x": -1.0})
    with pytest.raises(ComputationError, match="singular Jacobian|did not converge"):
        model.compensate([[10.0, 0.0, 0.0]])


def test_work_offset_shift_and_dict_round_trip():
    model = paper_like_model()
    o = np.array([-250.0, -150.0, -300.0])
    prog = model.in_program_coordinates(o)
    P = np.random.default_rng(4).uniform(0, 100, (30, 3))
    assert_allclose(prog.error(P), model.error(P + o), rtol=0, atol=1e-15)
    back = AxisErrorModel.from_dict(model.to_dict())
    assert_allclose(back.error(P), model.error(P), rtol=0, atol=0)


def test_volumetric_map_of_a_scale_error():
    """Pure scale errors s: |E| = |s * X|, largest at the far corner."""
    model = AxisErrorModel.from_components(scale={"x": 1e-4, "y": 2e-4, "z": -3e-4})
    vm = volumetric_map(model, envelope=[[0, 100], [0, 50], [-40, 0]], shape=(5, 6, 3))
    assert vm.error.shape == (5, 6, 3, 3)
    corner = np.array([100 * 1e-4, 50 * 2e-4, -40 * -3e-4])
    assert vm.stats["max_mm"] == pytest.approx(np.linalg.norm(corner), abs=1e-15)
    assert_allclose(vm.stats["max_at_mm"], [100, 50, -40])
    assert_allclose(vm.stats["max_component_mm"], np.abs(corner), atol=1e-15)
    assert_allclose(vm.axes[1], np.linspace(0, 50, 6))


# -------------------------------------------------------------- simulated machine
def bear_points():
    prog, _ = parse_gcode(read_gcode(BEAR), source=BEAR)
    return prog.endpoints(known_only=True)


def test_validation_with_the_true_model_leaves_no_error():
    """Fitted model = the machine's true (polynomial) model: measured without noise the fit
    is exact, and the positional error of bear.nc's 15158 points drops from 537 um max /
    312 um RMS to 5e-12 mm max (the Newton tolerance)."""
    machine = SimulatedMachine(paper_like_model())
    fit = fit_axis_errors(machine.measure(measure_positions()))
    pts = bear_points()
    assert pts.shape == (15158, 3)
    v = validate(fit, machine, pts)
    assert 0.53 < v["before"]["max_mm"] < 0.54
    assert 0.31 < v["before"]["rms_mm"] < 0.32
    assert v["after"]["max_mm"] < 1e-9
    assert v["reduction"] > 1 - 1e-8


def test_validation_with_noise_and_a_periodic_error_leaves_only_the_fit_error():
    """A machine with a 2 um periodic ball-screw error on X (pitch 5 mm, not a polynomial)
    measured with 1 um noise: the residual after compensation is exactly the difference
    between the true and the fitted error at the commands, E_true(X') - E_fit(X').
    bear.nc: before max 537 um / RMS 312 um, after max 2.8 um / RMS 1.5 um (99.5 % less);
    the X positions (every 4.55 mm) do not alias with the 5 mm screw pitch."""
    def screw(t):
        e = np.zeros((t.size, 3))
        e[:, 0] = 0.002 * np.sin(2 * np.pi * t / 5.0)
        return e

    machine = SimulatedMachine(paper_like_model(), extra={"x": screw})
    data = machine.measure({"x": np.linspace(0, 100, 23), "y": np.linspace(0, 100, 21),
                            "z": np.linspace(-50, 0, 11)}, noise=0.001, seed=42)
    fit = fit_axis_errors(data, model="auto")
    pts = bear_points()
    v = validate(fit, machine, pts)
    cmd = fit.compensate(pts)
    residual = machine.actual(cmd) - pts
    # (up to the Newton tolerance of the compensation, 1e-10 mm)
    assert_allclose(residual, machine.error(cmd) - fit.error(cmd), rtol=0, atol=2e-10)
    assert v["before"]["rms_mm"] > 0.3
    assert v["after"]["rms_mm"] < 0.002
    assert v["after"]["max_mm"] < 0.004
    assert v["reduction"] > 0.99
    # the fit residuals are what the 1-D functions cannot represent: noise and the screw
    fx = [f for f in fit.fits if f.name == "delta_x(x)"][0]
    assert 0.0012 < fx.rms < 0.0022


def test_measure_keeps_the_other_slides_at_the_reference():
    model = AxisErrorModel.from_components(scale={"y": 1e-3}, squareness={"xy": 2e-4},
                                           reference=(5.0, 7.0, 0.0))
    data = SimulatedMachine(model).measure({"x": np.array([5.0, 15.0])})
    p, e = data["x"]
    # Y's scale error does not show: Y stands at its reference; xy squareness does
    assert_allclose(e, [[0, 0, 0], [0, 2e-3, 0]], atol=1e-15)
    assert error_stats(e)["max_mm"] == pytest.approx(2e-3)


# ---------------------------------------------------------------------- CSV input
def test_long_layout_with_units_comments_and_any_column_order(tmp_path):
    f = tmp_path / "err.csv"
    f.write_text("# laser run 2026-01-12\n"
                 "Position[mm];EZ[um];AXIS;ex[um];ey[um]\n"
                 "0;0;x;0;0\n"
                 "100;1.5;X;12;-3\n"
                 "\n"
                 ";;;;\n"
                 "// Z next\n"
                 "-50;-17;z;2;0.5\n"
                 "0;0;Z;0;0\n", encoding="utf-8")
    t = read_axis_errors(str(f))
    assert t.layout == "long"
    assert t.rows() == {"x": 2, "z": 2}
    assert_allclose(t.data["x"][1], [[0, 0, 0], [0.012, -0.003, 0.0015]], atol=1e-15)
    assert_allclose(t.data["z"][0], [-50, 0])
    assert_allclose(t.data["z"][1][0], [0.002, 0.0005, -0.017], atol=1e-15)
    assert t.lines["z"].tolist() == [8, 9]


def test_table_layout_several_tables_pooled_runs(tmp_path):
    f = tmp_path / "tables.txt"
    f.write_text("X(in)\tEXX\tEYX\tEZX\n"
                 "0\t0\t0\t0\n"
                 "1\t0.001\t0\t-0.002\n"
                 "Z EXZ[um] EYZ[um] EZZ[um]\n"
                 "-10 1 2 3\n"
                 "0   0 0 0\n"
                 "X EXX EZX\n"          # a second X run, without EYX
                 "50 0.004 0.001\n", encoding="utf-8")
    t = read_axis_errors(str(f))
    assert t.layout == "tables"
    assert_allclose(t.data["x"][0], [0, 25.4, 50])
    # the second run did not measure EYX: not measured (NaN) there, not a zero
    assert_allclose(t.data["x"][1], [[0, 0, 0], [0.001, 0, -0.002], [0.004, np.nan, 0.001]])
    assert t.warnings == []
    assert_allclose(t.data["z"][1][0], [0.001, 0.002, 0.003], atol=1e-15)
    assert t.lines["x"].tolist() == [2, 3, 8]


def test_tables_that_leave_columns_out_fit_what_they_measured(tmp_path):
    """One X run gives EXX, another EYX: delta_x(x) is 100 um/m and delta_y(x) 20 um/m,
    each from its own 3 rows (not halved by the other run's rows read as zeros); EZX, in
    no table, is 0 at all 6 rows, with a warning."""
    f = tmp_path / "runs.txt"
    f.write_text("X EXX\n0 0\n100 0.010\n200 0.020\nX EYX\n0 0\n100 0.002\n200 0.004\n")
    t = read_axis_errors(str(f))
    assert np.isnan(t.data["x"][1][3:, 0]).all() and np.isnan(t.data["x"][1][:3, 1]).all()
    assert_allclose(t.data["x"][1][:, 2], np.zeros(6), atol=0)
    assert t.warnings == ["%s: EZX in no table, taken as 0 (no error measured, none "
                          "compensated)" % f]
    m = fit_axis_errors(t.data)
    assert_allclose(m.slope[0], [1e-4, 2e-5, 0.0], rtol=1e-9, atol=1e-15)
    assert [fit.n for fit in m.fits] == [3, 3, 6]


@pytest.mark.parametrize("text, where, what", [
    ("axis,position,ex,ey,ez,temp\nX,0,0,0,0\n", ":1:6:", "unknown column 'temp'"),
    ("axis,position,ex,ey\nX,0,0,0\n", ":1:", "missing column(s) ez"),
    ("axis,position,ex,ey,ez\nX,0,0,0,0\nQ,1,0,0,0\n", ":3:1:", "axis 'Q'"),
    ("axis,position,ex,ey,ez\nX,0,0,0,0\nX,1,0,0,1,5\n", ":3:", "6 fields, expected 5"),
    ("axis,position,ex[um],ey,ez\nX,0,1e,0,0\n", ":2:3:", "ex: '1e' is not a number"),
    ("axis,position,ex[furlong],ey,ez\n", ":1:3:", "unknown unit 'furlong'"),
    ("X EXX EYY EZX\n0 0 0 0\n", ":1:3:", "column 'EYY' belongs to slide Y"),
    ("X EXX EYX EZX\n0 0 0 0\n1 0 0,5 0\n", ":3:3:", "not a number"),
    ("pos ex\n1 2\n", ":1:", "unknown header"),
    ("axis,position,ex,ey,ez\n# nothing\n", ":2:", "no data rows"),
])
def test_csv_errors_name_file_line_column(tmp_path, text, where, what):
    f = tmp_path / "bad.csv"
    f.write_text(text, encoding="utf-8")
    with pytest.raises(MeasurementFileError) as exc:
        read_axis_errors(str(f))
    msg = str(exc.value)
    assert msg.startswith(str(f) + where), msg
    assert what in msg


def test_csv_write_read_round_trip(tmp_path):
    data = SimulatedMachine(paper_like_model()).measure(measure_positions(), noise=1e-3)
    (tmp_path / "sub").mkdir()
    path = tmp_path / "sub" / "m.csv"
    write_axis_errors(str(path), data, units="um")
    assert format_axis_errors(data, "um").splitlines()[0] == \
        "axis,position[mm],ex[um],ey[um],ez[um]"
    t = read_axis_errors(str(path))
    for ax in "xyz":
        assert_allclose(t.data[ax][0], data[ax][0], atol=1e-6)
        assert_allclose(t.data[ax][1], data[ax][1], rtol=1e-8, atol=1e-12)


def test_csv_round_trip_keeps_what_a_table_did_not_measure(tmp_path):
    """A column a table left out is NaN; write_axis_errors writes it as an empty field,
    which the long form reads as not measured again: the same data, the same fit (it wrote
    'nan', which the reader refused)."""
    src = tmp_path / "runs.txt"
    src.write_text("X EXX\n0 0\n100 0.010\n200 0.020\nX EYX\n0 0\n100 0.002\n200 0.004\n")
    t = read_axis_errors(str(src))
    out = tmp_path / "long.csv"
    write_axis_errors(str(out), t.data, units="um")
    text = out.read_text()
    assert "nan" not in text.lower()
    assert text.splitlines()[1:3] == ["X,0.000000,0,,0", "X,100.000000,10,,0"]
    back = read_axis_errors(str(out))
    assert back.layout == "long" and back.warnings == []
    assert_allclose(back.data["x"][0], t.data["x"][0])
    assert_allclose(back.data["x"][1], t.data["x"][1], rtol=1e-12, atol=1e-15)   # NaN too
    assert back.lines["x"].tolist() == [2, 3, 4, 5, 6, 7]
    assert_allclose(fit_axis_errors(back.data).slope[0], fit_axis_errors(t.data).slope[0],
                    rtol=1e-9, atol=1e-15)
    assert [fit.n for fit in fit_axis_errors(back.data).fits] == [3, 3, 6]


def test_long_form_empty_fields_and_what_cannot_be_written(tmp_path):
    f = tmp_path / "e.csv"
    f.write_text("axis,position,ex,ey,ez\nX,0,0.001,,\nX,100,,0.002,\n")
    t = read_axis_errors(str(f))
    assert_allclose(t.data["x"][1], [[0.001, np.nan, 0.0], [np.nan, 0.002, 0.0]])
    # ez is in no row: taken as 0, with a warning that says so
    assert t.warnings == ["%s: EZX in no row, taken as 0 (no error measured, none "
                          "compensated)" % f]
    f.write_text("axis,position,ex,ey,ez\nX,0,0,0,0\nX,100,,,\n")
    with pytest.raises(MeasurementFileError, match=r"e\.csv:3: no error in this row"):
        read_axis_errors(str(f))
    f.write_text("axis,position,ex,ey,ez\nX,,0,0,0\n")
    with pytest.raises(MeasurementFileError, match=r"e\.csv:2:2: position: '' is not a number"):
        read_axis_errors(str(f))
    for bad in ({"x": ([0.0], [[np.inf, 0.0, 0.0]])}, {"x": ([np.nan], [[0.0, 0.0, 0.0]])},
                {"x": ([0.0], [[np.nan, np.nan, np.nan]])}):
        with pytest.raises(InputError, match="axis X, row 1"):
            write_axis_errors(str(tmp_path / "w.csv"), bad)
    assert not (tmp_path / "w.csv").exists()
