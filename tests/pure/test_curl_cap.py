# SPDX-License-Identifier: LGPL-2.1-or-later
"""A region's field held short of turning a curl inside out
(core/compensation/curl_cap.py): the curvature of the faces' samples, the soft cap, and the
capped field, one function of the position, that leaves the field as it is where every
radius is well above the correction."""

import numpy as np
import pytest

from surfcomp.core.compensation import curl_cap
from tests.pure.surfaces import quarter_cylinder, sphere_octant


def constant(value):
    return lambda x: np.full(len(np.asarray(x).reshape(-1, 3)), value)


def test_the_curvature_of_a_cylinder_and_a_sphere():
    # the quarter cylinder's Su x Sv points away from its axis: outward 1 makes it convex
    pts, convex, concave = curl_cap.curvature_samples(quarter_cylinder(25.0, 40.0), 1)
    assert np.allclose(np.hypot(pts[:, 0], pts[:, 1]), 25.0)
    assert convex == pytest.approx(np.full(len(pts), 1 / 25.0), rel=1e-9)
    assert np.max(concave) < 1e-12
    _pts, convex, concave = curl_cap.curvature_samples(quarter_cylinder(25.0, 40.0), -1)
    assert np.max(convex) < 1e-12 and concave == pytest.approx(1 / 25.0, rel=1e-9)
    # the sphere: both directions curve alike; the pole (degenerate normal) left out
    both = [curl_cap.curvature_samples(sphere_octant(10.0), s) for s in (1, -1)]
    convex_side = max(both, key=lambda b: np.max(b[1]))
    assert convex_side[1] == pytest.approx(0.1, rel=1e-6)
    assert np.max(convex_side[2]) < 1e-9


def test_the_samples_are_at_most_step_apart_and_keep_the_boundary():
    cyl = quarter_cylinder(25.0, 40.0)
    pts, *_ = curl_cap.curvature_samples(cyl, 1, step=2.0)
    z = np.unique(np.round(pts[:, 2], 9))
    assert np.max(np.diff(z)) <= 2.0 + 1e-9 and 21 <= len(z) <= 26
    pts, *_ = curl_cap.curvature_samples(cyl, 1, keep=lambda U, V: V < 0.5, step=2.0)
    assert np.max(pts[:, 2]) < 20.0


def test_the_soft_cap_is_the_field_below_the_knee_and_below_the_limit_beyond():
    kappa = 1 / 0.012                                 # a 12 um curl
    limit = 1 / kappa                                 # t = |delta| kappa
    delta = np.linspace(-0.05, 0.05, 2001)
    out = curl_cap.soft_cap(delta, kappa)
    below = np.abs(delta) * kappa <= curl_cap.KNEE
    assert np.array_equal(out[below], delta[below])
    assert np.all(np.abs(out) < limit) and np.all(np.sign(out) == np.sign(delta))
    assert np.all(np.diff(out) > 0)                   # monotone: no correction turned round
    # C1 at the knee: the slope on either side of it is 1
    knee = curl_cap.KNEE / kappa
    h = 1e-9
    slope = (curl_cap.soft_cap(knee + h, kappa) - curl_cap.soft_cap(knee, kappa)) / h
    assert slope == pytest.approx(1.0, abs=1e-5)


def test_wide_radii_leave_the_field_as_it_is():
    cyl = quarter_cylinder(25.0, 40.0)
    samples = [curl_cap.curvature_samples(cyl, 1, step=0.5)]
    capped = curl_cap.CappedField(constant(0.03), samples, 0.5, 0.06)
    assert not capped.active
    x = curl_cap.curvature_samples(cyl, 1)[0]
    active, short = capped.capped(x)
    assert np.array_equal(capped(x), np.full(len(x), 0.03))
    assert not active.any() and not short.any()


def test_a_tight_curl_caps_inward_corrections_and_the_cap_fades_with_distance():
    r = 0.012                                         # 12 um radius, corrected 30 um
    curl = quarter_cylinder(r, 40.0)
    samples = [curl_cap.curvature_samples(curl, 1, step=0.1)]
    capped = curl_cap.CappedField(constant(0.03), samples, 0.1, 0.06)
    assert capped.active
    on = curl_cap.curvature_samples(curl, 1)[0]
    held = capped(on)
    # on the curl: below SHARE x the radius (and the limit's SLOPE over the 0.1 mm cell a
    # sample stands for), so 1 - delta kappa stays above about 1 - SHARE
    assert np.all(held > 0.0) and np.all(held < curl_cap.SHARE * r + curl_cap.SLOPE * 0.18)
    active, short = capped.capped(on)
    assert active.all() and short == pytest.approx(0.03 - held)
    # away from the curl the limit grows by SLOPE per mm: 25 mm off it is past the field
    far = on[:5] + [25.0, 0.0, 0.0]
    assert np.array_equal(capped(far), np.full(5, 0.03))
    # along a line away from it the capped field never falls: no new fold of its own
    line = np.array([[0.0, 0.0, 20.0]]) + np.linspace(0, 20, 401)[:, None] * [1.0, 0, 0]
    assert np.all(np.diff(capped(line)) >= -1e-15)
    # an outward correction on the convex curl: nothing to fold, nothing capped
    out = curl_cap.CappedField(constant(-0.03), samples, 0.1, 0.06)
    assert np.array_equal(out(on), np.full(len(on), -0.03))


def test_the_limit_is_taken_only_where_the_cap_can_act_and_alike_there(monkeypatch):
    # two tight curls (12 and 60 um) and a field that falls away from them: the bound of
    # kappa per box is above kappa everywhere, and capping only where the bound lets the
    # field pass the knee gives the same bits as capping everywhere
    samples = [curl_cap.curvature_samples(quarter_cylinder(r, 40.0), 1, step=0.1)
               for r in (0.012, 0.06)]
    samples[1] = (samples[1][0] + [3.0, 1.0, 0.0],) + samples[1][1:]
    capped = curl_cap.CappedField(lambda x: 0.03 - 0.0005 * np.abs(x[:, 0]), samples,
                                  0.1, 0.06)
    lim = capped.inward
    rng = np.random.default_rng(5)
    x = rng.uniform([-30.0, -30.0, -10.0], [30.0, 30.0, 50.0], (20000, 3))
    on = np.concatenate([s[0] for s in samples])
    x[:len(on)] = on + rng.normal(0, 0.5, on.shape)
    kappa = lim(x)
    bound = lim.bound(x)
    assert np.all(bound >= kappa) and np.any(kappa > 0) and np.any(bound == 0)
    raw, out = capped.both(x)
    assert np.array_equal(out, curl_cap.soft_cap(raw, kappa))
    assert np.any(out != raw) and np.any(out == raw)
    # the boxes' bounds kept from the first call are the same in the next
    assert np.array_equal(lim.bound(x[::-1]), bound[::-1])
    # in small blocks (of points, of boxes, of box-sample pairs) the capped field alike, to
    # the bit
    for name, value in (("BLOCK", 64), ("BOX_BLOCK", 5), ("PAIRS", 7)):
        monkeypatch.setattr(curl_cap, name, value)
    small = curl_cap.CappedField(capped.field, samples, 0.1, 0.06)
    y = x[::4]
    assert small.inward.bound(y) == pytest.approx(bound[::4], rel=1e-12)   # other sums
    assert np.array_equal(small.both(y)[1], out[::4])
