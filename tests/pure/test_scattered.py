# SPDX-License-Identifier: LGPL-2.1-or-later
"""Scattered deviation fields (surfcomp.core.compensation.scattered): the smoothing fit against
scipy's thin-plate RBF and brute-force leave-one-out, its transfer function against the analytic
one, the Clough-Tocher field against scipy's, bounds, and the corrected face on a 7 x 10
adaptive layout like the mirror-method paper's (mirror-compensation-onmachine.txt: seven
curves along u, ten unevenly spaced points on each, denser where the slope changes)."""

import functools

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.interpolate import CloughTocher2DInterpolator, RBFInterpolator
from scipy.sparse.linalg import spsolve

from examples.make_example import example_surface
from surfcomp.core.compensation import corrected, corrected_check
from surfcomp.core.compensation import scattered as sc
from surfcomp.core.compensation import scattered_field as scf
from surfcomp.core.compensation.pspline import PSplineSolver, tensor_rows
from surfcomp.core.compensation.scattered import ScatteredField, smooth
from surfcomp.core.surface import bspline
from surfcomp.errors import InputError


def werner_like():
    """The bundled example's face: 45 x 45 mm, 7 x 7 poles, bicubic, interior knots."""
    return example_surface()


def mirror_layout(seed=5):
    """7 curves (unevenly spaced v), 10 unevenly spaced points each, denser at small u."""
    rng = np.random.default_rng(seed)
    vs = np.array([0.04, 0.17, 0.33, 0.5, 0.64, 0.8, 0.95])
    U, V = [], []
    t = np.linspace(0.0, 1.0, 10)
    for j, v in enumerate(vs):
        u = 0.03 + 0.94 * t ** (1.6 if j < 4 else 1.2)
        u = u + rng.uniform(-0.01, 0.01, 10) * (t > 0) * (t < 1)
        U.append(u)
        V.append(np.full(10, v) + rng.uniform(-0.005, 0.005, 10))
    return np.concatenate(U), np.concatenate(V)


def systematic(u, v):
    """A smooth systematic correction (mm): offset, tilt, bow and a slow wave."""
    return 0.03 + 0.02 * (u - 0.5) - 0.06 * (v - 0.5) ** 2 + 0.01 * np.sin(3 * u) * v


# ------------------------------------------------------------------ smoothing fit
@pytest.mark.parametrize("ell", [0.0, 0.15])
def test_rippa_loo_equals_brute_force_refits(ell):
    rng = np.random.default_rng(0)
    x = rng.random((40, 2))
    d = np.sin(3 * x[:, 0]) + x[:, 1] ** 2 + rng.normal(0, 0.05, 40)
    loo = sc.loo_residuals(x[:, 0], x[:, 1], d, ell)
    s = sc.tps_smoothing_parameter(40, float(np.prod(np.ptp(x, axis=0))), ell)
    brute = np.array([d[k] - RBFInterpolator(np.delete(x, k, 0), np.delete(d, k),
                                             kernel="thin_plate_spline", smoothing=s)(x[k:k + 1])[0]
                      for k in range(40)])
    assert np.max(np.abs(brute)) > 0.05  # a real check, not all zeros
    assert_allclose(loo, brute, atol=1e-9)
    fit = smooth(x[:, 0], x[:, 1], d, ell)
    assert_allclose(fit.loo_rms, np.sqrt(np.mean(brute ** 2)), atol=1e-9)
    assert_allclose(fit.loo_max, np.max(np.abs(brute)), atol=1e-9)
    # the determined part is scipy's thin-plate smoothing spline at the points
    ref = RBFInterpolator(x, d, kernel="thin_plate_spline", smoothing=s)(x)
    assert_allclose(fit.determined, ref, atol=1e-10)
    assert_allclose(fit.determined + fit.random, d, atol=1e-15)


