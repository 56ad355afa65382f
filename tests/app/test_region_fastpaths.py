# SPDX-License-Identifier: LGPL-2.1-or-later
"""The fast paths of the region route (issue 30, the 200k-point blade bench) against the
plain computation they replace, on the BladeX blade: the field's kernel sums in dense
blocks against the pairs of a sparse distance matrix, the edge normals projected in one
call per face against one call per point set."""

import os

import numpy as np
import pytest
from scipy.spatial import cKDTree

from surfcomp.app import region
from surfcomp.app.region_orient import orient
from surfcomp.core.compensation import region_field
from tests.app import region_parts as rp

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BLADEX = os.path.join(ROOT, "tests", "data", "real", "cad", "BladeX")


@pytest.fixture(scope="module")
def blade():
    import Part

    faces = rp.blade_faces(BLADEX)
    field = rp.around_edge_field(rp.leading_edge(faces))
    parts = [rp.sample_faces([f], k, field, seed=i) for i, (f, k) in
             enumerate(zip(rp.blade_outward(faces), (3000, 3000, 150, 250)))]
    pts, _nrm, dev = (np.concatenate([p[j] for p in parts]) for j in range(3))
    return Part.Compound(faces), pts, dev


def _pair_sums(fld, x, radius):
    """The sums as the sparse distance matrix gives them (the code before the blocks)."""
    m = cKDTree(x).sparse_distance_matrix(fld._tree, radius, output_type="ndarray")
    w = region_field.wendland(m["v"] / radius) * fld.weights[m["j"]]
    return (np.bincount(m["i"], weights=w * fld.values[m["j"]], minlength=len(x)),
            np.bincount(m["i"], weights=w, minlength=len(x)), len(m))


def test_field_block_sums_equal_the_sparse_pairs(blade):
    """6400 points on the blade, the field of the bench's radius rule (5 % of the
    diagonal): at the points, at points 2 mm off them (more candidates per block) and,
    with the fallback kernel 4 R, at points 20 mm away, the block sums equal the sparse
    pairs' within 1e-12 relative; so does the field."""
    shape, pts, dev = blade
    radius = region.FIELD_SHARE * shape.BoundBox.DiagonalLength
    fld = region_field.RegionField(pts, dev, radius)
    off = pts + np.array([0.0, 2.0, 0.0])
    far = pts[::50] + np.array([20.0, 0.0, 0.0])
    for x, r in ((pts, radius), (off, radius), (far, 4.0 * radius)):
        num, den = fld._sums(x, r)
        n0, d0, pairs = _pair_sums(fld, x, r)
        assert pairs > 10 * len(x)            # many centres in reach: a real test
        assert np.max(np.abs(den - d0)) <= 1e-12 * np.max(d0)
        assert np.max(np.abs(num - n0)) <= 1e-12 * np.max(np.abs(n0))
    n0, d0, _ = _pair_sums(fld, pts, radius)
    old = (n0 + region_field.MEAN_WEIGHT * fld.mean) / (d0 + region_field.MEAN_WEIGHT)
    new = fld(pts)
    assert 0.02 < np.max(new) < 0.031         # the 30 um field, smoothed
    np.testing.assert_allclose(new, old, rtol=0, atol=1e-15)
    # a block of more points than one dense product holds is split in rows alike
    keep = region_field.BLOCK_VALUES
    try:
        region_field.BLOCK_VALUES = 1000
        np.testing.assert_allclose(fld(pts), new, rtol=0, atol=1e-15)
    finally:
        region_field.BLOCK_VALUES = keep
    assert fld(np.empty((0, 3))).shape == (0,)


def test_prefetched_edge_normals_equal_one_projection_per_set(blade):
    """The blade's six shared edges: the normals and parameters every edge point set
    gets from the one projection per face equal, bit for bit, those of projecting each
    set alone; the nominal angles are the blade's (143.3 deg at the leading edge)."""
    shape = blade[0]
    faces = [region.region_face(shape, k) for k in range(4)]
    assert orient(shape, faces) == ["Face2", "Face3"]    # as the run turns them
    edges = region.shared_edges(shape, faces)     # prefetches
    assert len(edges) == 6
    assert max(e.nominal_angle for e in edges) == pytest.approx(179.246, abs=0.01)
    assert sorted(round(e.nominal_angle, 1) for e in edges) == \
        [13.8, 22.3, 95.4, 97.5, 143.3, 179.2]
    sets = [(j, p) for e in edges for j in (e.a, e.b) for p in region.edge_point_sets(e.samples)]
    batched = [region.normals_at(faces[j], p) for j, p in sets]
    assert all(len(f.normals_cache) for f in faces)
    for f in faces:
        f.normals_cache.clear()
    for (j, p), b in zip(sets, batched):
        alone = region.normals_at(faces[j], p)
        for x, y in zip(alone, b):
            np.testing.assert_array_equal(x, y)


def _faces(shape):
    faces = [region.region_face(shape, k) for k in range(4)]
    orient(shape, faces)
    return faces


def test_two_round_location_equals_projecting_every_masked_point(blade):
    """The blade's points, each on the face of its nearest sample first and on the others
    only where they may be nearer: the same nearest faces, parameters, normals and
    distances (bit for bit) as projecting every point of each face's sample mask on it,
    and the points left out are the mask's off-face points only."""
    shape, pts, _dev = blade
    faces = _faces(shape)
    dist, res = region.project_all(faces, pts, 1.0)
    new = region.locate(faces, pts, 1.0, (dist, res))
    plain = _faces(shape)
    may, first = region._sample_distances(plain, pts, 1.0)
    dist0, res0 = np.full((4, len(pts)), np.inf), []
    for i, f in enumerate(plain):
        idx = np.flatnonzero(may[i])
        p = f.project(pts[idx], max_distance=1.0)
        res0.append((idx, p))
        ok = p.converged.copy()
        ok[ok] = region.inside(f.polylines, p.u[ok], p.v[ok])
        dist0[i, idx[ok]] = np.abs(p.distance[ok])
    old = region.locate(plain, pts, 1.0, (dist0, res0))
    np.testing.assert_array_equal(new[0], old[0])
    assert np.bincount(new[0]).tolist() == [3000, 3000, 150, 250]
    for a, b in zip(new[1:], old[1:]):
        np.testing.assert_array_equal(a, b)
    left_out = sum(len(i0) - len(i) for (i, _), (i0, _) in zip(res, res0))
    assert left_out > 100                 # the other side's points near the knife edges
    for i in range(4):
        idx = res[i][0]
        assert set(idx) <= set(res0[i][0])
        assert set(np.flatnonzero(new[0] == i)) <= set(idx)
        fin = np.isfinite(dist[i])
        np.testing.assert_array_equal(dist[i][fin], dist0[i][fin])


def test_field_cells_in_the_order_of_unique_rows(blade):
    """The field's cells of the blade's points (and of keys either side of zero) are those
    of ``np.unique`` over the rows: the same inverse and counts, so the same centres in
    the same order."""
    shape, pts, _dev = blade
    cell = region_field.CELL * region.FIELD_SHARE * shape.BoundBox.DiagonalLength
    for key in (np.floor(pts / cell).astype(np.int64),
                np.floor((pts - pts.mean(axis=0)) / (0.1 * cell)).astype(np.int64)):
        _, inv, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        inv2, count2 = region_field._cells(key)
        assert len(count) > 100
        np.testing.assert_array_equal(inv2, inv.ravel())
        np.testing.assert_array_equal(count2, count)
    assert np.min(key) < 0
