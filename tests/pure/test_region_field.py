# SPDX-License-Identifier: LGPL-2.1-or-later
"""The region's filter and field in space (issue 30): invariants and reference values."""

import math

import numpy as np
import pytest

from surfcomp.core.compensation import region_build, region_field
from surfcomp.errors import MeasurementFileError
from tests.pure.surfaces import cube_corner_edges


def _grid(n=41, step=0.5):
    x, y = np.meshgrid(np.arange(n) * step, np.arange(n) * step, indexing="ij")
    return np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)


def test_spacing_of_a_grid():
    assert region_field.spacing(_grid()) == pytest.approx(0.5, abs=1e-12)


def test_constant_passes_the_mask_filter_unchanged():
    p = _grid()
    for kind in ("box", "gaussian"):
        out = region_field.mask_filter_3d(p, np.full(len(p), 0.0123), 5, kind)
        np.testing.assert_allclose(out, 0.0123, atol=1e-15)


def test_box_filter_is_the_mean_over_the_ball():
    p = _grid(11)
    d = np.zeros(len(p))
    centre = 5 * 11 + 5
    d[centre] = 1.0
    out = region_field.mask_filter_3d(p, d, 5, "box")
    # a ball of radius 2.5 steps holds 21 grid nodes (|i|^2 + |j|^2 <= 6.25)
    assert out[centre] == pytest.approx(1.0 / 21.0, abs=1e-15)
    assert out[centre + 3 * 11] == 0.0          # 3 steps away: outside the ball


def test_mask_one_keeps_the_deviations():
    p = _grid(5)
    d = np.arange(len(p), dtype=float)
    np.testing.assert_array_equal(region_field.mask_filter_3d(p, d, 1), d)


def test_field_reproduces_a_constant_and_a_plane_in_the_middle():
    p = _grid()
    f = region_field.RegionField(p, np.full(len(p), 0.02), radius=2.0)
    x = np.array([[3.3, 7.1, 0.0], [10.0, 10.0, 0.0], [-50.0, 0.0, 0.0]])
    np.testing.assert_allclose(f(x), 0.02, atol=1e-15)
    lin = region_field.RegionField(p, 1e-3 * p[:, 0], radius=2.0)
    # a kernel average reproduces a linear field away from the border, up to the shift of
    # the kernel centres gathered in cells of R / 3 (0.67 mm at 1 um/mm: below 0.1 um)
    assert lin(np.array([[10.0, 10.0, 0.0]]))[0] == pytest.approx(0.010, abs=1e-4)


def test_field_is_one_function_of_position_and_continuous():
    rng = np.random.default_rng(0)
    p = rng.uniform(0, 10, (4000, 3))
    f = region_field.RegionField(p, np.sin(p[:, 0]) * 1e-2, radius=1.5)
    x = rng.uniform(2, 8, (200, 3))
    h = 1e-6
    dx = np.abs(f(x + [h, 0, 0]) - f(x))
    assert np.max(dx) <= 1e-2 * 10 * h     # Lipschitz: no jump anywhere sampled
    np.testing.assert_array_equal(f(x), f(x.copy()))


def test_assign_nearest_face_and_no_face():
    dist = np.array([[0.1, np.inf, 0.5, 2.0], [0.2, 0.05, np.nan, 3.0]])
    np.testing.assert_array_equal(region_field.assign(dist, 1.0), [0, 1, 0, -1])


def test_coverage_share():
    samples = _grid(11, 1.0)
    pts = samples[samples[:, 0] < 4.5]
    assert region_field.coverage(samples, pts, 0.1) == pytest.approx(5 / 11, abs=1e-12)
    assert region_field.coverage(samples, pts[:0], 0.1) == 0.0


def test_straddle_refused_with_lines_and_faces():
    p = _grid(21, 0.5)
    face = (p[:, 0] > 5.0).astype(int)
    d = np.where(face == 1, 0.3, 0.0)
    edge = np.stack([np.full(50, 5.0), np.linspace(0, 10, 50), np.zeros(50)], axis=1)
    lines = np.arange(1, len(p) + 1)
    with pytest.raises(MeasurementFileError, match="between FaceA and FaceB differ by 0.3000"):
        region_field.check_straddle(p, d, face, [(0, 1, edge)], 1.25, 0.2, lines, "m.csv",
                                    ["FaceA", "FaceB"])
    region_field.check_straddle(p, d, face, [(0, 1, edge)], 1.25, 0.5, lines, "m.csv",
                                ["FaceA", "FaceB"])


