# SPDX-License-Identifier: LGPL-2.1-or-later
"""The fast paths of the region route (issue 30, the 200k-point blade bench) against the
plain computation they replace, on the BladeX blade: the field's kernel sums in dense
blocks against the pairs of a sparse distance matrix, the edge normals projected in one
call per face against one call per point set, the sharp edges' bounded nearest-sample
search against the unbounded one."""

import os

import numpy as np
import pytest
from scipy.spatial import cKDTree

from surfcomp.app import region
from surfcomp.app.region_orient import orient
from surfcomp.core.compensation import region_build, region_edges, region_field
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


def _segment_blend(sharp, x, idx):
    """One edge's distance, miter, excess and exactness at every point of ``x`` as the
    code before the bounded search gave them (nearest sample from an unbounded query, both
    segments at it, the nearer one's Catmull-Rom values)."""
    pts, ex = sharp.points[idx], sharp.exact[idx]
    mit = np.concatenate([sharp.miter[idx], sharp.excess[idx]], axis=1)
    last = len(idx) - 1
    _, j = cKDTree(pts).query(x, k=1)
    best_d, best_m, best_e = np.full(len(x), np.inf), np.zeros((len(x), 6)), np.zeros(len(x))
    for k0, k1 in ((np.maximum(j - 1, 0), j), (j, np.minimum(j + 1, last))):
        ab = pts[k1] - pts[k0]
        t = np.clip(np.einsum("ij,ij->i", x - pts[k0], ab)
                    / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
        d = np.linalg.norm(x - (pts[k0] + t[:, None] * ab), axis=1)
        b = d < best_d
        best_d[b] = d[b]
        ks = (np.maximum(k0 - 1, 0)[b], k0[b], k1[b], np.minimum(k1 + 1, last)[b])
        best_m[b] = region_edges._catmull_rom(mit, ks, t[b, None])
        best_e[b] = region_edges._catmull_rom(ex[:, None], ks, t[b, None])[:, 0]
    return best_d, best_m, best_e


def _plain_nearest(sharp, x):
    """``SharpEdges.nearest`` as it was: every point within the band plus the samples'
    spacing of any sample weighs every edge whose widened box holds it."""
    reach = sharp.band + sharp._reach
    near = np.flatnonzero(np.isfinite(cKDTree(sharp.points).query(
        x, k=1, distance_upper_bound=reach)[0]))
    dmin, wsum = np.full(len(x), np.inf), np.zeros(len(x))
    m, e = np.zeros((len(x), 6)), np.zeros(len(x))
    for idx in sharp._edges:
        lo, hi = sharp.points[idx].min(axis=0) - sharp.band, sharp.points[idx].max(axis=0) \
            + sharp.band
        k = near[np.all((x[near] >= lo) & (x[near] <= hi), axis=1)]
        d, mk, ek = _segment_blend(sharp, x[k], idx)
        w = (1.0 - region_edges.smoothstep(d / sharp.band)) / (d * d + (1e-9 * sharp.band) ** 2)
        dmin[k] = np.minimum(dmin[k], d)
        wsum[k] += w
        m[k] += w[:, None] * mk
        e[k] += w * ek
    far = wsum <= 0
    wsum[far], e[far] = 1.0, 1.0
    return dmin, m[:, :3] / wsum[:, None], e / wsum, m[:, 3:] / wsum[:, None]


def test_sharp_edges_bounded_search_equals_the_plain_one(blade):
    """The blade's six sharp edges with the bench's band (5 % of the diagonal): at the
    blade's points and at points 3 mm off them, as every face sees the edges, the miter,
    exactness and excess equal bit for bit those of searching every edge's nearest sample
    without a bound; the distance equals within the band and is at least the band beyond
    it (where nothing turns), and the displacement's direction is the same bit for bit."""
    shape, pts, _dev = blade
    faces = _faces(shape)
    edges = region.shared_edges(shape, faces)
    band = region.FIELD_SHARE * shape.BoundBox.DiagonalLength
    sharp = region.sharp_edges(faces, edges, band=band)
    assert len(sharp._edges) == 6 and band == pytest.approx(7.886, abs=1e-3)
    rng = np.random.default_rng(3)
    off = pts + 3.0 * rng.normal(size=pts.shape)
    normal = rng.normal(size=pts.shape)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    for s in [sharp] + [sharp.for_face(i) for i in range(4)]:
        for x in (pts, off):
            new, old = s.nearest(x), _plain_nearest(s, x)
            inside = old[0] < band
            assert 0.3 * len(x) < np.sum(inside) < len(x)     # both kinds of points
            assert np.sum(old[2] < 1.0) > 0.05 * len(x)       # knife edges in reach
            np.testing.assert_array_equal(new[0][inside], old[0][inside])
            assert np.all(new[0][~inside] >= band)
            for a, b in zip(new[1:], old[1:]):
                np.testing.assert_array_equal(a, b)
            turned = region_build.direction(x, normal, s)
            assert np.max(np.linalg.norm(turned - normal, axis=1)) > 0.1
            with pytest.MonkeyPatch.context() as mp:
                mp.setattr(s, "nearest", lambda y, s=s: _plain_nearest(s, y))
                np.testing.assert_array_equal(turned, region_build.direction(x, normal, s))
