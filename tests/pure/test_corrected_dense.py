# SPDX-License-Identifier: LGPL-2.1-or-later
"""The corrected-surface construction on dense grids, where MAX_SPANS caps the pole net.

MAX_SPANS is lowered so that small grids take the dense paths: node-line knots (one
span per grid step) for grids along parameter lines, and at least two spans per step
for grids that cross them. Both must meet the pipeline's requirements on raw, noisy
corrections: realised = intended within 0.1 um at the points, the nominal back within
0.1 um from a zero field, no overshoot over max|intended| + 1 um.
"""

import numpy as np
import pytest

from surfcomp.core.compensation import corrected, corrected_check
from surfcomp.core.compensation.corrected import (
    aligned_lines,
    construct,
    node_line_knots,
    realised_correction,
)
from surfcomp.core.surface import bspline

UM = 1e-3


def bicubic():
    """45 mm bicubic with interior knots (like the bundled example)."""
    k = np.array([0, 0, 0, 0, 0.3, 0.55, 0.8, 1, 1, 1, 1.0])
    x = np.linspace(0, 45, 7)
    X, Y = np.meshgrid(x, x, indexing="ij")
    Z = 4 * np.sin(X / 14) * np.cos(Y / 17) + 0.05 * X
    return bspline.Surface(np.stack([X, Y, Z], axis=-1), k, k, 3, 3)


def grid(n, rotated):
    t = np.linspace(0.02, 0.98, n)
    U, V = np.meshgrid(t, t, indexing="ij")
    if rotated:
        a, c = np.radians(20.0), 0.5
        U, V = (c + 0.68 * ((U - c) * np.cos(a) - (V - c) * np.sin(a)),
                c + 0.68 * ((U - c) * np.sin(a) + (V - c) * np.cos(a)))
    return U, V


@pytest.mark.parametrize("rotated,noise", [(False, 0.002), (True, 0.002), (True, 0.0)])
def test_dense_grid_paths_meet_the_requirements(monkeypatch, rotated, noise):
    """Along parameter lines: knots on the node lines. Across them the ladder: one span
    per grid step for smooth corrections; raw noisy ones overshoot beyond the turned grid
    on every space (measured 8.4, 4.7 and 1.9 um with 1, 1.5 and 2 spans per step, 6.0 um
    on the capped space), so the one closest to the limits is kept: two spans per step."""
    monkeypatch.setattr(corrected, "MAX_SPANS", 80)
    surf = bicubic()
    n = 41
    U, V = grid(n, rotated)
    rng = np.random.default_rng(2)
    delta = 0.03 * np.sin(3 * U) * np.cos(2 * V) + 0.01 + rng.normal(0, 1, U.shape) * noise
    step = 0.96 / (n - 1) * (0.68 if rotated else 1.0)
    built = construct(surf, U, V, delta, 1, step, step, refine=4)
    ch = built.checks
    assert (aligned_lines(U, V, 4) is None) == rotated
    spans = built.corrected.shape[0] - 3
    if not rotated:
        assert spans <= n + 4                         # one per step (+ the nominal's knots)
    elif noise:
        assert 2 * (1 / step) - 2 <= spans <= 2 * (1 / step) + 4
    else:
        assert spans <= (1 / step) + 4                # one span per grid step
    assert ch.max_error_at_points < 0.1 * UM
    assert ch.max_zero_deviation < 0.1 * UM
    # no overshoot inside the measured region; beyond it (the rotated grid leaves wide
    # corners) the continued raw noise rings more with two spans per step than with four:
    # a known limit, reported by the pipeline as a warning (measured 1.9 um here)
    us = np.linspace(0, 1, 201)
    uu, vv = np.meshgrid(us, us, indexing="ij")
    S, Su, Sv = bspline.evaluate_grid(surf, us, us, order=1)
    nrm = np.cross(Su, Sv)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    real = np.einsum("ijk,ijk->ij", S - bspline.evaluate_grid(built.corrected, us, us), nrm)
    s, t = built.field.locate(uu.ravel(), vv.ravel())
    inside = ((s >= 0) & (s <= n - 1) & (t >= 0) & (t <= n - 1)).reshape(uu.shape)
    assert np.abs(real[inside]).max() <= np.abs(delta).max() + 1 * UM
    assert ch.max_realised <= np.abs(delta).max() + (2.5 if rotated else 1) * UM
    # an independent check at the points with a fresh intersection
    real = realised_correction(surf, built.corrected, U.ravel(), V.ravel())
    np.testing.assert_allclose(real, delta.ravel(), atol=0.1 * UM)


def test_node_line_knots_keep_the_nominal_knots_and_fill_the_ends():
    own = [0, 0, 0, 0, 0.3, 0.55, 0.8, 1, 1, 1, 1]
    lines = np.linspace(0.1, 0.9, 17)  # step 0.05
    k = node_line_knots(own, 0.0, 1.0, lines)
    # the lines nearest to 0.3, 0.55, 0.8 are left out (0.3, 0.55, 0.8 are lines)
    assert not np.any(np.isclose(k, 0.3)) and not np.any(np.isclose(k, 0.8))
    np.testing.assert_allclose(k[:2], [0.05, 0.1])     # continued to the border
    assert k.max() == pytest.approx(0.95) and np.all(np.diff(k) > 0)
    assert aligned_lines(*np.meshgrid(lines, lines, indexing="ij"), refine=4) is None  # not dense