def test_pspline_loo_equals_brute_force_refits():
    rng = np.random.default_rng(1)
    x = rng.random((150, 2)) * [30.0, 10.0]
    d = 0.01 * np.sin(x[:, 0] / 5) * np.cos(x[:, 1] / 4) + rng.normal(0, 0.002, 150)
    solver = PSplineSolver(x, d, x.min(axis=0), x.max(axis=0))
    rho = 0.3
    resid, loo, _ = solver.solve(rho)
    B = tensor_rows(solver.ku, solver.kv, solver.nu, solver.nv, x).toarray()
    for k in range(0, 150, 7):
        keep = np.arange(150) != k
        c = np.linalg.solve(B[keep].T @ B[keep] + rho * solver.J, B[keep].T @ d[keep])
        assert_allclose(loo[k], d[k] - B[k] @ c, atol=1e-12)
    c = np.linalg.solve(B.T @ B + rho * solver.J, B.T @ d)
    assert_allclose(resid, d - B @ c, atol=1e-12)


@pytest.mark.parametrize("method", ["tps", "pspline"])
def test_smoothing_length_is_the_halved_wavelength(method):
    # analytic transfer 1 / (1 + (ell / L)^4) of the penalised fit for dense data
    L = 20.0
    g = np.linspace(0.0, 60.0, 31)
    uu, vv = np.meshgrid(g, g, indexing="ij")
    u, v = uu.ravel(), vv.ravel()
    d = np.sin(2 * np.pi * u / L)
    inner = (u > 15) & (u < 45) & (v > 15) & (v < 45)
    for ell in (L / 2, L, 2 * L):
        f = smooth(u, v, d, ell, method=method)
        gain = np.sum(f.determined[inner] * d[inner]) / np.sum(d[inner] ** 2)
        assert_allclose(gain, 1 / (1 + (ell / L) ** 4), atol=0.02)


def test_gcv_smoothing_recovers_systematic_field_better_than_raw():
    rng = np.random.default_rng(3)
    x = rng.random((800, 2)) * [80.0, 40.0]          # mm
    truth = 0.02 * np.sin(x[:, 0] / 12) * np.cos(x[:, 1] / 9) + 0.0003 * x[:, 0]
    noise = rng.normal(0, 0.003, 800)
    d = truth + noise
    raw_err = np.sqrt(np.mean(noise ** 2))           # 3.07 um
    for method in ("tps", "pspline"):
        f = smooth(x[:, 0], x[:, 1], d, method=method)
        err = np.sqrt(np.mean((f.determined - truth) ** 2))
        assert f.chosen_by == "gcv" and f.method == method
        assert err < 0.3 * raw_err                   # measured: 0.69 um (tps), 0.67 um (pspline)
        assert_allclose(f.noise_rms, 0.003, rtol=0.05)
        assert_allclose(f.fit_rms, np.sqrt(np.mean(f.random ** 2)), atol=1e-15)
        assert f.fit_rms < f.loo_rms < 1.1 * raw_err
        assert 10 < f.smoothing < 25                 # measured: 15.3 mm (tps), 16.6 mm (pspline)
    # same smoothing length, both methods give nearly the same field
    a = smooth(x[:, 0], x[:, 1], d, 15.0, method="tps")
    b = smooth(x[:, 0], x[:, 1], d, 15.0, method="pspline")
    assert_allclose(a.determined, b.determined, atol=0.002)


def test_scale_makes_anisotropic_parameters_isotropic():
    rng = np.random.default_rng(4)
    x = rng.random((120, 2)) * [50.0, 50.0]
    d = 0.01 * np.sin(x[:, 0] / 8) + 0.005 * np.cos(x[:, 1] / 6) + rng.normal(0, 0.002, 120)
    ref = smooth(x[:, 0], x[:, 1], d)
    # parameters with ranges 1 and 1e-3 (mm per unit parameter 50 and 5e4)
    f = smooth(x[:, 0] / 50.0, x[:, 1] / 5e4, d, scale=(50.0, 5e4))
    assert_allclose(f.determined, ref.determined, atol=1e-9)
    assert_allclose(f.smoothing, ref.smoothing, rtol=1e-6)


def test_constant_and_linear_data_are_reproduced_exactly():
    U, V = mirror_layout()
    for method in ("tps", "pspline"):
        for d in (np.full(U.size, 0.025), 0.01 + 0.02 * U - 0.03 * V):
            f = smooth(U, V, d, 0.3, method=method)
            assert_allclose(f.determined, d, atol=1e-12)
    field = ScatteredField(U, V, np.full(U.size, 0.025), box=((0, 1), (0, 1)))
    uu, vv = np.meshgrid(np.linspace(-0.2, 1.2, 141), np.linspace(-0.2, 1.2, 141), indexing="ij")
    assert_allclose(field(uu, vv), 0.025, atol=1e-16)