def test_miter_has_unit_normal_components():
    na = np.array([[0.0, 0.0, 1.0]])
    nb = np.array([[1.0, 0.0, 0.0]])
    m, exact = region_build.miters(na, nb, np.array([[1.0, 0, 0]]), np.array([[0, 0, 1.0]]))
    assert exact[0] == 1.0
    np.testing.assert_allclose(m @ na[0], 1.0, atol=1e-15)
    np.testing.assert_allclose(m @ nb[0], 1.0, atol=1e-15)
    # a knife edge (opposite normals) gets a shortened miter along its bisector
    m, exact = region_build.miters(na, -na, np.array([[1.0, 0, 0]]), np.array([[1.0, 0, 0]]))
    assert exact[0] == 0.0
    np.testing.assert_allclose(m[0], [-2.0, 0.0, 0.0], atol=1e-12)
    # between 90 and 120 deg the miter is still exact, its exactness falls smoothly
    nc = np.array([[math.sin(math.radians(105.0)), 0.0, math.cos(math.radians(105.0))]])
    m, exact = region_build.miters(na, nc, np.array([[1.0, 0, 0]]), np.array([[0, 0, 1.0]]))
    np.testing.assert_allclose([m[0] @ na[0], m[0] @ nc[0]], 1.0, atol=1e-12)
    assert exact[0] == pytest.approx(0.5, abs=1e-12)


def test_displacement_same_on_both_faces_at_a_sharp_edge():
    na, nb = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    edge = np.stack([np.zeros(50), np.linspace(0, 10, 50), np.zeros(50)], axis=1)
    m, c = region_build.miters(np.tile(na, (50, 1)), np.tile(nb, (50, 1)),
                               np.tile([-1.0, 0, 0], (50, 1)), np.tile([0, 0, -1.0], (50, 1)))
    sharp = region_build.SharpEdges(edge, m, c, np.zeros(50, int), band=1.0)
    x = np.array([[0.0, 3.3, 0.0]])
    delta = np.array([0.02])
    da = region_build.displacement(x, na[None], delta, sharp)
    db = region_build.displacement(x, nb[None], delta, sharp)
    np.testing.assert_allclose(da, db, atol=1e-15)
    np.testing.assert_allclose(da[0], [-0.02, 0.0, -0.02], atol=1e-15)
    # inside a face, the normal component is the correction
    y = np.array([[-0.5, 3.3, 0.0], [-2.0, 3.3, 0.0]])
    dy = region_build.displacement(y, np.tile(na, (2, 1)), np.full(2, 0.02), sharp)
    np.testing.assert_allclose(dy @ na, -0.02, atol=1e-15)
    np.testing.assert_allclose(dy[1], [0.0, 0.0, -0.02], atol=1e-15)


def _cube_corner(band=2.0):
    """The cube corner's sharp edges (:func:`tests.pure.surfaces.cube_corner_edges`) with
    their vertex, and the faces' normals."""
    from surfcomp.core.compensation import region_edges

    (pts, mit, ex, eid, nrm), n = cube_corner_edges()
    mit, ex = region_edges.at_vertices(pts, mit, ex, eid, nrm, 0.5 * band,
                                       region_edges.knife_limit(region_build.MITER_ANGLE), 1e-6)
    return region_edges.SharpEdges(pts, mit, ex, eid, band), n


def test_a_vertex_moves_alike_from_every_face():
    sharp, n = _cube_corner()
    delta = np.array([0.02])
    o = np.zeros((1, 3))
    d = [region_build.displacement(o, n[k][None], delta, sharp)[0] for k in "xyz"]
    np.testing.assert_allclose(d[0], d[1], atol=1e-15)
    np.testing.assert_allclose(d[0], d[2], atol=1e-15)
    # the vertex's vector is the least-squares miter of the three faces (moved inwards)
    assert np.all(d[0] > 0.0) and np.allclose(d[0], d[0][0], atol=1e-15)
    # two zones (2 mm) from the vertex, each edge's own miter again: both corrections met
    x = np.array([[5.0, 0.0, 0.0]])
    dy = region_build.displacement(x, n["y"][None], delta, sharp)[0]
    dz = region_build.displacement(x, n["z"][None], delta, sharp)[0]
    np.testing.assert_allclose(dy, dz, atol=1e-15)
    np.testing.assert_allclose([dy @ n["y"], dy @ n["z"]], -0.02, atol=1e-15)


def test_displacement_continuous_where_the_nearest_edge_changes():
    sharp, n = _cube_corner()
    # across the diagonal of the face z = 0, where the edges along x and y are equally near
    s = np.linspace(0.3, 0.7, 4001)
    x = np.stack([s, 1.0 - s, np.zeros_like(s)], axis=1)
    d = region_build.displacement(x, np.tile(n["z"], (len(s), 1)), np.full(len(s), 0.02),
                                  sharp)
    # steps of 1e-4 mm: the displacement changes by 5e-6 mm per step, no jump (the two
    # edges' vectors differ by 0.028 mm, which the nearest edge alone would jump by)
    step = np.linalg.norm(np.diff(d, axis=0), axis=1)
    assert np.max(step) < 1e-5 and np.max(step) < 1.1 * np.median(step)
