# SPDX-License-Identifier: LGPL-2.1-or-later
"""Arrange measured points on their n x m measurement grid (no FreeCAD).

A grid is an index array ``index[i, j]`` -> point number, oriented so that the
map from grid indices to the face's (u, v) parameters preserves orientation
(checked on every cell, so the correction field built on it is well defined).
"""

from dataclasses import dataclass

import numpy as np

from ...errors import GridError


@dataclass(frozen=True)
class Grid:
    """``index`` (n, m) int: point number at each node; ``rows_from`` tells how it was found."""

    index: np.ndarray
    rows_from: str

    @property
    def shape(self):
        return self.index.shape

    def take(self, values):
        """Arrange per-point ``values`` (N, ...) on the grid -> (n, m, ...)."""
        return np.asarray(values)[self.index]


class Scattered(Grid):
    """A layout that is not a complete grid: ``index`` (N,) is the points in file order.

    The :class:`Grid` interface (``index``, ``shape`` (N,), ``take``) keeps per-point and
    per-node arrays converting alike; ``rows_from`` says why the points are scattered.
    """


def _where(source, lines, k):
    return dict(file=source, line=int(lines[k]) if lines is not None else None)


def grid_from_indices(row, col, u, v, lines=None, source=None):
    """Grid from explicit ``row``/``col`` columns of the measurement file.

    Row and column labels may be any integers (0- or 1-based, gaps in numbering
    allowed); every (row, col) pair must occur exactly once and the grid must be
    complete.
    """
    row = np.asarray(row)
    col = np.asarray(col)
    ru, ri = np.unique(row, return_inverse=True)
    cu, ci = np.unique(col, return_inverse=True)
    n, m = ru.size, cu.size
    index = np.full((n, m), -1, dtype=np.int64)
    flat = ri * m + ci
    order = np.argsort(flat, kind="stable")
    dup = np.nonzero(np.diff(flat[order]) == 0)[0]
    if dup.size:
        a, b = order[dup[0]], order[dup[0] + 1]
        raise GridError("grid node (row %s, col %s) given twice (also on line %s) (expected each "
                        "row/col pair once)"
                        % (row[b], col[b], lines[a] if lines is not None else "?"),
                        **_where(source, lines, b))
    index.ravel()[flat] = np.arange(row.size)
    if np.any(index < 0):
        miss = np.argwhere(index < 0)
        names = ", ".join("(row %s, col %s)" % (ru[i], cu[j]) for i, j in miss[:10])
        more = "" if len(miss) <= 10 else " and %d more" % (len(miss) - 10)
        raise GridError("the row/col indices do not form a complete %d x %d grid: missing %s%s "
                        "(expected every row/col pair; without row/col columns the points can be "
                        "used as a scattered layout)"
                        % (n, m, names, more), file=source)
    return _oriented(Grid(index, "row/col columns"), u, v, source)


#: a row break must be wider than this many times every gap inside the rows
ROW_GAP_RATIO = 3.0


def _sorted_gaps(a):
    """The gaps between consecutive values of ``a`` in increasing order."""
    return np.diff(np.sort(a))