# ------------------------------------------------------------------ the field
def test_clough_tocher_parts_equal_scipy():
    rng = np.random.default_rng(0)
    x = rng.random((60, 2))
    f = np.sin(3 * x[:, 0]) + x[:, 1] ** 2
    ip = CloughTocher2DInterpolator(x, f, tol=1e-14, maxiter=100000)
    tri = ip.tri
    # gradients: our sparse system is the functional scipy iterates on
    M, inv, R = scf._gradient_system(x, tri)
    assert_allclose(spsolve(M.tocsc(), R @ f).reshape(-1, 2), ip.grad.reshape(-1, 2), atol=1e-10)
    assert_allclose(np.linalg.inv(inv), M.toarray().reshape(60, 2, 60, 2)[np.arange(60), :,
                                                                         np.arange(60), :],
                    atol=1e-9)
    # patches: same values as scipy's with scipy's gradients
    T, r = scf._transforms(x, tri.simplices)
    assert_allclose(T, tri.transform[:, :2], atol=1e-12)
    q = rng.random((2000, 2)) * 0.8 + 0.1
    s = tri.find_simplex(q)
    q, s = q[s >= 0], s[s >= 0]
    b = np.einsum("mij,mj->mi", T[s], q - r[s])
    coef = scf._ct_coefficients(x, tri.simplices, scf._ct_gfactors(tri, T, r), f[:, None],
                               ip.grad.reshape(-1, 2)[:, :, None])
    val = scf._ct_evaluate(coef, s, np.column_stack([b, 1 - b.sum(axis=1)]))[:, 0]
    assert_allclose(val, ip(q), atol=1e-12)


def test_field_interpolates_and_with_values_equals_a_new_field():
    U, V = mirror_layout()
    rng = np.random.default_rng(2)
    a = systematic(U, V) + rng.normal(0, 0.003, U.size)
    b = systematic(U, V) * 0.5 - 0.01
    fa = ScatteredField(U, V, a, scale=(45.0, 45.0), box=((0, 1), (0, 1)))
    assert_allclose(fa(U, V), a, atol=1e-14)
    uu, vv = np.meshgrid(np.linspace(0, 1, 61), np.linspace(0, 1, 61), indexing="ij")
    loc = fa.locate(uu.ravel(), vv.ravel())
    fb = fa.with_values(b)
    fresh = ScatteredField(U, V, b, scale=(45.0, 45.0), box=((0, 1), (0, 1)))
    assert_allclose(fb.at_index(*loc), fresh(uu, vv).ravel(), atol=1e-13)
    assert_allclose(fa.at_index(*loc), fa(uu, vv).ravel(), atol=0)  # unchanged by with_values
    # two channels at once
    both = ScatteredField(U, V, np.column_stack([a, b]), scale=(45.0, 45.0), box=((0, 1), (0, 1)))
    assert_allclose(both(uu, vv)[..., 1], fresh(uu, vv), atol=1e-13)


def test_noisy_field_is_bounded_and_continuous_everywhere():
    U, V = mirror_layout()
    rng = np.random.default_rng(7)
    vals = 0.02 + rng.normal(0, 0.02, U.size)        # raw, noise-dominated data
    field = ScatteredField(U, V, vals, scale=(45.0, 45.0), box=((0, 1), (0, 1)))
    g = np.linspace(-0.5, 1.5, 801)                  # the face box and far beyond
    uu, vv = np.meshgrid(g, g, indexing="ij")
    f = field(uu, vv)
    assert f.max() <= vals.max() + 1e-15 and f.min() >= vals.min() - 1e-15
    assert np.max(np.abs(f)) <= np.max(np.abs(vals)) + 1e-15
    # continuous (Lipschitz): along lines in u and v, halving the sample step halves the
    # largest difference between neighbouring samples (a jump would not shrink)
    lines = np.linspace(-0.3, 1.3, 17)
    steps = []
    for k in (2001, 4001):
        t = np.linspace(-0.5, 1.5, k)
        a, b = np.meshgrid(t, lines, indexing="ij")
        steps.append(max(np.max(np.abs(np.diff(field(a, b), axis=0))),
                         np.max(np.abs(np.diff(field(b, a), axis=0)))))
    assert steps[0] < 0.02 * np.ptp(vals) and steps[1] < 0.55 * steps[0]
    # smooth data: the field follows the systematic field between the points
    sm = ScatteredField(U, V, systematic(U, V), scale=(45.0, 45.0), box=((0, 1), (0, 1)))
    inside = (uu > 0.1) & (uu < 0.9) & (vv > 0.1) & (vv < 0.9)
    assert np.max(np.abs(sm(uu, vv) - systematic(uu, vv))[inside]) < 0.0015


