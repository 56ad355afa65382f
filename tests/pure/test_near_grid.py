# SPDX-License-Identifier: LGPL-2.1-or-later
"""Near-grid measurement points (staggered rows, a point dropped per row as a plan's reach
check drops them): the grid route either locates the whole face on the grid's map or the
points take the scattered route with the reason stated; never a ComputationError."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.compensation.field import GridField
from surfcomp.core.compensation.pipeline import Options, compensate, prepare
from surfcomp.core.measurement_set import MeasurementSet
from surfcomp.core.simulation import presets
from surfcomp.core.surface import bspline
from surfcomp.core.surface.grid import grid_from_uv
from surfcomp.core.surface.projection import Projector
from surfcomp.errors import GridError


def _staggered(first, last, n, m, shift):
    """Rows of constant v (m of them); every other row shifted along u by ``shift`` and
    its points beyond u = 1 dropped."""
    u, v = np.linspace(first, last, n), np.linspace(first, last, m)
    U, V = np.meshgrid(u, v, indexing="ij")
    U = U + (np.arange(m)[None, :] % 2) * shift
    keep = U.ravel() <= 1.0
    return U.ravel()[keep], V.ravel()[keep]


def _hexagonal():
    """25 points in staggered rows: 3 and 2 points alternating over 10 rows (found as a
    5 x 5 grid of rows of constant u whose v zigzags)."""
    u, v = _staggered(0.011555, 0.988445, 3, 10, 0.107227)
    return u, v


def test_staggered_grid_locates_beyond_its_zigzag_border():
    """The border column's u is 0.011555, 0.118782, 0.5, ...: PCHIP's end slope of u was
    zero there (the three-point slope changes sign), so the map's continuation beyond the
    border stayed at u = 0.011555 and (0, 0.8) could not be located."""
    u, v = _hexagonal()
    assert u.size == 25
    grid = grid_from_uv(u, v)
    assert grid.shape == (5, 5) and grid.rows_from == "rows of constant u on the face"
    field = GridField(u[grid.index], v[grid.index], np.zeros(grid.shape))
    targets = np.array([[0.0, 0.8], [0.0, 0.39], [0.0, 0.0], [1.0, 1.0], [0.3, 0.5]])
    s, t = field.locate(targets[:, 0], targets[:, 1])
    back = field._map(s, t, deriv=False)[0]
    assert_allclose(back, targets, rtol=0, atol=1e-9)
    assert s[0] < 0 and s[1] < 0          # beyond the border column s = 0 (u = 0.011555)
    assert 3.0 < t[0] < 4.0               # between the rows at v = 0.663 and 0.880
    s_grid, t_grid = field.locate_grid(np.linspace(0, 1, 61), np.linspace(0, 1, 61))
    assert np.all(np.isfinite(s_grid)) and np.all(np.isfinite(t_grid))


def _measure(u, v):
    surf, outward = presets.get_preset("mirror2019-s3").surface()
    P = np.array([bspline.evaluate_grid(surf, [a], [b])[0, 0] for a, b in zip(u, v)])
    normal = Projector(surf).project(P).normal * outward
    d = 0.02 * np.sin(3 * u) + 0.01 * np.cos(2 * v)
    return surf, outward, MeasurementSet(nominal=P, normal=normal, deviation=d,
                                         source="<simulated measurement>")


def _corrected(surf, outward, ms, layout):
    prep = prepare(surf, outward, ms, Options(layout=layout))
    comp = compensate(surf, outward, prep, Options(layout=layout))
    s = np.linspace(0.0, 1.0, 21)
    return prep, comp, bspline.evaluate_grid(comp.corrected, s, s)


def test_staggered_rows_with_dropped_points_take_the_scattered_route():
    """3 and 2 points in alternate rows of the s3 preset face (the third point of every
    other row dropped, beyond the face): found as a 5 x 3 grid whose neighbouring rows lie
    0.014 apart in u and a row apart in v. Its map passes the coarse check of prepare but
    cannot be inverted at one of the corrected face's samples: it used to end in 'could not
    locate (u, v) = (0, 0.833333) on the measurement grid' (exit 1); now the compensation
    takes the scattered route, says why, and gives the scattered route's face."""
    u, v = _staggered(0.013118, 0.986882, 3, 6, 0.013929)
    assert u.size == 15 and grid_from_uv(u, v).shape == (5, 3)
    surf, outward, ms = _measure(u, v)
    prep, comp, auto = _corrected(surf, outward, ms, "auto")
    assert comp.prepared.grid.rows_from == "scattered (grid too distorted)"
    assert any("5 x 3 grid found in the points (rows of constant u on the face) is too "
               "distorted for the grid route: could not locate" in w and
               w.endswith("the points are used as a scattered layout") for w in prep.warnings)
    assert comp.checks.max_error_at_points < 1e-4     # mm, the intended correction met
    _, _, scattered = _corrected(surf, outward, ms, "scattered")
    assert_allclose(auto, scattered, rtol=0, atol=1e-12)
    with pytest.raises(GridError, match=r"too distorted for the grid route.*; layout "
                                        r"'scattered' uses the points as they are") as err:
        _corrected(surf, outward, ms, "grid")
    assert err.value.options == ("layout",)       # the command line shows --layout