def _row_candidates(gaps, n_pts):
    """Row counts that can split ``n_pts`` sorted values into equal rows (linear work).

    Rows of ``n_pts // rows`` points break at every ``m``-th gap; :func:`_try_rows` needs
    each break wider than :data:`ROW_GAP_RATIO` times every gap inside the rows. With at
    most ``n_pts // 2`` rows at least half of the gaps lie inside rows, so the median
    gap is a lower bound of the widest inside gap, and a row count whose narrowest break
    is not wider than the ratio times that median cannot give a grid. One partition for
    the median and ``rows - 1`` gaps per divisor: O(N) after the sort, however many
    divisors N has. Returns ``(rows, ...)`` increasing and the median gap.
    """
    k = (n_pts + 1) // 2 - 1
    median = float(np.partition(gaps, k)[k])
    out = [rows for rows in _divisors(n_pts) if 2 <= rows <= n_pts // 2
           and gaps[n_pts // rows - 1::n_pts // rows].min() > ROW_GAP_RATIO * median]
    return out, median


def _divisors(n):
    """The divisors of n, increasing."""
    small = [k for k in range(1, int(np.sqrt(n)) + 1) if n % k == 0]
    return sorted(set(small + [n // k for k in small]))


def _row_ratio(gaps, rows, scale):
    """Narrowest break over widest inside gap when ``rows`` equal rows break at every
    ``m``-th sorted gap (the largest ``rows - 1`` gaps whenever the ratio exceeds 1)."""
    m = gaps.size // rows + 1
    inside = np.ones(gaps.size, dtype=bool)
    inside[m - 1::m] = False
    small = gaps[inside].max() if inside.any() else 0.0
    return gaps[~inside].min() / max(small, 1e-15 * scale)


def _try_rows(a, b, name_a, name_b, gaps=None):
    """Points in rows of nearly constant ``a``; within a row ordered by ``b``.

    Of the row counts dividing N whose equal rows each break on a gap wider than
    :data:`ROW_GAP_RATIO` times every gap inside them, the one with the largest ratio
    (the fewest rows among equals). Points that are plainly not in rows cost one sort
    and linear work (:func:`_row_candidates`); only the few row counts that pass it
    are checked against every gap.
    """
    n_pts = a.size
    gaps = _sorted_gaps(a) if gaps is None else gaps
    candidates, _ = _row_candidates(gaps, n_pts)
    scale = max(1.0, float(np.abs(a).max()))
    best = None
    for rows in candidates:
        ratio = _row_ratio(gaps, rows, scale)
        if ratio > ROW_GAP_RATIO and (best is None or ratio > best[0]):
            best = (ratio, rows)
    if best is None:
        return None
    rows = best[1]
    cols = n_pts // rows
    # rows are consecutive runs of the points sorted by a
    members = np.argsort(a, kind="stable").reshape(rows, cols)
    within = np.argsort(b[members], axis=1, kind="stable")
    return np.take_along_axis(members, within, axis=1)


def _describe_incomplete(a, b, name_a, name_b, gaps=None):
    """A message that says which row is short when points almost form a grid."""
    gaps = _sorted_gaps(a) if gaps is None else gaps
    if gaps.size == 0:
        return "only one point"
    top = max(1, int(np.sqrt(a.size)) // 2)
    thresh = 0.3 * np.sort(np.partition(gaps, gaps.size - top)[gaps.size - top:]).mean()
    labels = np.concatenate([[0], np.cumsum(gaps > thresh)])
    sizes = np.bincount(labels)
    if sizes.size < 2:
        return "the points do not fall into rows of constant %s or %s" % (name_a, name_b)
    common = np.bincount(sizes).argmax()
    if common == 1:
        return ("the points do not fall into rows of constant %s or %s (most of the %d groups "
                "of nearly equal %s hold a single point: a scattered layout)"
                % (name_a, name_b, sizes.size, name_a))
    odd = [k for k in range(sizes.size) if sizes[k] != common]
    if not odd:
        return "found %d rows of %d points" % (sizes.size, common)
    order = np.argsort(a, kind="stable")
    full = order[labels == next(k for k in range(sizes.size) if sizes[k] == common)]
    ref = np.sort(b[full])
    half = 0.5 * np.min(np.diff(ref)) if ref.size > 1 else np.inf
    parts = []
    for k in odd[:5]:
        mem = order[labels == k]
        text = "the row at %s=%.6g has %d points" % (name_a, a[mem].mean(), sizes[k])
        if sizes[k] < common:
            gaps = [x for x in ref if np.min(np.abs(b[mem] - x)) > half]
            if gaps:
                text += " (missing near %s=%s)" % (name_b, ", ".join("%.6g" % x for x in gaps[:5]))
        parts.append(text)
    return ("found %d rows of constant %s, most with %d points, but %s"
            % (sizes.size, name_a, common, "; ".join(parts)))


def grid_from_uv(u, v, lines=None, source=None):
    """Find the n x m grid from the points' (u, v) on the face.

    Rows may come in any order and any direction (serpentine scans). The points
    must fall into rows of nearly constant v (or of nearly constant u), each with
    the same number of points.
    """
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    if u.size < 4:
        raise GridError("%d measured points cannot form a grid (expected at least 2 x 2)" % u.size,
                        file=source)
    sorted_v = _sorted_gaps(v)
    for a, b, na, nb, how, sg in ((v, u, "v", "u", "rows of constant v", sorted_v),
                                  (u, v, "u", "v", "rows of constant u", None)):
        index = _try_rows(a, b, na, nb, sg)
        if index is not None:
            if how.endswith("v"):
                index = index.T  # (rows of v, points along u) -> first axis along u
            return _oriented(Grid(np.ascontiguousarray(index), how + " on the face"), u, v, source)
    index = _rows_in_file_order(u, v)
    if index is not None:
        try:
            return _oriented(Grid(index, "scan lines in file order (across the parameter lines)"),
                             u, v, source)
        except GridError:
            pass  # not a proper grid after all: report why the other ways failed
    raise GridError("the %d measured points do not form a complete n x m grid on the face: %s "
                    "(expected rows of equal length; add row/col columns, or layout "
                    "'scattered')" % (u.size, _describe_incomplete(v, u, "v", "u", sorted_v)),
                    file=source, options=("layout",))


#: cosine of the direction change (45 degrees) that ends a scan line in file order
_ROW_TURN = np.cos(np.radians(45.0))


#: points whose scan lines are checked first (a scattered file fails within them)
_SCAN_PREFIX = 4096


def _line_sizes(x, turn):
    """Lengths of the scan lines of points ``x`` (k, 2) in file order (None for repeated
    points): a line ends where the scan direction turns by more than ``turn`` (a cosine)
    on both sides of one step."""
    d = np.diff(x, axis=0)
    length = np.linalg.norm(d, axis=1)
    if d.shape[0] < 3 or np.any(length == 0):
        return None
    e = d / length[:, None]
    cos = np.einsum("ij,ij->i", e[:-1], e[1:])     # turn between step k and step k + 1
    turned = cos < turn
    # step k (1..N-3) links two lines when the direction turns before and after it
    links = np.nonzero(turned[:-1] & turned[1:])[0] + 1
    starts = np.concatenate([[0], links + 1])
    return np.diff(np.concatenate([starts, [x.shape[0]]]))


def _rows_in_file_order(u, v, turn=_ROW_TURN):
    """Rows of a raster or serpentine scan written line by line, whatever their angle to
    the parameter lines: a row ends where the scan direction turns by more than 45
    degrees on both sides of one step (the step to the next line). Returns the index
    (n, m) with every row running the first row's way, or None when the points are not
    n equal lines of m >= 3 evenly spaced points (within 25 %; n >= 2).

    The first :data:`_SCAN_PREFIX` points are looked at first: the lines complete in
    them are the file's first lines, so unequal ones there (a scattered file) decide
    without a pass over all points."""
    x = np.stack([u / (np.ptp(u) or 1.0), v / (np.ptp(v) or 1.0)], axis=1)
    if u.size > 2 * _SCAN_PREFIX:
        head = _line_sizes(x[:_SCAN_PREFIX], turn)
        if head is None or (head.size > 1 and (head[0] < 3 or np.any(head[1:-1] != head[0])
                                               or head[-1] > head[0])):
            return None
    sizes = _line_sizes(x, turn)
    if sizes is None or sizes.size < 2 or sizes[0] < 3 or np.any(sizes != sizes[0]):
        return None
    index = np.arange(u.size).reshape(sizes.size, sizes[0])
    # a scan grid steps evenly along its lines; points placed adaptively along curves
    # (the mirror paper's layouts) are a scattered layout, not a grid
    along = np.linalg.norm(np.diff(x[index], axis=1), axis=2)
    if np.any(np.abs(along / np.median(along) - 1.0) > 0.25):
        return None
    first = x[index[0, -1]] - x[index[0, 0]]
    back = np.einsum("ij,j->i", x[index[:, -1]] - x[index[:, 0]], first) < 0
    index[back] = index[back, ::-1]
    # the lines must follow each other across the face (no line out of place)
    gaps = np.linalg.norm(x[index[1:, 0]] - x[index[:-1, 0]], axis=1)
    if np.max(gaps) > 3.0 * np.median(gaps):
        return None
    return np.ascontiguousarray(index)


def _oriented(grid, u, v, source):
    """Flip the second axis if needed so every cell maps to (u, v) with positive orientation."""
    index = grid.index
    n, m = index.shape
    if n < 2 or m < 2:
        raise GridError("a %d x %d grid has no cells (expected at least 2 x 2 points)" % (n, m),
                        file=source)
    U, V = np.asarray(u)[index], np.asarray(v)[index]
    du_s, dv_s = U[1:, :-1] - U[:-1, :-1], V[1:, :-1] - V[:-1, :-1]
    du_t, dv_t = U[:-1, 1:] - U[:-1, :-1], V[:-1, 1:] - V[:-1, :-1]
    det = du_s * dv_t - dv_s * du_t
    if np.median(det) < 0:
        index = index[:, ::-1]
        det = -det[:, ::-1]
    if np.any(det <= 0):
        i, j = np.argwhere(det <= 0)[0]
        raise GridError("the measurement grid folds over itself on the face near grid cell "
                        "(%d, %d) (expected a grid whose cells do not overlap in (u, v))" % (i, j),
                        file=source)
    return Grid(np.ascontiguousarray(index), grid.rows_from)