def test_check_figures_skip_a_degenerate_edge_not_the_whole_surface():
    """A pole row collapsed to a point (as at a sphere's pole) has no normal there: the
    check figures leave those dense points out instead of turning NaN or losing the rest."""
    nominal = bicubic()
    poles = nominal.poles.copy()
    poles[0, :, :] = poles[0, 3, :]                      # the u = 0 edge is one point
    nominal = bspline.Surface(poles, nominal.knots_u, nominal.knots_v, 3, 3)
    lifted = bspline.Surface(poles + [0.0, 0.0, 0.005], nominal.knots_u, nominal.knots_v, 3, 3)
    u = v = np.array([0.5])
    figures = corrected_check.check_figures(nominal, lifted, nominal, u, v, np.array([0.0]), 1.0,
                                      (5, 5), realised=np.array([0.0]))
    us, vs = corrected_check.dense_parameters(nominal, (5, 5), 4)
    _, Su, Sv = bspline.evaluate_grid(nominal, us[1:], vs, order=1)
    n = np.cross(Su, Sv)
    nz = n[..., 2] / np.linalg.norm(n, axis=-1)
    # the grid's largest is 0.005 max|n_z|; refined between the nodes
    # the figure reaches the face's largest, 0.005 where the normal is vertical (the lift)
    assert 0.005 * np.max(np.abs(nz)) - 1e-12 <= figures.max_realised <= 0.005 + 1e-12
    assert figures.max_realised > 0.004 and figures.max_zero_deviation == 0.0


def test_intersections_stop_after_the_final_small_step(monkeypatch):
    """The realised correction stops a point's Newton iteration after a step from
    |F| < FINAL_STEP (no evaluation to confirm it): the same values as iterating until
    |F| < 1e-12 mm, to 1e-12 mm, with fewer surface evaluations."""
    surf = bicubic()
    poles = surf.poles.copy()
    rng = np.random.default_rng(8)
    poles[..., 2] += rng.normal(0, 0.02, poles.shape[:2])          # up to ~50 um moved
    moved = bspline.Surface(poles, surf.knots_u, surf.knots_v, surf.degree_u,
                            surf.degree_v, surf.weights, surf.u_range, surf.v_range)
    u, v = (a.ravel() for a in np.meshgrid(np.linspace(0, 1, 120), np.linspace(0, 1, 90),
                                           indexing="ij"))
    calls = []
    ders = bspline.derivatives
    monkeypatch.setattr(bspline, "derivatives",
                        lambda *a, **k: (calls.append(a[1].size), ders(*a, **k))[1])
    fast = realised_correction(surf, moved, u, v)
    n_fast, calls[:] = sum(calls), []
    monkeypatch.setattr(corrected_check, "FINAL_STEP", 0.0)
    full = realised_correction(surf, moved, u, v)
    assert np.abs(fast - full).max() <= 1e-12
    assert np.abs(full).max() > 10 * UM
    assert n_fast < sum(calls)


def test_realised_change_is_newtons_to_first_order():
    """The residual iteration's later surfaces get their realised correction from the
    first one's intersections (``realised_change``: one evaluation of the surfaces'
    difference): equal to Newton's on the new surface to second order, within 5e-5 um x
    (move in um)^2 (measured 1.4e-6 um for 0.3 um, 1.1e-4 um for 2.9 um: samples moved
    by raw noise, beyond the iteration's updates of fractions of a um), and a
    construction that iterates returns Newton's own values for the surface it keeps."""
    surf = bicubic()
    U, V = grid(41, True)
    rng = np.random.default_rng(4)
    delta = 0.03 * np.sin(3 * U) * np.cos(2 * V) + 0.01
    frame = corrected_check.NodeFrame(surf, U.ravel(), V.ravel(), 1)
    step = 0.96 / 40 * 0.68
    smp = corrected._Sampling(surf, 1, step, step, 4, per_step=1)
    uu, vv = np.meshgrid(smp.us, smp.vs, indexing="ij")
    samples = 0.03 * np.sin(3 * uu) * np.cos(2 * vv) + 0.01             # up to 40 um
    first = smp.build(samples)
    real = frame.realised(first, guess=delta.ravel())
    for size in (0.1 * UM, 1 * UM):
        after = smp.build(samples + rng.normal(0, size, samples.shape))
        linear = frame.realised_change(first, after, real)
        newton = realised_correction(surf, after, U.ravel(), V.ravel(), guess=real)
        moved = np.abs(newton - real).max() / UM
        assert moved > 2 * size / UM
        assert np.abs(linear - newton).max() <= 5e-5 * moved ** 2 * UM
    step = 0.96 / 40 * 0.68
    noisy = delta + rng.normal(0, 0.002, U.shape)
    built = construct(surf, U, V, noisy, 1, step, step, 4)
    assert built.iterations >= 1
    again = realised_correction(surf, built.corrected, U.ravel(), V.ravel())
    assert abs(np.abs(again - noisy.ravel()).max() - built.checks.max_error_at_points) <= 1e-12