def test_staggered_rows_too_sheared_for_prepare_take_the_scattered_route():
    """8 and 7 points in alternate rows, found as a 15 x 3 grid (rows 0.018 apart in u):
    the coarse check in prepare already fails; the warning says so, the face is the
    scattered route's."""
    u, v = _staggered(0.017004, 0.982996, 8, 6, 0.017979)
    assert u.size == 45 and grid_from_uv(u, v).shape == (15, 3)
    surf, outward, ms = _measure(u, v)
    prep, comp, auto = _corrected(surf, outward, ms, "auto")
    assert prep.grid.rows_from == "scattered (grid too distorted)"
    assert any("too distorted for the grid route" in w for w in prep.warnings)
    _, _, scattered = _corrected(surf, outward, ms, "scattered")
    assert_allclose(auto, scattered, rtol=0, atol=1e-12)


def test_hexagonal_points_stay_on_the_grid_route_and_agree_with_the_scattered_one():
    """The 5 x 5 staggered grid is located over the whole face: the grid route's corrected
    face lies within 16 um of the scattered route's (a regular 5 x 5 grid's two routes
    differ by 15.2 um on this face and deviation: the mask filter against the smoothing
    fit, most beyond the measured region) and meets the intended correction at the points."""
    u, v = _hexagonal()
    surf, outward, ms = _measure(u, v)
    prep, comp, grid = _corrected(surf, outward, ms, "auto")
    assert prep.grid.shape == (5, 5) and not prep.warnings
    assert comp.checks.max_error_at_points < 1e-4
    _, _, scattered = _corrected(surf, outward, ms, "scattered")
    diff = np.linalg.norm(grid - scattered, axis=-1)
    assert 1e-3 < diff.max() < 0.016                 # mm: the routes differ, but not far


@pytest.mark.parametrize("points", ["hexagonal", "staggered"])
def test_simulate_measures_near_grid_plan_points_by_the_auto_layout(points):
    """The loop measured at near-grid plan points (no longer forced onto the scattered
    route, as compensate --layout auto takes them): the 25 staggered points as their 5 x 5
    grid, the 45 in rows of 8 and 7 as their 15 x 3 grid; both compensate. (The sparse
    grid's mask filter leaves more than the scattered route's smoothing fit would: 2.34
    against 1.97 um with these draws.)"""
    from surfcomp.core.simulation import simulate as sim

    u, v = _hexagonal() if points == "hexagonal" else _staggered(0.009971, 0.990029, 8, 6,
                                                                  0.020939)
    pr = presets.get_preset("mirror2019-s3")
    surf, outward, ms = _measure(u, v)
    res = sim.simulate(surf, outward, sim.MachiningModel(**pr.model), points=ms.nominal,
                       grid=(10, 8), specs=sim.method_specs(["none", "filtered"]), replicas=1,
                       seed=2, between=2)
    assert res.before[0]["grid"].count == u.size
    none, filtered = res.values("none", "std")[0], res.values("filtered", "std")[0]
    assert filtered < (0.8 if points == "hexagonal" else 0.5) * none
    assert max(res.checks["filtered"]) < 1e-4      # mm, the correction met at the points


def test_sheared_grid_that_fails_one_sample_of_the_face_falls_back_at_build_time():
    """15 points in staggered rows of 3 and 2 (found as a 5 x 3 grid, neighbouring rows
    0.05 apart in u and half a row apart in v): prepare's coarse check passes, but Newton
    cycles between two cells at the face sample (0.214286, 0.375) while the corrected face
    is built. It used to end there with exit 1; now the compensation is made again on the
    scattered route and the warning names the sample."""
    u, v = _staggered(0.003688, 0.996312, 3, 6, 0.050439)
    assert u.size == 15
    surf, outward, ms = _measure(u, v)
    prep, comp, auto = _corrected(surf, outward, ms, "auto")
    assert prep.grid.shape == (5, 3)
    assert comp.prepared.grid.rows_from == "scattered (grid too distorted)"
    assert prep.warnings == comp.prepared.warnings == [
        "<simulated measurement>: the 5 x 3 grid found in the points (rows of constant u on the "
        "face) is too distorted "
        "for the grid route: could not locate (u, v) = (0.214286, 0.375) on the measurement "
        "grid; the points are used as a scattered layout"]
    assert comp.checks.max_error_at_points < 1e-4
    _, _, scattered = _corrected(surf, outward, ms, "scattered")
    assert_allclose(auto, scattered, rtol=0, atol=1e-12)
