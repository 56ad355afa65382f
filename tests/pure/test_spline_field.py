# SPDX-License-Identifier: LGPL-2.1-or-later
"""The smoothing fit's spline as a correction field (surfcomp.core.compensation.spline_field) and
the corrected face built from it (surfcomp.core.compensation.corrected.construct_smooth): the field
equals the fit at the points, continues C1 and bounded beyond them, and the face realises it
everywhere with the nominal's knots and the field's only."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from examples.make_example import deviation_field, example_surface
from surfcomp.core.compensation import corrected, corrected_check
from surfcomp.core.compensation.pipeline import SMOOTH_MATCH, Options, compensate
from surfcomp.core.compensation.scattered import ScatteredField, smooth
from surfcomp.core.compensation.spline_field import (
    SOFT_LIMIT,
    ConstantField,
    SplineField,
    soft_limit,
)
from surfcomp.core.surface import bspline

SCALE = (45.0, 45.0)   # mm per unit parameter of the example face (45 x 45 mm)


def scattered_set(n, seed=3, lo=0.02, hi=0.98, noise=0.0015):
    """``n`` points scattered over [lo, hi]^2 of the example face with its deviation field
    (Werner-like, -29..+47 um) plus noise, as (u, v, d)."""
    surf = example_surface()
    rng = np.random.default_rng(seed)
    u, v = rng.uniform(lo, hi, n), rng.uniform(lo, hi, n)
    S = bspline.evaluate(surf, u, v)
    return u, v, deviation_field(S[:, 0], S[:, 1]) + rng.normal(0, noise, n)


@pytest.fixture(scope="module")
def fit():
    u, v, d = scattered_set(6000)
    return u, v, smooth(u, v, d, scale=SCALE)


def test_field_is_the_fit_at_the_points(fit):
    u, v, f = fit
    assert f.method == "pspline" and isinstance(f.field, SplineField)
    assert_allclose(f.field(u, v), f.determined, rtol=0, atol=1e-15)
    # the knot grid spans the points' box in face parameters
    assert_allclose(f.field.knots(0)[[0, -1]], [u.min(), u.max()], atol=1e-15)
    assert_allclose(f.field.knots(1)[[0, -1]], [v.min(), v.max()], atol=1e-15)


def test_continuation_is_c1_and_bounded(fit):
    u, v, f = fit
    field = f.field
    edge = u.max()
    for vv in (0.1, 0.5, 0.9):
        h = 1e-6
        left = field(np.array([edge - h, edge - 2 * h]), np.full(2, vv))
        right = field(np.array([edge + h, edge + 2 * h]), np.full(2, vv))
        # value and slope continuous across the border (to the finite-difference error)
        assert abs((left[0] + right[0]) / 2 - field(np.array([edge]), np.array([vv]))[0]) < 1e-12
        assert abs((left[0] - left[1]) / h - (right[1] - right[0]) / h) < 1e-5
    # far beyond the points (the whole (u, v) plane around the face) the field stays
    # within the soft limit of the largest value at the points
    g = np.linspace(-1.0, 2.0, 301)
    uu, vv = np.meshgrid(g, g, indexing="ij")
    top = np.max(np.abs(f.determined))
    assert np.max(np.abs(field(uu, vv))) <= top + SOFT_LIMIT
    # ... and levels off: at most one knot span of the border slope beyond the border value
    width = field.spline.width / field.scale
    at = field(np.full(2, edge), np.array([0.5, 0.5]))[0]
    slope = (at - field(np.array([edge - 1e-6]), np.array([0.5]))[0]) / 1e-6
    far = field(np.array([edge + 10 * width[0]]), np.array([0.5]))[0]
    assert abs(far - at) <= abs(slope) * width[0] * 1.0001


def test_soft_limit():
    f = np.linspace(-0.1, 0.1, 20001)
    out = soft_limit(f, -0.05, 0.05, 1e-3)
    inside = np.abs(f) <= 0.05
    assert np.array_equal(out[inside], f[inside])
    assert np.max(np.abs(out)) <= 0.05 + 1e-3
    # monotone and smooth: slope 1 at the limit, falling to 0 beyond it
    slope = np.diff(out) / np.diff(f)
    assert np.all(slope >= 0) and np.all(slope <= 1 + 1e-9)
    assert slope[np.searchsorted(f, 0.05)] > 0.99


@pytest.mark.parametrize("n", [6000, 40000])
def test_corrected_face_from_the_field(n):
    """The example face, n scattered points: the space is the nominal's knots and the fit's
    (no finer one), and the face realises the field at the points and between them."""
    nominal = example_surface()
    u, v, d = scattered_set(n)
    f = smooth(u, v, d, scale=SCALE)
    built = corrected.construct_smooth(nominal, u, v, f.determined, f.field)
    ch = built.checks
    # every knot of the face is one of the nominal's or of the fit's, and all of the
    # nominal's are there (knot insertion: the space holds the nominal)
    for axis, (built_knots, own) in enumerate(((built.corrected.knots_u, nominal.knots_u),
                                               (built.corrected.knots_v, nominal.knots_v))):
        knots, own = np.unique(built_knots), np.unique(own)
        theirs = f.field.knots(axis)
        dist = np.minimum(np.min(np.abs(knots[:, None] - own), axis=1),
                          np.min(np.abs(knots[:, None] - theirs), axis=1))
        assert np.max(dist) < 1e-12 and np.all(np.isin(own, knots))
    assert ch.poles_shape[0] <= 40 and ch.poles_shape[1] <= 40
    # measured: 0.002 um (6000 points) and 0.003 um (40 000); zero field 2e-11 um
    assert ch.max_error_at_points < 2e-5
    assert ch.max_zero_deviation < 1e-9
    assert ch.max_realised <= ch.max_intended + 1e-3
    # between the points too: the face's correction on a dense grid is the field's
    g = np.linspace(0.0, 1.0, 161)
    uu, vv = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    want = f.field(uu, vv)
    real = corrected_check.realised_correction(nominal, built.corrected, uu, vv, guess=want)
    assert np.max(np.abs(real - want)) < 5e-5


def test_degree_two_nominal_gets_a_finer_space():
    """A biquadratic nominal cannot hold the cubic field on the union of the knots: the
    space is split until the limits are met."""
    ex = example_surface()
    knots = np.r_[0, 0, np.linspace(0, 1, 6), 1, 1]
    us = bspline.greville(knots, 2)
    S = bspline.evaluate_grid(ex, us, us)
    quad = bspline.Surface(bspline.interpolate_grid(us, us, S, knots, knots, 2, 2, None),
                           knots, knots, 2, 2)
    u, v, d = scattered_set(6000)
    f = smooth(u, v, d, scale=SCALE)
    built = corrected.construct_smooth(quad, u, v, f.determined, f.field)
    assert corrected.meets_limits(built.checks)
    spans = f.field.spline.spans[0]
    assert built.checks.poles_shape[0] > spans + 2 + 4
    assert built.checks.max_error_at_points < corrected.ACCEPT_TOL


def test_pipeline_uses_the_field_for_filtered_only():
    """``filtered`` on scattered points builds from the fit's spline; ``raw`` (the values at
    the points are not the spline's) through the values, as before."""
    nominal = example_surface()
    u, v, d = scattered_set(1200, noise=0.0005)
    prepared = _prepared(nominal, u, v, d)
    assert prepared.scattered
    comp = compensate(nominal, 1, prepared, Options(method="filtered"))
    delta = comp.correction.delta
    assert isinstance(comp.field, SplineField)
    assert np.max(np.abs(comp.field(prepared.u, prepared.v) - delta)) <= SMOOTH_MATCH
    assert comp.checks.max_error_at_points < 2e-5 and comp.corrected.shape[0] <= 40
    raw = compensate(nominal, 1, prepared, Options(method="raw"))
    assert isinstance(raw.field, ScatteredField)
    assert raw.checks.max_error_at_points < corrected.ACCEPT_TOL
    # a document made before the lean faces (Lean false) recomputes as it did then
    old = compensate(nominal, 1, prepared, Options(method="filtered", lean=False))
    assert isinstance(old.field, ScatteredField)
    assert old.corrected.shape[0] >= corrected.MIN_SPANS + 3