def test_bad_inputs_are_refused():
    U, V = mirror_layout()
    with pytest.raises(InputError, match="points 0 and 70 have the same"):
        ScatteredField(np.r_[U, U[0]], np.r_[V, V[0]], np.zeros(71))
    with pytest.raises(InputError, match="lie on one line"):
        ScatteredField(U, 0.3 + 0 * U, np.zeros(U.size))
    with pytest.raises(InputError, match="shape"):
        ScatteredField(U, V, np.zeros(U.size + 1))
    with pytest.raises(InputError, match="finite"):
        smooth(U, V, np.r_[np.nan, np.zeros(U.size - 1)])
    with pytest.raises(InputError, match="smoothing must be a length"):
        smooth(U, V, np.zeros(U.size), -1.0)
    with pytest.raises(InputError, match="scale factors"):
        smooth(U, V, np.zeros(U.size), scale=(1.0, 0.0))


# ------------------------------------------------------------------ the corrected face
@pytest.mark.parametrize("kind", ["raw", "smoothed", "zero"])
def test_mirror_layout_corrected_face_requirements(kind):
    nominal = werner_like()
    U, V = mirror_layout()
    rng = np.random.default_rng(11)
    raw = systematic(U, V) + rng.normal(0, 0.003, U.size)
    if kind == "raw":
        delta = raw
    elif kind == "smoothed":
        fit = smooth(U, V, raw, scale=(45.0, 45.0))
        assert fit.chosen_by == "gcv" and fit.method == "tps"
        # measured: noise 2.48 um (true 3), LOO 3.05 um, fit residual max 4.5 um
        assert 0.0015 < fit.noise_rms < 0.0045 and fit.fit_max < 0.008 and fit.loo_rms < 0.005
        delta = fit.determined
        # 70 points: smoothing halves the error against the systematic field (1.24 vs 2.52 um)
        err = np.sqrt(np.mean((delta - systematic(U, V)) ** 2))
        assert err < 0.6 * np.sqrt(np.mean((raw - systematic(U, V)) ** 2))
    else:
        delta = np.zeros(U.size)
    factory = functools.partial(ScatteredField, scale=(45.0, 45.0),
                                box=(nominal.u_range, nominal.v_range))
    surf, field, _ = corrected.build_matching_surface(nominal, U, V, delta, 1, 0.1, 0.15, 4,
                                                      field_factory=factory)
    assert isinstance(field, ScatteredField)
    real = corrected_check.realised_correction(nominal, surf, U, V, 1, guess=delta)
    assert_allclose(real, delta, atol=1e-4)          # within 0.1 um at the points
    # a check grid 4x denser than the 10 x 7 layout, over the whole face
    us, vs = corrected_check.dense_parameters(nominal, (10, 7), 4)
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    dense = corrected_check.realised_correction(nominal, surf, uu, vv, 1, guess=field(uu, vv))
    assert np.max(np.abs(dense)) <= np.max(np.abs(delta)) + 1e-3   # no overshoot over 1 um
    if kind == "zero":
        S = bspline.evaluate(nominal, uu, vv)
        assert np.max(np.linalg.norm(bspline.evaluate(surf, uu, vv) - S, axis=-1)) < 1e-4
        assert np.max(np.abs(dense)) < 1e-4
    else:
        # the face follows the systematic field between the points (7 x 10 points only;
        # measured max 5.8 um raw, 2.2 um smoothed)
        inside = (uu > 0.1) & (uu < 0.9) & (vv > 0.1) & (vv < 0.9)
        limit = 0.008 if kind == "raw" else 0.003
        assert np.max(np.abs(dense - systematic(uu, vv))[inside]) < limit
