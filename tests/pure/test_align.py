# SPDX-License-Identifier: LGPL-2.1-or-later
"""Rigid alignment before deviations (issue 28): best fit, constraints, 3-2-1, transforms."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from surfcomp.cli.option_flags import flag
from surfcomp.core.compensation.pipeline import Options, prepare
from surfcomp.core.measurement import align
from surfcomp.core.measurement.align_report import AlignOptions, absorbed
from surfcomp.core.measurement.align_report import align as run_align
from surfcomp.core.measurement.align_rps import rps_fit
from surfcomp.core.surface import bspline
from surfcomp.errors import InputError
from surfcomp.io.measurement_set import MeasurementSet
from tests.pure.surfaces import wavy_patch


def plane(origin, eu, ev, size=40.0):
    """A degree-1 plane patch ``origin + s eu + t ev`` (s, t in 0..size)."""
    o, eu, ev = (np.asarray(a, dtype=float) for a in (origin, eu, ev))
    P = np.array([[o, o + size * ev], [o + size * eu, o + size * (eu + ev)]])
    k = np.array([0, 0, 1, 1.0])
    return bspline.Surface(P, k, k, 1, 1)


def on_surface(surf, n, seed):
    rng = np.random.default_rng(seed)
    u = rng.uniform(*surf.u_range, n)
    v = rng.uniform(*surf.v_range, n)
    return bspline.evaluate(surf, u, v), bspline.normals(surf, u, v)


def transform(seed, max_deg=15.0, max_mm=100.0):
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=3)
    angle = np.radians(rng.uniform(0.5, 1.0) * max_deg)
    R = Rotation.from_rotvec(axis / np.linalg.norm(axis) * angle).as_matrix()
    return align.rigid(R, rng.uniform(-1.0, 1.0, 3) * max_mm)


def errors(M_fit, T_true, pts):
    """Rotation error (rad) and largest point error (mm) of a fit over ``pts`` (nominal)."""
    E = M_fit @ T_true
    rot = np.linalg.norm(Rotation.from_matrix(E[:3, :3]).as_rotvec())
    return rot, np.abs(align.apply(E, pts) - pts).max()


def measured(pts, seed, **kw):
    """Points moved into a measuring frame: ``(measured, T)`` with ``T`` measured <- nominal."""
    T = transform(seed, **kw)
    return align.apply(T, pts), T


REF = [align.Reference("Face1", wavy_patch())]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_known_transform_recovered_exactly(seed):
    pts, _n = on_surface(wavy_patch(), 800, seed)
    meas, T = measured(pts, seed)
    fit, _label = align.best_fit(meas, REF)
    rot, dist = errors(fit.matrix, T, pts)
    assert fit.converged
    assert rot <= 1e-6
    assert dist <= 1e-4          # 0.1 um


@pytest.mark.parametrize("noise_seed", [1, 2, 3])
def test_noise_error_within_three_sigma_over_root_n(noise_seed):
    """Each of the six independent directions of the transform error moves the points along
    their normals by an RMS within 3 sigma / sqrt(N): the least-squares error of each
    direction has the standard deviation sigma / sqrt(N) there, so this is a 3-sigma bound
    (the exact linear least-squares solution of the same noise is computed beside it)."""
    surf, N, sigma = wavy_patch(), 3000, 2e-3
    pts, n = on_surface(surf, N, 11)
    noise = np.random.default_rng(noise_seed).normal(0.0, sigma, N)
    meas, T = measured(pts + n * noise[:, None], 13)
    fit, _ = align.best_fit(meas, REF)
    E = fit.matrix @ T
    c = pts.mean(axis=0)
    xi = np.r_[align.apply(E, c[None])[0] - c, Rotation.from_matrix(E[:3, :3]).as_rotvec()]
    J = np.hstack([n, np.cross(pts - c, n)]) / np.sqrt(N)
    _U, S, Vt = np.linalg.svd(J, full_matrices=False)
    unit = sigma / np.sqrt(N)
    modes = np.abs(S * (Vt @ xi)) / unit
    exact = np.abs(S * (Vt @ np.linalg.lstsq(J, -noise / np.sqrt(N), rcond=None)[0])) / unit
    assert modes.max() <= 3.0
    assert exact.max() <= 3.0
    assert np.abs(modes - exact).max() <= 0.5     # Tukey's fit near least squares (95 %)
    assert modes.max() > 0.1                      # the noise did move the fit


def test_noise_mean_offset_of_constrained_fit():
    """Translation along z only on a plane: the fitted offset is the mean of the noise."""
    surf, N, sigma = plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), 2000, 3e-3
    pts, _ = on_surface(surf, N, 5)
    noise = np.random.default_rng(6).normal(0.0, sigma, N)
    meas = pts + [0.0, 0.0, 0.25] + noise[:, None] * [0, 0, 1]
    fit, _ = align.best_fit(meas, [align.Reference("P", surf)], dof=("z",), robust=False)
    assert abs(fit.matrix[2, 3] + 0.25) <= 3 * sigma / np.sqrt(N)
    np.testing.assert_allclose(fit.matrix[2, 3], -0.25 - noise.mean(), atol=1e-9)


def test_five_percent_outliers_do_not_move_the_fit():
    pts, n = on_surface(wavy_patch(), 600, 21)
    rng = np.random.default_rng(22)
    bad = rng.choice(600, 30, replace=False)
    off = pts.copy()
    off[bad] += n[bad] * rng.choice([-1.0, 1.0], 30)[:, None] * 1.0
    meas, T = measured(off, 23)
    fit, _ = align.best_fit(meas, REF)
    rot, _ = errors(fit.matrix, T, pts)
    good = np.setdiff1d(np.arange(600), bad)
    _, dist = errors(fit.matrix, T, pts[good])
    assert dist <= 1e-3          # 1 um
    assert (fit.weight[bad] == 0).all()
    plain, _ = align.best_fit(meas, REF, robust=False)
    assert errors(plain.matrix, T, pts[good])[1] > 10e-3     # least squares alone moves


@pytest.mark.parametrize("degrees, axis", [(30, (0, 0, 1)), (30, (1, 1, 0.3)),
                                            (150, (1, 1, 0.3))])
def test_far_start_converges_after_pre_alignment(degrees, axis):
    """30 degrees off converges; 150 degrees off only with the principal-axes starts."""
    pts, _ = on_surface(wavy_patch(), 500, 31)
    c = pts.mean(axis=0)
    ax = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    R = Rotation.from_rotvec(ax * np.radians(degrees)).as_matrix()
    T = align.rigid(R, c - R @ c + [20.0, -15.0, 10.0])
    meas = align.apply(T, pts)
    fit, label = align.best_fit(meas, REF)
    rot, dist = errors(fit.matrix, T, pts)
    assert fit.converged and rot <= 1e-6 and dist <= 1e-4
    if degrees > 90:
        assert label == "principal axes"
        with pytest.raises(InputError, match="did not converge"):
            align.best_fit(meas, REF, coarse=False)


def test_plane_reference_refused_naming_free_dof():
    surf = plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    pts, _ = on_surface(surf, 300, 41)
    meas = pts + [0.0, 0.0, 0.1]
    ref = [align.Reference("Face3", surf)]
    with pytest.raises(InputError) as exc:
        align.best_fit(meas, ref, coarse=False)
    msg = str(exc.value)
    assert "cannot fix x, y, rz" in msg and "Face3" in msg and "with align_dof z,rx,ry" in msg
    assert "with --align-dof z,rx,ry" in exc.value.shown(flag)     # as the command line says
    with pytest.raises(InputError, match="cannot fix rz"):
        align.best_fit(meas, ref, dof=align.parse_dof("z,rz"))
    fit, _ = align.best_fit(meas, ref, dof=align.parse_dof("z,rx,ry"))
    np.testing.assert_allclose(fit.matrix[2, 3], -0.1, atol=1e-12)


def test_parse_dof():
    assert align.parse_dof("xyz") == ("x", "y", "z")
    assert align.parse_dof("rz") == ("rz",)
    assert align.parse_dof("xy,rz") == ("x", "y", "rz")
    assert align.parse_dof("all") == align.DOF_NAMES
    with pytest.raises(InputError, match="^align_dof 'xq'"):
        align.parse_dof("xq")


def test_deviations_after_alignment_equal_unmoved():
    """Datum face exact, compensated face with a machining error; both moved by the same
    transform: after the fit on the datum, the compensated face's deviations are those of
    the points never moved."""
    datum, comp = wavy_patch(), plane((0, 0, -20), (1, 0, 0), (0, 1, 0), size=45.0)
    dpts, _ = on_surface(datum, 600, 51)
    cpts, cn = on_surface(comp, 400, 52)
    dev = 0.02 + 0.01 * np.sin(cpts[:, 0] / 7.0) + 0.0005 * cpts[:, 1]
    cmeas = cpts + cn * dev[:, None]
    T = transform(53)
    fit, _ = align.best_fit(align.apply(T, dpts), [align.Reference("Datum", datum)])
    moved = align.apply(fit.matrix, align.apply(T, cmeas))
    d_moved = prepare(comp, 1, MeasurementSet(measured=moved), Options()).deviation
    d_never = prepare(comp, 1, MeasurementSet(measured=cmeas), Options()).deviation
    np.testing.assert_allclose(d_moved, d_never, atol=1e-4)
    np.testing.assert_allclose(d_never, dev, atol=1e-9)


def test_absorbed_mean_and_tilt_on_compensated_face():
    surf = plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    pts, _ = on_surface(surf, 500, 61)
    meas = pts + (0.02 + 0.001 * pts[:, 0])[:, None] * [0, 0, 1]
    opts = AlignOptions("bestfit", dof="z,rx,ry")
    after, rec = run_align(meas, opts, [align.Reference("Face1", surf)], compensated=0)
    span = pts[:, 0].max() - pts[:, 0].min()
    mean = 0.02 + 0.001 * pts[:, 0].mean()
    assert abs(rec.absorbed["mean_offset_um"] + mean * 1e3) <= 0.1
    assert abs(rec.absorbed["tilt_um"] - span * 1.0) <= 0.1
    np.testing.assert_allclose(after[:, 2], 0.0, atol=1e-6)
    assert rec.warnings and "absorbed a mean offset" in rec.warnings[0]
    d = rec.as_dict()
    assert d["method"] == "bestfit" and len(d["matrix"]) == 4
    assert d["rms_after_um"]["Face1"] < 1e-3 < d["rms_before_um"]["Face1"]
    flat = absorbed(pts, pts + [0, 0, 0.003], np.tile([0, 0, 1.0], (500, 1)))
    assert flat == pytest.approx({"mean_offset_um": 3.0, "tilt_um": 0.0}, abs=1e-9)


def corner():
    return [align.Reference("A", plane((0, 0, 0), (1, 0, 0), (0, 1, 0))),
            align.Reference("B", plane((0, 0, 0), (1, 0, 0), (0, 0, 1))),
            align.Reference("C", plane((0, 0, 0), (0, 1, 0), (0, 0, 1)))]


def test_rps_three_two_one_on_a_corner():
    pts = np.array([[5, 5, 0], [30, 8, 0], [12, 30, 0], [5, 0, 10], [30, 0, 20], [0, 20, 15.0],
                    [20, 20, 0]])
    T = transform(71, max_deg=5.0, max_mm=2.0)
    meas = align.apply(T, pts)
    spec = {"primary": ["1", "2", "3"], "secondary": [4, 5], "tertiary": [6]}
    fit, idx = rps_fit(meas, spec, corner())
    rot, dist = errors(fit.matrix, T, pts)
    assert rot <= 1e-9 and dist <= 1e-9
    assert list(idx) == [0, 1, 2, 3, 4, 5]
    named = dict(spec, primary={"points": ["p1", "p2", "p3"], "face": "A"})
    ids = ["p%d" % k for k in range(1, 8)]
    with pytest.raises(InputError, match="secondary.*'4'"):
        rps_fit(meas, named, corner(), ids=ids)


def test_rps_collinear_refused():
    pts = np.array([[5, 5, 0], [10, 10, 0], [20, 20, 0], [5, 0, 10], [30, 0, 20], [0, 20, 15.0]])
    spec = {"primary": [1, 2, 3], "secondary": [4, 5], "tertiary": [6]}
    with pytest.raises(InputError, match="collinear"):
        rps_fit(pts, spec, corner())
    with pytest.raises(InputError, match="needs 2 point"):
        rps_fit(pts, {"primary": [1, 2, 3], "secondary": [4], "tertiary": [6]}, corner())


def test_transform_checks_and_work_offset():
    M = align.work_offset([10.0, -5.0, 2.0], 90.0)
    np.testing.assert_allclose(align.apply(M, [[1.0, 0.0, 0.0]]), [[10.0, -4.0, 2.0]],
                               atol=1e-12)
    assert align.check_rigid(M) is not None
    scaled = M.copy()
    scaled[:3, :3] *= 1.0 + 1e-8
    with pytest.raises(InputError, match="not rigid"):
        align.check_rigid(scaled)
    mirror = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(InputError, match="determinant -1"):
        align.check_rigid(mirror)
    # a known transform is applied before the fit
    pts, _ = on_surface(wavy_patch(), 300, 81)
    T = transform(82)
    after, rec = run_align(align.apply(T, pts), AlignOptions(transform=np.linalg.inv(T)), REF)
    np.testing.assert_allclose(after, pts, atol=1e-9)
    assert rec.method == "none"


def test_bad_input_fewer_points_and_no_convergence():
    pts, _ = on_surface(wavy_patch(), 5, 91)
    with pytest.raises(InputError, match="5 point.*6 degrees of freedom"):
        align.best_fit(pts, REF, coarse=False)
    pts, _ = on_surface(wavy_patch(), 300, 92)
    with pytest.raises(InputError, match="did not converge in 1 iterations"):
        align.best_fit(align.apply(transform(93), pts), REF, coarse=False, max_iter=1)



def test_rms_before_is_over_the_points_of_each_face():
    """Each face's "RMS before" is over the points the fit gives it, as its "after" and its
    count are. Before, it was over the faces nearest the points before the fit: on a corner
    moved by (2, -3, 4) mm a point of A near B counted for B, and a face no point was
    nearest before had no figure (printed "nan um before")."""
    s, t = np.random.default_rng(5).uniform(5.0, 35.0, (2, 3, 60))
    zero = np.zeros(60)
    # A: z = 0, B: y = 0, C: x = 0
    P = np.vstack([np.column_stack(c) for c in ((s[0], t[0], zero), (s[1], zero, t[1]),
                                                (zero, s[2], t[2]))])
    shift = np.array([2.0, -3.0, 4.0])
    _after, rec = run_align(P + shift, AlignOptions(method="bestfit"), corner())
    d = rec.as_dict()
    assert d["points"] == {"A": 60, "B": 60, "C": 60}
    assert d["rms_before_um"] == pytest.approx({"A": 4000.0, "B": 3000.0, "C": 2000.0},
                                               abs=1e-6)
    assert max(d["rms_after_um"].values()) < 1e-6


def test_rps_id_that_names_two_points_is_refused():
    """Before: the last point of that id was taken without a word (a file whose ids repeat,
    such as one point name per feature, aligned on whichever point came last)."""
    pts = np.array([[5, 5, 0], [30, 8, 0], [12, 30, 0], [5, 0, 10], [30, 0, 20], [0, 20, 15.0],
                    [20, 20, 0]])
    ids = ["p1", "p2", "p3", "p4", "p5", "p6", "p1"]
    spec = {"primary": ["p1", "p2", "p3"], "secondary": ["p4", "p5"], "tertiary": ["p6"]}
    with pytest.raises(InputError) as exc:
        rps_fit(pts, spec, corner(), ids=ids, source="rps.json")
    assert str(exc.value) == ("rps.json: 3-2-1 primary: the id 'p1' names 2 points of the "
                              "measurement file (points 1, 7; expected an id that names one "
                              "point)")
    _fit, idx = rps_fit(pts, spec, corner(), ids=ids[:6] + ["p7"])    # ids once each
    assert list(idx) == [0, 1, 2, 3, 4, 5]
