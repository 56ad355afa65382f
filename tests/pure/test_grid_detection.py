# SPDX-License-Identifier: LGPL-2.1-or-later
"""Grid detection at scale (surfcomp.core.surface.grid): scattered points are told apart without
the per-row-count search, and the search finds the same rows as the exhaustive one
(every row count dividing N split at its largest gaps) that it replaced."""

import numpy as np
import pytest

from surfcomp.core.surface import grid
from surfcomp.core.surface.grid import grid_from_uv
from surfcomp.errors import GridError


def exhaustive_rows(a, b):
    """The former search, kept as the reference: for every row count dividing N, split the
    sorted values at the ``rows - 1`` largest gaps (argpartition) and keep the count with
    the largest ratio of the narrowest cut to the widest gap left inside, above 3, whose
    rows have equal sizes. O(N) per divisor of N."""
    n_pts = a.size
    order = np.argsort(a, kind="stable")
    xs = a[order]
    gaps = np.diff(xs)
    best = None
    for rows in range(2, n_pts // 2 + 1):
        if n_pts % rows:
            continue
        cut = np.sort(np.argpartition(gaps, -(rows - 1))[-(rows - 1):])
        labels_sorted = np.zeros(n_pts, dtype=int)
        labels_sorted[cut + 1] = 1
        labels_sorted = np.cumsum(labels_sorted)
        inside = np.delete(gaps, cut)
        small = inside.max() if inside.size else 0.0
        ratio = gaps[cut].min() / max(small, 1e-15 * max(1.0, np.abs(xs).max()))
        if ratio <= 3.0 or (best is not None and ratio <= best[0]):
            continue
        labels = np.empty(n_pts, dtype=int)
        labels[order] = labels_sorted
        if np.all(np.bincount(labels, minlength=rows) == n_pts // rows):
            best = (ratio, rows)
    if best is None:
        return None
    members = order.reshape(best[1], n_pts // best[1])
    within = np.argsort(b[members], axis=1, kind="stable")
    return np.take_along_axis(members, within, axis=1)


def layouts():
    """Seeded (u, v) sets: grids of many shapes (skewed, shuffled, serpentine, exact,
    noisy up to and beyond the 3:1 gap ratio), grids with holes, and scattered sets."""
    rng = np.random.default_rng(15)
    out = []
    for n, m in [(2, 2), (3, 8), (7, 10), (12, 12), (24, 10), (30, 30), (16, 45), (60, 7)]:
        s, t = np.meshgrid(np.linspace(0.05, 0.95, n), np.linspace(0.02, 0.98, m),
                           indexing="ij")
        for skew, noise in [(0.0, 0.0), (0.01, 0.0), (0.03, 0.0), (0.01, 0.002),
                            (0.0, 0.02), (0.0, 0.06)]:
            U = s + skew * np.sin(3 * t) + rng.normal(0, noise, s.shape)
            V = t + skew * s ** 2 + rng.normal(0, noise, s.shape)
            p = rng.permutation(U.size)
            out.append(("%dx%d skew %g noise %g" % (n, m, skew, noise),
                        U.ravel()[p], V.ravel()[p]))
            out.append(("%dx%d file order" % (n, m), U.ravel(), V.ravel()))
        holes = rng.choice(n * m, max(1, n * m // 20), replace=False)
        out.append(("%dx%d with holes" % (n, m), np.delete(s.ravel(), holes),
                    np.delete(t.ravel(), holes)))
    for k in (8, 50, 144, 1000, 5040):
        out.append(("scattered %d" % k, rng.random(k), rng.random(k)))
    # rows of two points, the most rows a grid can have
    out.append(("rows of two", np.tile([0.1, 0.9], 36) + rng.normal(0, 1e-3, 72),
                np.repeat(np.linspace(0, 1, 36), 2)))
    return out


@pytest.mark.parametrize("name,u,v", layouts(), ids=[c[0] for c in layouts()])
def test_row_search_equals_the_exhaustive_search(name, u, v):
    for a, b in ((v, u), (u, v)):
        ref = exhaustive_rows(a, b)
        got = grid._try_rows(a, b, "a", "b")
        if ref is None:
            assert got is None
        else:
            assert got is not None and got.shape == ref.shape
            np.testing.assert_array_equal(got, ref)


def test_the_layouts_include_grids_and_non_grids():
    """The comparison above is not vacuous: both answers occur, for many row counts."""
    found = [exhaustive_rows(v, u) for _, u, v in layouts()]
    shapes = {f.shape for f in found if f is not None}
    assert len(shapes) >= 8 and sum(f is None for f in found) >= 15


def test_scattered_points_are_decided_without_the_row_search(monkeypatch):
    """A million-point-like scattered set: the median-gap bound rules out every row count
    (no per-count pass over the gaps), the scan-line test stops within its first
    points, and the error says that the points are scattered."""
    rng = np.random.default_rng(3)
    u, v = rng.random(200_000), rng.random(200_000)

    def no_search(*args):
        raise AssertionError("the per-row-count check ran on scattered points")

    seen = []
    line_sizes = grid._line_sizes
    monkeypatch.setattr(grid, "_row_ratio", no_search)
    monkeypatch.setattr(grid, "_line_sizes", lambda x, turn: seen.append(len(x)) or
                        line_sizes(x, turn))
    for a in (u, v):
        rows, median = grid._row_candidates(np.diff(np.sort(a)), a.size)
        assert rows == [] and 0 < median < 1e-5
    with pytest.raises(GridError) as exc:
        grid_from_uv(u, v, source="cloud.xyz")
    msg = str(exc.value)
    assert msg.startswith("cloud.xyz: the 200000 measured points do not form a complete")
    assert "do not fall into rows of constant v or u" in msg and "scattered layout" in msg
    assert seen == [grid._SCAN_PREFIX]


def test_exact_grid_rows_pass_the_bound():
    """Rows of exactly equal v (median gap 0): the bound lets the right row counts through
    and the search finds the 40 x 25 grid."""
    s, t = np.meshgrid(np.linspace(0, 1, 40), np.linspace(0, 1, 25), indexing="ij")
    p = np.random.default_rng(1).permutation(s.size)
    u, v = s.ravel()[p], t.ravel()[p]
    rows, median = grid._row_candidates(np.diff(np.sort(v)), v.size)
    assert median == 0.0 and 25 in rows
    g = grid_from_uv(u, v)
    assert g.shape == (40, 25) and g.rows_from == "rows of constant v on the face"
    np.testing.assert_array_equal(u[g.index], s)
    np.testing.assert_array_equal(v[g.index], t)