def _prepared(nominal, u, v, d):
    """A scattered :class:`~surfcomp.core.compensation.pipeline.Prepared` of measured points off the
    nominal by ``d`` along its normal."""
    from surfcomp.core.compensation.pipeline import prepare
    from surfcomp.io.measurement_set import MeasurementSet

    P = bspline.evaluate(nominal, u, v)
    N = bspline.normals(nominal, u, v)
    ms = MeasurementSet(measured=P + d[:, None] * N, source="scattered.xyz")
    return prepare(nominal, 1, ms, Options())


@pytest.mark.parametrize("layout", ["grid", "scattered"])
def test_uniform_offset_keeps_the_nominal_knots(layout):
    """``offset`` (one value everywhere) has no knots of its own: the face is the nominal's
    space split until the offset surface meets the limits (the example: 11 x 11 poles,
    against 49 x 49 on the grid's node lines and about 1100 x 1100 through 250 000
    scattered values)."""
    nominal = example_surface()
    if layout == "grid":
        t = np.linspace(0.01, 0.99, 45)
        uu, vv = np.meshgrid(t, t, indexing="ij")
        u, v = uu.ravel(), vv.ravel()
        S = bspline.evaluate(nominal, u, v)
        d = deviation_field(S[:, 0], S[:, 1])
    else:
        u, v, d = scattered_set(1500)
    prepared = _prepared(nominal, u, v, d)
    assert prepared.scattered == (layout == "scattered")
    comp = compensate(nominal, 1, prepared, Options(method="offset"))
    assert isinstance(comp.field, ConstantField)
    assert_allclose(comp.correction.delta, np.mean(d), atol=1e-12)
    ch = comp.checks
    assert ch.poles_shape == (11, 11)
    assert corrected.meets_limits(ch) and ch.max_error_at_points < 2e-5
    old = compensate(nominal, 1, prepared, Options(method="offset", lean=False))
    assert not isinstance(old.field, ConstantField) and old.corrected.shape[0] > 11

